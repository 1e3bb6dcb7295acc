//! `histencil compare pair --before DIR... --after DIR...`: did a change of histencil (or of a
//! setting) move the lighting time, told apart from the machine's drift.
//!
//! One `compare` run pairs its techniques by round, in one process. Two builds cannot share a
//! process, so the pairing here is one level up: the builds' runs alternate on one device
//! (before, after, before, after ...), each pair's ratio is the after run's median lighting time
//! over the before run's, cell by cell, and the verdict is the lab's own
//! ([`Verdict::at_margin`]) on the median of those ratios, its order-statistic interval taken
//! over the pairs. A drift of the machine that is slow against the length of one pair divides
//! out of each ratio; one that runs across the pairs splits the halves, which the verdict holds
//! to agree. As with rounds, fewer than [`crate::stats::MIN_VERDICT_ROUNDS`] pairs decide
//! nothing.
//!
//! Why a margin of its own (2 % by default, not the talk's 5 %): the question is whether a
//! change costs the built-in techniques anything, and a 4 % loss is one an engine would want
//! named. Whether ±2 % can be resolved is the device's to say: on lavapipe, run-to-run drift of
//! ±10 % left every cell undecided.

use super::merge::DeviceReport;
use crate::stats::{median_interval, Interval, Verdict};
use crate::{write_file, LabError, Result};
use serde_json::{json, Value};
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
    pub runs: Vec<(PathBuf, PathBuf)>,
    pub device: String,
    pub driver: String,
    pub workload: String,
    pub cells: Vec<PairedCell>,
    /// Cells some run lacks (`technique at n BRDFs: absent from DIR`), compared in none.
    pub left_out: Vec<String>,
}

impl Paired {
    /// Pairs `before[i]` with `after[i]`. Refuses unequal counts, no runs, a margin outside
    /// (0, 50 %), and runs of another device, driver, workload or conditions than the first.
    ///
    /// # Errors
    /// [`LabError::Settings`] naming the run that differs and how.
    pub fn new(
        before: Vec<DeviceReport>,
        after: Vec<DeviceReport>,
        names: (String, String),
        margin: f64,
    ) -> Result<Self> {
        if before.is_empty() || before.len() != after.len() {
            return Err(LabError::Settings(format!(
                "compare pair takes as many before runs as after runs, alternated on one device \
                 (before, after, before, after ...); got {} and {}",
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
        let first = &before[0];
        for r in before.iter().chain(&after) {
            let differs = [
                ("device", r.device.clone(), first.device.clone()),
                ("driver", driver(r).into(), driver(first).into()),
                ("workload", describe(r), describe(first)),
            ]
            .into_iter()
            .find(|(_, a, b)| a != b);
            if let Some((what, a, b)) = differs {
                return Err(LabError::Settings(format!(
                    "{} has {what} `{a}`, {} has `{b}`: pair runs of one workload on one device \
                     and driver (the same compare options; only the binary or the setting under \
                     test changes)",
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
        Ok(Self {
            names,
            margin,
            device: first.device.clone(),
            driver: driver(first).into(),
            workload: describe(first),
            runs: before
                .iter()
                .zip(&after)
                .map(|(b, a)| (b.dir.clone(), a.dir.clone()))
                .collect(),
            cells,
            left_out,
        })
    }

    /// "within ±2 %" and the rest, at this comparison's margin.
    fn word(&self, v: Verdict) -> String {
        match v {
            Verdict::Within => format!("within ±{} %", self.margin * 100.0),
            other => other.word().into(),
        }
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
            self.margin * 100.0
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
             Each pair is a run of `{before}`, then a run of `{after}`, with the same \
             `histencil compare` options, the pairs one after another. A cell's ratio is the \
             `{after}` run's median lighting time over the `{before}` run's, pair by pair; the median of those ratios with \
             its 95 % order-statistic interval over the pairs, and the lab's verdict at ±{} % \
             (none from fewer than {} pairs; each half of the pairs must agree).\n\n**{}.**\n\n\
             | technique | BRDFs | {before} ms | {after} ms | {after} / {before} | verdict |\n\
             |---|---|---|---|---|---|\n",
            self.device,
            self.driver,
            self.workload,
            self.margin * 100.0,
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
        md.push_str("\n| pair | before | after |\n|---|---|---|\n");
        for (i, (b, a)) in self.runs.iter().enumerate() {
            let _ = writeln!(md, "| {} | `{}` | `{}` |", i + 1, b.display(), a.display());
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
            "pairs": self.runs.iter().map(|(b, a)| json!([b, a])).collect::<Vec<_>>(),
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

/// The driver as Vulkan names it, without what histencil says of it (its quirks, with their
/// reasons, and the limits it checked): two builds may word those otherwise, or apply other
/// quirks, which is then part of the change under test.
fn driver(r: &DeviceReport) -> &str {
    let d = r.driver.as_str();
    [", quirks:", ", limits:"]
        .iter()
        .filter_map(|cut| d.find(cut))
        .min()
        .map_or(d, |at| &d[..at])
}

/// What two runs must share to be paired: the workload and the conditions.
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
        }
    }

    /// `n` pairs: before at 1 ms drifting up 1 % a pair, after at `factor` of its pair's.
    fn pairs(n: usize, factor: f64) -> (Vec<DeviceReport>, Vec<DeviceReport>) {
        let drift = |i: usize| 1.0 + 0.01 * i as f64;
        let b = (0..n).map(|i| run(&format!("b{i}"), drift(i))).collect();
        let a = (0..n)
            .map(|i| run(&format!("a{i}"), drift(i) * factor))
            .collect();
        (b, a)
    }

    fn paired(n: usize, factor: f64) -> Paired {
        let (b, a) = pairs(n, factor);
        Paired::new(b, a, ("old".into(), "new".into()), 0.02).unwrap()
    }

    #[test]
    fn the_drift_divides_out_and_the_verdict_is_the_labs_at_the_margin() {
        // The machine drifts 9 % over the runs; each pair's ratio stays the change alone.
        let same = paired(10, 1.005);
        assert_eq!(same.tally(), [2, 0, 0, 0], "{}", same.markdown());
        assert!((same.cells[0].ratio.median - 1.005).abs() < 1e-12);
        assert!(same.markdown().contains("| within ±2 % |"));
        let slower = paired(10, 1.04);
        assert_eq!(slower.tally(), [0, 2, 0, 0]);
        assert!(
            slower.summary().contains("stencil at 1 (slower)"),
            "{}",
            slower.summary()
        );
        assert_eq!(paired(10, 0.9).tally(), [0, 0, 2, 0]);
        // Fewer pairs than the lab decides from: undecided, however clear.
        assert_eq!(paired(6, 1.2).tally(), [0, 0, 0, 2]);
    }

    #[test]
    fn a_change_part_way_through_the_pairs_is_undecided() {
        let (b, mut a) = pairs(12, 1.0);
        for (i, r) in a.iter_mut().enumerate().skip(6) {
            *r = run(&format!("a{i}"), (1.0 + 0.01 * i as f64) * 1.05);
        }
        let p = Paired::new(b, a, ("old".into(), "new".into()), 0.02).unwrap();
        assert_eq!(p.tally(), [0, 0, 0, 2], "{}", p.markdown());
    }

    #[test]
    fn what_cannot_be_paired_is_refused_and_a_missing_cell_is_named() {
        let names = || ("old".to_string(), "new".to_string());
        let (b, a) = pairs(3, 1.0);
        let err = |b, a, m| Paired::new(b, a, names(), m).unwrap_err().to_string();
        assert!(err(b.clone(), a[..2].to_vec(), 0.02).contains("got 3 and 2"));
        assert!(err(vec![], vec![], 0.02).contains("got 0 and 0"));
        assert!(err(b.clone(), a.clone(), 0.0).contains("margin"));
        let mut other = a.clone();
        other[1].width = 320;
        assert!(err(b.clone(), other, 0.02).contains("a1 has workload"));
        let mut other = a.clone();
        other[2].driver = "2.0".into();
        assert!(err(b.clone(), other, 0.02).contains("a2 has driver `2.0`"));
        // What histencil says of the driver may differ between the builds; the driver may not.
        let mut worded = a.clone();
        worded[2].driver = "1.0, quirks: small-tiles (why: ...), limits: all met".into();
        assert!(Paired::new(b.clone(), worded, names(), 0.02).is_ok());
        let mut fewer = a.clone();
        fewer[0].rows[0].1.pop();
        let p = Paired::new(b, fewer, names(), 0.02).unwrap();
        assert_eq!(p.cells.len(), 1);
        assert_eq!(p.left_out, ["stencil at 2 BRDFs: absent from a0"]);
        assert!(p
            .markdown()
            .contains("- stencil at 2 BRDFs: absent from a0"));
    }
}
