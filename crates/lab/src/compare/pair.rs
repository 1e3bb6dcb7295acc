//! `histencil compare pair --before DIR... --after DIR...`: did a change of histencil (or of a
//! setting) move the lighting time, told apart from the machine's drift.
//!
//! One `compare` run pairs its techniques by round, in one process. Two builds cannot share a
//! process, so the pairing here is one level up: the builds' runs alternate on one device, each
//! pair's ratio is the after run's median lighting time over the before run's, cell by cell, and
//! the verdict is the lab's own ([`Verdict::at_margin`]) on the median of those ratios, its
//! order-statistic interval taken over the pairs. A drift of the machine adds to every ratio the
//! change it made over one run, on the side of whichever build ran second; so the runs must
//! alternate which build goes first (before then after, then after then before, ...), and the
//! drift's two signs then widen the interval instead of moving the median. A drift that changes
//! part way splits the halves, which the verdict holds to agree. As with rounds, fewer than
//! [`crate::stats::MIN_VERDICT_ROUNDS`] pairs decide nothing.
//!
//! Why a margin of its own (2 % by default, not the talk's 5 %): the question is whether a
//! change costs the techniques anything, and a 4 % loss is one an engine would want named.
//! Whether a device resolves ±2 % is for its runs to say.

use super::merge::DeviceReport;
use crate::stats::{median_interval, Interval, Verdict};
use crate::{write_file, LabError, Result};
use serde_json::{json, Value};
use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// One technique at one BRDF count, over every pair.
#[derive(Clone, Debug, PartialEq)]
pub struct PairedCell {
    pub technique: String,
    pub brdfs: usize,
    /// The before runs' median lighting times (ms): their median and order-statistic interval.
    pub before_ms: Interval,
    pub after_ms: Interval,
    /// After over before, paired run by run.
    pub ratio: Interval,
    pub verdict: Verdict,
}

/// The before and after runs of one workload on one device, paired in the order given.
#[derive(Clone, Debug)]
pub struct Paired {
    pub names: (String, String),
    /// A tie within `1 ± margin`.
    pub margin: f64,
    /// Each pair's before and after run: its folder and its conditions (quiet, or the load the
    /// steady clock saw beside it).
    pub runs: Vec<[(PathBuf, String); 2]>,
    pub device: String,
    pub driver: String,
    pub workload: String,
    pub cells: Vec<PairedCell>,
    /// Cells some run lacks (`technique at n BRDFs: absent from DIR`), compared in none.
    pub left_out: Vec<String>,
}

impl Paired {
    /// Pairs `before[i]` with `after[i]`. Refuses unequal counts, no runs, a run given twice, a
    /// margin outside (0, 50 %), and runs of another device or driver than the first, or with
    /// another value of a setting both reports hold, but for the settings named in `differs`
    /// (the one under test: `depth_bounds`, say).
    ///
    /// # Errors
    /// [`LabError::Settings`] naming the run that differs and how.
    pub fn new(
        before: Vec<DeviceReport>,
        after: Vec<DeviceReport>,
        names: (String, String),
        margin: f64,
        differs: &[String],
    ) -> Result<Self> {
        if before.is_empty() || before.len() != after.len() {
            return Err(LabError::Settings(format!(
                "compare pair takes as many before runs as after runs, alternated on one device \
                 (before, after, then after, before ...); got {} and {}",
                before.len(),
                after.len()
            )));
        }
        if !(margin > 0.0 && margin < 0.5) {
            return Err(LabError::Settings(format!(
                "the margin is a percentage above 0 and below 50; got {}",
                margin * 100.0
            )));
        }
        let mut seen = BTreeSet::new();
        for r in before.iter().chain(&after) {
            let at = r.dir.canonicalize().unwrap_or_else(|_| r.dir.clone());
            if !seen.insert(at) {
                return Err(LabError::Settings(format!(
                    "{} is given twice: each pair is two runs of their own",
                    r.dir.display()
                )));
            }
        }
        let first = &before[0];
        for r in before.iter().chain(&after) {
            let differs_from_first = [
                ("device", r.device.clone(), first.device.clone()),
                ("driver", driver(r), driver(first)),
            ]
            .into_iter()
            .filter(|(_, a, b)| a != b)
            .chain(setting_differences(r, first, differs))
            .next();
            if let Some((what, a, b)) = differs_from_first {
                return Err(LabError::Settings(format!(
                    "{} has {what} `{a}`, {} has `{b}`: pair runs of one workload on one device \
                     and driver (the same compare options; only the binary, or a setting named \
                     by --differs, changes)",
                    r.dir.display(),
                    first.dir.display()
                )));
            }
        }
        let mut cells = Vec::new();
        let mut left_out = Vec::new();
        for (technique, row) in &first.rows {
            for cell in row {
                let find = |r: &DeviceReport| {
                    r.rows
                        .iter()
                        .find(|(t, _)| t == technique)
                        .and_then(|(_, c)| c.iter().find(|c| c.brdfs == cell.brdfs))
                        .map(|c| c.lighting.median)
                };
                let missing = before.iter().chain(&after).find(|r| find(r).is_none());
                if let Some(r) = missing {
                    left_out.push(format!(
                        "{technique} at {} BRDFs: absent from {}",
                        cell.brdfs,
                        r.dir.display()
                    ));
                    continue;
                }
                let times =
                    |runs: &[DeviceReport]| -> Vec<f64> { runs.iter().filter_map(&find).collect() };
                let (b, a) = (times(&before), times(&after));
                let ratios: Vec<f64> = a.iter().zip(&b).map(|(a, b)| a / b).collect();
                let ratio = median_interval(&ratios);
                cells.push(PairedCell {
                    technique: technique.clone(),
                    brdfs: cell.brdfs,
                    before_ms: median_interval(&b),
                    after_ms: median_interval(&a),
                    verdict: Verdict::at_margin(&ratio, margin),
                    ratio,
                });
            }
        }
        for r in before.iter().chain(&after).skip(1) {
            for (technique, row) in &r.rows {
                for cell in row {
                    let in_first = first
                        .rows
                        .iter()
                        .any(|(t, c)| t == technique && c.iter().any(|c| c.brdfs == cell.brdfs));
                    if !in_first {
                        let line = format!(
                            "{technique} at {} BRDFs: absent from {}",
                            cell.brdfs,
                            first.dir.display()
                        );
                        if !left_out.contains(&line) {
                            left_out.push(line);
                        }
                    }
                }
            }
        }
        Ok(Self {
            names,
            margin,
            device: first.device.clone(),
            driver: driver(first),
            workload: describe(first),
            runs: before
                .iter()
                .zip(&after)
                .map(|(b, a)| [b, a].map(|r| (r.dir.clone(), r.conditions())))
                .collect(),
            cells,
            left_out,
        })
    }

    /// "within ±2 %" and the rest, at this comparison's margin.
    fn word(&self, v: Verdict) -> String {
        match v {
            Verdict::Within => format!("within ±{} %", self.percent()),
            other => other.word().into(),
        }
    }

    /// The margin in percent as the user wrote it (2, 2.5), not as binary floating point
    /// gives it back (7.000000000000001).
    fn percent(&self) -> String {
        format!("{:.3}", self.margin * 100.0)
            .trim_end_matches('0')
            .trim_end_matches('.')
            .to_string()
    }

    /// How many cells each verdict took, in the order within, slower, faster, undecided.
    pub fn tally(&self) -> [usize; 4] {
        let count = |v: Verdict| self.cells.iter().filter(|c| c.verdict == v).count();
        [
            count(Verdict::Within),
            count(Verdict::Slower),
            count(Verdict::Faster),
            count(Verdict::Undecided),
        ]
    }

    /// The one-line answer: the tally, and the cells a decided verdict put beyond the margin.
    pub fn summary(&self) -> String {
        let [within, slower, faster, undecided] = self.tally();
        let beyond: Vec<String> = self
            .cells
            .iter()
            .filter(|c| matches!(c.verdict, Verdict::Slower | Verdict::Faster))
            .map(|c| format!("{} at {} ({})", c.technique, c.brdfs, c.verdict.word()))
            .collect();
        let mut line = format!(
            "{} over {}, {} pairs on {}: {within} cells within ±{} %, {slower} slower, {faster} \
             faster, {undecided} undecided",
            self.names.1,
            self.names.0,
            self.runs.len(),
            self.device,
            self.percent()
        );
        if !beyond.is_empty() {
            let _ = write!(line, " ({})", beyond.join("; "));
        }
        line
    }

    /// The table, in Markdown.
    pub fn markdown(&self) -> String {
        let (before, after) = &self.names;
        let mut md = format!(
            "# histencil compare pair: {after} against {before}\n\n{}, driver {}. Workload: {}.\n\n\
             Each pair is a run of `{before}` and a run of `{after}` with the same \
             `histencil compare` options, which went first alternating from pair to pair, the \
             pairs one after another. A cell's ratio is the `{after}` run's median lighting \
             time over the `{before}` run's, pair by pair; the median of those ratios with \
             its 95 % order-statistic interval over the pairs, and the lab's verdict at ±{} % \
             (none from fewer than {} pairs; each half of the pairs must agree).\n\n**{}.**\n\n\
             | technique | BRDFs | {before} ms | {after} ms | {after} / {before} | verdict |\n\
             |---|---|---|---|---|---|\n",
            self.device,
            self.driver,
            self.workload,
            self.percent(),
            crate::stats::MIN_VERDICT_ROUNDS,
            self.summary(),
        );
        for c in &self.cells {
            let ms = |i: &Interval| format!("{:.4} [{:.4}, {:.4}]", i.median, i.lo, i.hi);
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {:.4} [{:.4}, {:.4}] | {} |",
                c.technique,
                c.brdfs,
                ms(&c.before_ms),
                ms(&c.after_ms),
                c.ratio.median,
                c.ratio.lo,
                c.ratio.hi,
                self.word(c.verdict)
            );
        }
        if !self.left_out.is_empty() {
            md.push_str("\nLeft out (some run lacks the cell):\n\n");
            for l in &self.left_out {
                let _ = writeln!(md, "- {l}");
            }
        }
        md.push_str("\n| pair | before | its conditions | after | its conditions |\n");
        md.push_str("|---|---|---|---|---|\n");
        for (i, [(b, bc), (a, ac)]) in self.runs.iter().enumerate() {
            let (b, a) = (b.display(), a.display());
            let _ = writeln!(md, "| {} | `{b}` | {bc} | `{a}` | {ac} |", i + 1);
        }
        md
    }

    pub fn json(&self) -> Value {
        let interval = |i: &Interval| json!({"median": i.median, "lo": i.lo, "hi": i.hi});
        json!({
            "before": self.names.0,
            "after": self.names.1,
            "margin": self.margin,
            "device": self.device,
            "driver": self.driver,
            "workload": self.workload,
            "pairs": self
                .runs
                .iter()
                .map(|[(b, bc), (a, ac)]| json!([
                    {"dir": b.display().to_string(), "conditions": bc},
                    {"dir": a.display().to_string(), "conditions": ac},
                ]))
                .collect::<Vec<_>>(),
            "summary": self.summary(),
            "cells": self.cells.iter().map(|c| json!({
                "technique": c.technique,
                "brdfs": c.brdfs,
                "before_ms": interval(&c.before_ms),
                "after_ms": interval(&c.after_ms),
                "ratio": interval(&c.ratio),
                "verdict": self.word(c.verdict),
            })).collect::<Vec<_>>(),
            "left_out": self.left_out,
        })
    }

    /// Writes `paired.md` and `paired.json` into `dir`.
    ///
    /// # Errors
    /// I/O errors.
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>> {
        let md = dir.join("paired.md");
        write_file(&md, self.markdown().as_bytes())?;
        let js = dir.join("paired.json");
        crate::write_json(&js, &self.json())?;
        Ok(vec![md, js])
    }
}

/// The driver as Vulkan names it, without what histencil says of its quirks and limits (two
/// builds may word those otherwise, or apply other quirks, which is then part of the change
/// under test), but with whether the validation layer ran (it appends itself after them) and
/// which.
fn driver(r: &DeviceReport) -> String {
    let d = r.driver.as_str();
    let core = d.find(", quirks:").map_or(d, |at| &d[..at]);
    match d.find(", validation layer") {
        Some(at) => {
            let layer = &d[at..];
            let layer = layer[2..].find(", ").map_or(layer, |end| &layer[..end + 2]);
            format!("{core}{layer}")
        }
        None => core.to_string(),
    }
}

/// Each setting both runs' reports hold with different values, but for those in `differs`:
/// `(name, this run's, the first run's)`. A setting one build's report lacks (an option it did
/// not have yet) is not compared.
fn setting_differences(
    r: &DeviceReport,
    first: &DeviceReport,
    differs: &[String],
) -> Vec<(&'static str, String, String)> {
    let (Some(mine), Some(theirs)) = (r.settings.as_object(), first.settings.as_object()) else {
        return Vec::new();
    };
    mine.iter()
        .filter(|(key, _)| !differs.iter().any(|d| d == *key))
        .filter_map(|(key, value)| {
            let other = theirs.get(key)?;
            (other != value).then(|| ("setting", format!("{key} = {value}"), format!("{other}")))
        })
        .collect()
}

/// The workload and conditions for the table's header.
fn describe(r: &DeviceReport) -> String {
    format!(
        "scene `{}` at {}x{}, {} busy threads beside it, depth bounds test {}",
        r.scene,
        r.width,
        r.height,
        r.beside_load,
        if r.depth_bounds { "on" } else { "off" }
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compare::merge::MergedCell;

    /// A run whose stencil row takes `ms` at 1 BRDF and twice it at 2.
    fn run(dir: &str, ms: f64) -> DeviceReport {
        let cell = |brdfs: usize, m: f64| MergedCell {
            brdfs,
            lighting: Interval {
                lo: m * 0.99,
                median: m,
                hi: m * 1.01,
                samples: 10,
                halves: None,
            },
            overhead: None,
        };
        DeviceReport {
            dir: dir.into(),
            device: "GPU".into(),
            driver: "1.0".into(),
            scene: "huge-lights".into(),
            width: 1280,
            height: 720,
            rounds: 10,
            beside_load: 0,
            busy_elsewhere: None,
            depth_bounds: true,
            rows: vec![("stencil".into(), vec![cell(1, ms), cell(2, 2.0 * ms)])],
            sizes: vec![],
            settings: json!({"scene": "huge-lights", "width": 1280, "depth_bounds": true}),
        }
    }

    /// `n` pairs on a machine slowing `drift` a run, the after build at `factor` of the before
    /// build's time, which build went first alternating as the lab alternates it.
    fn pairs(n: usize, factor: f64, drift: f64) -> (Vec<DeviceReport>, Vec<DeviceReport>) {
        let at = |k: usize| 1.0 + drift * k as f64;
        let (mut b, mut a) = (Vec::new(), Vec::new());
        for i in 0..n {
            let (bk, ak) = if i % 2 == 0 {
                (2 * i, 2 * i + 1)
            } else {
                (2 * i + 1, 2 * i)
            };
            b.push(run(&format!("b{i}"), at(bk)));
            a.push(run(&format!("a{i}"), at(ak) * factor));
        }
        (b, a)
    }

    fn names() -> (String, String) {
        ("old".into(), "new".into())
    }

    fn paired(n: usize, factor: f64, drift: f64) -> Paired {
        let (b, a) = pairs(n, factor, drift);
        Paired::new(b, a, names(), 0.02, &[]).unwrap()
    }

    #[test]
    fn alternating_the_order_keeps_a_drift_from_deciding_and_the_verdict_is_the_labs() {
        let same = paired(10, 1.005, 0.0);
        assert_eq!(same.tally(), [2, 0, 0, 0], "{}", same.markdown());
        assert!((same.cells[0].ratio.median - 1.005).abs() < 1e-12);
        assert!(same.markdown().contains("| within ±2 % |"));
        let slower = paired(10, 1.04, 0.0);
        assert_eq!(slower.tally(), [0, 2, 0, 0]);
        assert!(
            slower.summary().contains("stencil at 1 (slower)"),
            "{}",
            slower.summary()
        );
        assert_eq!(paired(10, 0.9, 0.0).tally(), [0, 0, 2, 0]);
        // Fewer pairs than the lab decides from: undecided, however clear.
        assert_eq!(paired(6, 1.2, 0.0).tally(), [0, 0, 0, 2]);
        // The machine slows 5 % a run. Had the after build always gone second, every ratio
        // would read 1.03 to 1.05: a decided loss that is the drift's. Alternated, the drift's
        // two signs straddle the tie: undecided, and the median stays on the change.
        let always_second: (Vec<_>, Vec<_>) = (0..10)
            .map(|i| {
                let at = |k: usize| 1.0 + 0.05 * k as f64;
                (
                    run(&format!("b{i}"), at(2 * i)),
                    run(&format!("a{i}"), at(2 * i + 1)),
                )
            })
            .unzip();
        let biased = Paired::new(always_second.0, always_second.1, names(), 0.02, &[]).unwrap();
        assert_eq!(biased.tally(), [0, 2, 0, 0], "{}", biased.markdown());
        let drifting = paired(10, 1.0, 0.05);
        let r = drifting.cells[0].ratio;
        assert!(
            r.lo < 0.98 && r.hi > 1.02 && (r.median - 1.0).abs() < 0.002,
            "{r:?}"
        );
        assert_eq!(drifting.tally(), [0, 0, 0, 2], "{}", drifting.markdown());
    }

    #[test]
    fn a_change_part_way_through_the_pairs_is_undecided() {
        let (b, mut a) = pairs(12, 1.0, 0.0);
        for (i, r) in a.iter_mut().enumerate().skip(6) {
            *r = run(&format!("a{i}"), 1.05);
        }
        let p = Paired::new(b, a, names(), 0.02, &[]).unwrap();
        assert_eq!(p.tally(), [0, 0, 0, 2], "{}", p.markdown());
    }

    #[test]
    fn what_cannot_be_paired_is_refused_and_a_missing_cell_is_named() {
        let (b, a) = pairs(3, 1.0, 0.0);
        let err = |b, a, m, differs: &[String]| {
            Paired::new(b, a, names(), m, differs)
                .unwrap_err()
                .to_string()
        };
        assert!(err(b.clone(), a[..2].to_vec(), 0.02, &[]).contains("got 3 and 2"));
        assert!(err(vec![], vec![], 0.02, &[]).contains("got 0 and 0"));
        assert!(err(b.clone(), a.clone(), 0.0, &[]).contains("margin"));
        // One run passed as two pairs' would be ten ratios of exactly 1.
        let mut twice = a.clone();
        twice[1].dir = "b0".into();
        assert!(err(b.clone(), twice, 0.02, &[]).contains("b0 is given twice"));
        let mut other = a.clone();
        other[2].driver = "2.0".into();
        assert!(err(b.clone(), other, 0.02, &[]).contains("a2 has driver `2.0`"));
        // What histencil says of the driver may differ between the builds; the driver may
        // not, and neither may whether the validation layer ran.
        let mut worded = a.clone();
        worded[2].driver = "1.0, quirks: small-tiles (why: ...), limits: all met".into();
        assert!(Paired::new(b.clone(), worded.clone(), names(), 0.02, &[]).is_ok());
        worded[2]
            .driver
            .push_str(", validation layer 1.3.239 (implementation 1), settings");
        assert!(err(b.clone(), worded, 0.02, &[]).contains("validation layer 1.3.239"));
        // A setting both reports hold must agree, unless it is the one under test; one only
        // a newer build writes is not compared.
        let mut unbounded = a.clone();
        unbounded[0].settings["depth_bounds"] = json!(false);
        assert!(err(b.clone(), unbounded.clone(), 0.02, &[])
            .contains("a0 has setting `depth_bounds = false`"));
        let under_test = ["depth_bounds".to_string()];
        assert!(Paired::new(b.clone(), unbounded, names(), 0.02, &under_test).is_ok());
        let mut newer = a.clone();
        newer[1].settings["steady_clock"] = json!(true);
        assert!(Paired::new(b.clone(), newer, names(), 0.02, &[]).is_ok());
        // A cell some run lacks, on either side of the first, is left out and named.
        let mut fewer = a.clone();
        fewer[0].rows[0].1.pop();
        let p = Paired::new(b.clone(), fewer, names(), 0.02, &[]).unwrap();
        assert_eq!(p.cells.len(), 1);
        assert_eq!(p.left_out, ["stencil at 2 BRDFs: absent from a0"]);
        assert!(p
            .markdown()
            .contains("- stencil at 2 BRDFs: absent from a0"));
        let mut more = a.clone();
        let stencil = more[1].rows[0].1.clone();
        more[1].rows.push(("tiled".into(), stencil));
        let p = Paired::new(b, more, names(), 0.025, &[]).unwrap();
        assert_eq!(p.left_out.len(), 2, "{:?}", p.left_out);
        assert!(p.left_out[0].starts_with("tiled at 1 BRDFs: absent from b0"));
        assert!(p.summary().contains("±2.5 %"), "{}", p.summary());
    }
}
