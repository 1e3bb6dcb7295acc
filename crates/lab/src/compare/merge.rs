//! `histencil compare merge DIR...`: several devices' `compare` reports in one table and one
//! plot, because a platform comparison compares platforms.
//!
//! Runs on different devices share no round, so their times cannot be paired the way one run
//! pairs its techniques. Each device therefore keeps its own figures: the median lighting time
//! with its 95 % interval, and the overhead of n BRDFs over one (a ratio paired by round within
//! that device's run) with its verdict. Across devices the table says only which is lower where
//! the two intervals do not overlap, and "overlap" where they do.
//!
//! Verdicts that reverse (faster in one report, slower in another) are listed. Across devices,
//! and between a quiet and a loaded run of one device (`compare --beside-load`, or other
//! processes' load the steady clock read), a reversal is a finding: a load on the cores changes
//! a CPU driver's ratios themselves. Between two runs of one device, driver and conditions (a
//! repeat) it is a failure of the verdicts, noise the margin should have absorbed, which
//! [`Merged::same_device_reversals`] gives the CLI to exit non-zero on.

use super::report::interval_json;
use crate::plot::{self, Axis, Series};
use crate::stats::{Interval, Verdict};
use crate::{write_file, LabError, Result};
use serde_json::{json, Value};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// One technique at one BRDF count, as one device's report gives it.
#[derive(Clone, Debug, PartialEq)]
pub struct MergedCell {
    pub brdfs: usize,
    pub lighting: Interval,
    /// Against the technique's 1-BRDF time in the same run; none at one BRDF.
    pub overhead: Option<(Interval, String)>,
}

/// One light size of a device's sweep: stencil's time over branching's, paired by round.
#[derive(Clone, Debug, PartialEq)]
pub struct MergedSize {
    pub coverage: f64,
    pub stencil_over_branching: Interval,
    pub faster: String,
}

/// What the merge takes from one device's `report.json`.
#[derive(Clone, Debug, PartialEq)]
pub struct DeviceReport {
    pub dir: PathBuf,
    pub device: String,
    pub driver: String,
    pub scene: String,
    pub width: u64,
    pub height: u64,
    pub rounds: u64,
    /// Busy threads beside the run (0: quiet; absent in reports from before the option).
    pub beside_load: u64,
    /// The most cores other processes kept busy in a kept round, where beyond the steady
    /// clock's limit ([`crate::steady::Stability::busy_elsewhere`]): a busy machine's run.
    pub busy_elsewhere: Option<f64>,
    /// The depth bounds test was on (absent, so off, in reports from before it existed).
    pub depth_bounds: bool,
    /// `(technique, cells by BRDF count)`.
    pub rows: Vec<(String, Vec<MergedCell>)>,
    pub sizes: Vec<MergedSize>,
    /// The report's `settings` object as written: what `compare pair` holds two builds' runs
    /// to, key by key.
    pub settings: Value,
}

/// Where in `report.json` a value was missing or of the wrong type.
fn field<'a>(file: &Path, v: &'a Value, path: &str) -> Result<&'a Value> {
    let mut at = v;
    for key in path.split('.') {
        at = match key.parse::<usize>() {
            Ok(i) => at.get(i),
            Err(_) => at.get(key),
        }
        .ok_or_else(|| bad(file, format!("has no {path}")))?;
    }
    Ok(at)
}

fn bad(file: &Path, problem: String) -> LabError {
    LabError::Settings(format!("{}: {problem}", file.display()))
}

fn number(file: &Path, v: &Value, path: &str) -> Result<f64> {
    field(file, v, path)?
        .as_f64()
        .filter(|x| x.is_finite())
        .ok_or_else(|| bad(file, format!("{path} is not a finite number")))
}

fn text(file: &Path, v: &Value, path: &str) -> Result<String> {
    field(file, v, path)?
        .as_str()
        .map(str::to_owned)
        .ok_or_else(|| bad(file, format!("{path} is not a string")))
}

/// The most cores other processes kept busy in a kept round of the report's steady clock, where
/// beyond its limit (the clock's `busy_elsewhere`, which the report's conditions line states
/// too); `None` for a quiet run, a run without the clock, and reports before the clock read
/// the load.
fn busy_elsewhere(stability: &Value) -> Option<f64> {
    stability["busy_elsewhere"]["most_cores"].as_f64()
}

fn interval(file: &Path, v: &Value, path: &str) -> Result<Interval> {
    Ok(Interval {
        lo: number(file, v, &format!("{path}.lo"))?,
        median: number(file, v, &format!("{path}.median"))?,
        hi: number(file, v, &format!("{path}.hi"))?,
        samples: number(file, v, &format!("{path}.samples"))? as usize,
        // Reports before the halves were kept have none: their verdicts stand as the whole
        // interval gives them.
        halves: field(file, v, &format!("{path}.halves"))
            .ok()
            .and_then(|h| Some((h.get(0)?.as_f64()?, h.get(1)?.as_f64()?))),
    })
}

fn array<'a>(file: &Path, v: &'a Value, path: &str) -> Result<&'a Vec<Value>> {
    field(file, v, path)?
        .as_array()
        .ok_or_else(|| bad(file, format!("{path} is not a list")))
}

impl DeviceReport {
    /// Reads `dir/report.json`, as `histencil compare` wrote it.
    ///
    /// # Errors
    /// [`LabError::Settings`] naming the file and the first value missing or malformed.
    pub fn read(dir: &Path) -> Result<Self> {
        let file = dir.join("report.json");
        let bytes = std::fs::read(&file).map_err(|e| bad(&file, format!("cannot read it: {e}")))?;
        let v: Value =
            serde_json::from_slice(&bytes).map_err(|e| bad(&file, format!("is not JSON: {e}")))?;
        let mut rows = Vec::new();
        for (r, row) in array(&file, &v, "rows")?.iter().enumerate() {
            let name = text(&file, row, "technique")?;
            let mut cells = Vec::new();
            for c in 0..array(&file, row, "cells")?.len() {
                let at = |k: &str| format!("rows.{r}.cells.{c}.{k}");
                let brdfs = number(&file, &v, &at("brdfs"))? as usize;
                let overhead = if c == 0 {
                    None
                } else {
                    let ratio = interval(&file, &v, &at("overhead_ratio"))?;
                    Some((ratio, text(&file, &v, &at("verdict_against_1_brdf"))?))
                };
                cells.push(MergedCell {
                    brdfs,
                    lighting: interval(&file, &v, &at("lighting_interval_ms"))?,
                    overhead,
                });
            }
            rows.push((name, cells));
        }
        let mut sizes = Vec::new();
        for (i, _) in array(&file, &v, "light_sizes")?.iter().enumerate() {
            let at = |k: &str| format!("light_sizes.{i}.{k}");
            sizes.push(MergedSize {
                coverage: number(&file, &v, &at("coverage"))?,
                stencil_over_branching: interval(&file, &v, &at("stencil_over_branching"))?,
                faster: text(&file, &v, &at("faster"))?,
            });
        }
        Ok(Self {
            dir: dir.to_owned(),
            device: text(&file, &v, "device")?,
            driver: text(&file, &v, "driver")?,
            scene: text(&file, &v, "settings.scene")?,
            width: number(&file, &v, "settings.width")? as u64,
            height: number(&file, &v, "settings.height")? as u64,
            rounds: number(&file, &v, "table_sampling.rounds")? as u64,
            beside_load: v["settings"]["beside_load_threads"].as_u64().unwrap_or(0),
            busy_elsewhere: busy_elsewhere(&v["stability"]),
            // Reports from before the depth bounds test ran without it.
            depth_bounds: v["settings"]["depth_bounds"].as_bool().unwrap_or(false),
            rows,
            sizes,
            settings: v["settings"].clone(),
        })
    }

    /// Reads each of `dirs` ([`DeviceReport::read`]), in order.
    ///
    /// # Errors
    /// The first folder's whose report is missing or malformed.
    pub fn read_all(dirs: &[PathBuf]) -> Result<Vec<Self>> {
        dirs.iter().map(|dir| Self::read(dir)).collect()
    }

    /// The conditions of the run: "quiet", or the load beside it.
    pub(crate) fn conditions(&self) -> String {
        let mut load = match self.beside_load {
            0 => "quiet".into(),
            n => format!("beside {n} busy threads"),
        };
        if let Some(most) = self.busy_elsewhere {
            load = match self.beside_load {
                0 => format!("beside other processes (up to {most:.2} cores)"),
                _ => format!("{load} and other processes (up to {most:.2} cores)"),
            };
        }
        if self.depth_bounds {
            format!("{load}, depth bounds test")
        } else {
            load
        }
    }

    /// Every verdict of the report, keyed by what it is about, decided again from its interval
    /// by this version's rule ([`Verdict::of`]) whatever word the report stored: a report
    /// written under another rule is judged as the others are.
    fn verdicts(&self) -> Vec<(String, Verdict)> {
        let mut out = Vec::new();
        for (name, cells) in &self.rows {
            for c in cells {
                if let Some((ratio, _)) = &c.overhead {
                    out.push((
                        format!("{name} at {} BRDFs over 1", c.brdfs),
                        Verdict::of(ratio),
                    ));
                }
            }
        }
        for s in &self.sizes {
            let v = Verdict::of(&s.stencil_over_branching);
            out.push((
                format!(
                    "stencil over branching at {} % light size",
                    100.0 * s.coverage
                ),
                v,
            ));
        }
        out
    }

    /// The workload, which every merged report must share.
    fn workload(&self) -> (String, u64, u64, Vec<(String, Vec<usize>)>) {
        let shape = self
            .rows
            .iter()
            .map(|(n, cells)| (n.clone(), cells.iter().map(|c| c.brdfs).collect()))
            .collect();
        (self.scene.clone(), self.width, self.height, shape)
    }
}

/// Several devices' reports of one workload.
#[derive(Clone, Debug)]
pub struct Merged {
    pub reports: Vec<DeviceReport>,
}

impl Merged {
    /// Refuses fewer than two reports, and reports of different workloads (scene, size,
    /// techniques, BRDF counts) or light sizes. One device, driver and conditions twice is a
    /// repeat, whose reversals the merge judges.
    ///
    /// # Errors
    /// [`LabError::Settings`] naming the report that differs and how.
    pub fn new(reports: Vec<DeviceReport>) -> Result<Self> {
        let Some(first) = reports.first() else {
            return Err(LabError::Settings(
                "compare merge needs report folders".into(),
            ));
        };
        if reports.len() < 2 {
            return Err(LabError::Settings(
                "compare merge puts two or more runs side by side; got one report".into(),
            ));
        }
        for r in reports.iter().skip(1) {
            if r.workload() != first.workload() {
                let (s, w, h, _) = r.workload();
                return Err(LabError::Settings(format!(
                    "{} measured scene `{s}` at {w}x{h} with techniques {:?}, {} `{}` at {}x{} \
                     with {:?}: merge runs of one workload (the same compare options)",
                    r.dir.display(),
                    r.rows.iter().map(|(n, _)| n).collect::<Vec<_>>(),
                    first.dir.display(),
                    first.scene,
                    first.width,
                    first.height,
                    first.rows.iter().map(|(n, _)| n).collect::<Vec<_>>(),
                )));
            }
            let coverages =
                |r: &DeviceReport| r.sizes.iter().map(|s| s.coverage).collect::<Vec<_>>();
            if coverages(r) != coverages(first) {
                return Err(LabError::Settings(format!(
                    "{} swept light sizes {:?}, {} {:?}",
                    r.dir.display(),
                    coverages(r),
                    first.dir.display(),
                    coverages(first)
                )));
            }
        }
        Ok(Self { reports })
    }

    /// Every verdict decided one way in one report and the other way in another:
    /// `(what, report a, report b)`.
    pub fn reversals(&self) -> Vec<(String, usize, usize)> {
        self.decided_both()
            .into_iter()
            .filter(|p| p.2.reverses(p.4))
            .map(|(what, a, _, b, _)| (what, a, b))
            .collect()
    }

    /// Every pair of runs' verdicts on the same thing that both decided:
    /// `(what, run a, its verdict, run b, its verdict)`.
    fn decided_both(&self) -> Vec<(String, usize, Verdict, usize, Verdict)> {
        let all: Vec<Vec<(String, Verdict)>> = self.reports.iter().map(|r| r.verdicts()).collect();
        let mut out = Vec::new();
        for a in 0..all.len() {
            for b in a + 1..all.len() {
                for ((what, va), (_, vb)) in all[a].iter().zip(&all[b]) {
                    if va.decided() && vb.decided() {
                        out.push((what.clone(), a, *va, b, *vb));
                    }
                }
            }
        }
        out
    }

    /// The reversals between two runs of one device and driver under the same conditions (a
    /// repeat: the same load beside it, by histencil or other processes, and the same depth
    /// bounds test): noise turning a verdict round, which the margin and the intervals exist to
    /// prevent. Between a quiet and a loaded run a reversal is a finding, listed with the others
    /// and not judged: on lavapipe a load on the cores changes the techniques' ratios
    /// themselves (llvmpipe's rasterizer shares the cores with it, and many small draws fare
    /// otherwise than a few large ones: the talk's stencil on the AMD pretest platform over
    /// branching at 3 BRDFs read 1.11 quiet and 0.86 beside two busy threads, 64x64, 15 rounds).
    pub fn same_device_reversals(&self) -> Vec<(String, usize, usize)> {
        let same = |a: &DeviceReport, b: &DeviceReport| {
            let busy = |d: &DeviceReport| d.busy_elsewhere.is_some();
            (&a.device, &a.driver, a.beside_load, busy(a), a.depth_bounds)
                == (&b.device, &b.driver, b.beside_load, busy(b), b.depth_bounds)
        };
        self.reversals()
            .into_iter()
            .filter(|(_, a, b)| same(&self.reports[*a], &self.reports[*b]))
            .collect()
    }

    /// The tables, in Markdown.
    pub fn markdown(&self) -> String {
        let first = &self.reports[0];
        let mut md = format!(
            "# histencil compare: devices side by side\n\nScene `{}` at {}x{}. Each device's own \
             `histencil compare` run: the median lighting time with its 95 % interval over that \
             run's rounds, and the overhead of n BRDFs over one, paired by round within the run, \
             with its verdict. Runs on different devices share no round, so no verdict is drawn \
             across runs: the last column names the lower where the runs' intervals do not \
             overlap.\n\n| run | device | driver | conditions | table rounds | report |\n\
             |---|---|---|---|---|---|\n",
            first.scene, first.width, first.height
        );
        for (i, r) in self.reports.iter().enumerate() {
            let _ = writeln!(
                md,
                "| run {} | {} | {} | {} | {} | `{}` |",
                i + 1,
                r.device,
                r.driver,
                r.conditions(),
                r.rounds,
                r.dir.display()
            );
        }
        md += "\n## Lighting time against BRDF count\n\n| technique | BRDFs |";
        for i in 0..self.reports.len() {
            let _ = write!(md, " run {} |", i + 1);
        }
        md += " lower |\n|---|---|";
        md += &"---|".repeat(self.reports.len() + 1);
        md += "\n";
        for (t, (name, cells)) in first.rows.iter().enumerate() {
            for (c, cell) in cells.iter().enumerate() {
                let _ = write!(md, "| {name} | {} |", cell.brdfs);
                let here: Vec<&MergedCell> = self.reports.iter().map(|r| &r.rows[t].1[c]).collect();
                for m in &here {
                    let _ = write!(md, " {} |", cell_text(m));
                }
                let _ = writeln!(md, " {} |", self.lower(|r| r.rows[t].1[c].lighting));
            }
        }
        if !first.sizes.is_empty() {
            md += "\n## Stencil over branching per light size\n\nBelow 1 stencil is faster; the \
                   verdict is each run's own.\n\n| light size |";
            for i in 0..self.reports.len() {
                let _ = write!(md, " run {} |", i + 1);
            }
            md += "\n|---|";
            md += &"---|".repeat(self.reports.len());
            md += "\n";
            for (s, size) in first.sizes.iter().enumerate() {
                let _ = write!(md, "| {} % |", 100.0 * size.coverage);
                for r in &self.reports {
                    let i = &r.sizes[s].stencil_over_branching;
                    let faster = match Verdict::of(i) {
                        Verdict::Faster => "stencil",
                        Verdict::Slower => "branching",
                        other => other.word(),
                    };
                    let _ = write!(md, " {:.3} [{:.3}, {:.3}] {faster} |", i.median, i.lo, i.hi);
                }
                md += "\n";
            }
        }
        let decided = self.decided_both();
        let reversals: Vec<_> = decided.iter().filter(|p| p.2.reverses(p.4)).collect();
        let differing = decided.iter().filter(|p| p.2 != p.4).count();
        let pairs = decided.len();
        let _ = writeln!(
            md,
            "\n## Verdicts that reverse\n\nOf {pairs} pairs of runs' verdicts on the same \
             thing that are both decided (faster, slower or within ±5 %), {} reverse (faster \
             in one run, slower in another) and {} differ otherwise (within ±5 % in one, \
             faster or slower in another).\n",
            reversals.len(),
            differing - reversals.len()
        );
        for (what, a, va, b, vb) in &reversals {
            let _ = writeln!(
                md,
                "- {what}: {} in run {}, {} in run {}",
                va.word(),
                a + 1,
                vb.word(),
                b + 1
            );
        }
        md
    }

    /// Which device's interval lies wholly below every other's, or "overlap".
    fn lower(&self, of: impl Fn(&DeviceReport) -> Interval) -> String {
        let intervals: Vec<Interval> = self.reports.iter().map(&of).collect();
        let below_all = |i: usize| {
            intervals
                .iter()
                .enumerate()
                .all(|(j, o)| j == i || intervals[i].hi < o.lo)
        };
        match (0..intervals.len()).find(|&i| below_all(i)) {
            Some(i) => format!("run {}", i + 1),
            None => "overlap".into(),
        }
    }

    /// Every figure of the merge.
    pub fn json(&self) -> Value {
        let reports: Vec<Value> = self
            .reports
            .iter()
            .map(|r| {
                json!({
                    "dir": r.dir.display().to_string(),
                    "device": r.device,
                    "driver": r.driver,
                    "rounds": r.rounds,
                    "conditions": r.conditions(),
                    "rows": r.rows.iter().map(|(name, cells)| json!({
                        "technique": name,
                        "cells": cells.iter().map(|c| {
                            let mut cell = json!({
                                "brdfs": c.brdfs,
                                "lighting_interval_ms": interval_json(&c.lighting),
                            });
                            if let Some((ratio, verdict)) = &c.overhead {
                                cell["overhead_ratio"] = interval_json(ratio);
                                cell["verdict_against_1_brdf"] = json!(verdict);
                            }
                            cell
                        }).collect::<Vec<_>>(),
                    })).collect::<Vec<_>>(),
                    "light_sizes": r.sizes.iter().map(|s| json!({
                        "coverage": s.coverage,
                        "stencil_over_branching": interval_json(&s.stencil_over_branching),
                        "faster": s.faster,
                    })).collect::<Vec<_>>(),
                })
            })
            .collect();
        let first = &self.reports[0];
        json!({
            "scene": first.scene,
            "width": first.width,
            "height": first.height,
            "devices": reports,
        })
    }

    /// Lighting time against BRDF count, one line per technique and device.
    fn plot(&self, path: &Path) -> Result<()> {
        let series: Vec<Series> = self
            .reports
            .iter()
            .flat_map(|r| {
                r.rows.iter().map(move |(name, cells)| Series {
                    name: format!("{name} ({})", r.device),
                    points: cells
                        .iter()
                        .map(|c| (c.brdfs as f64, c.lighting.median))
                        .collect(),
                    bars: cells
                        .iter()
                        .map(|c| (c.lighting.lo, c.lighting.hi))
                        .collect(),
                })
            })
            .collect();
        plot::line_chart(
            path,
            "Lighting time against BRDF count, devices side by side",
            Axis {
                label: "BRDFs in use",
                log: false,
            },
            Axis {
                label: "lighting ms",
                log: true,
            },
            &series,
        )
    }

    /// Writes `merged.md`, `merged.json` and `merged-lighting.png` into `dir`.
    ///
    /// # Errors
    /// I/O and plotting errors.
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>> {
        let md = dir.join("merged.md");
        write_file(&md, self.markdown().as_bytes())?;
        let js = dir.join("merged.json");
        crate::write_json(&js, &self.json())?;
        let png = dir.join("merged-lighting.png");
        self.plot(&png)?;
        Ok(vec![md, js, png])
    }
}

/// `1.234 ms [1.2, 1.3]`, and over one BRDF `(+3.2 % [+1.1, +5.0], slower)`.
fn cell_text(c: &MergedCell) -> String {
    let i = &c.lighting;
    let t = format!("{:.3} ms [{:.3}, {:.3}]", i.median, i.lo, i.hi);
    match &c.overhead {
        None => t,
        Some((r, _)) => {
            let verdict = Verdict::of(r).word();
            let pct = |x: f64| 100.0 * (x - 1.0);
            format!(
                "{t} ({:+.1} % [{:+.1}, {:+.1}], {verdict})",
                pct(r.median),
                pct(r.lo),
                pct(r.hi)
            )
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn report(dir: &str, device: &str, driver: &str, scene: &str) -> DeviceReport {
        let i = |m: f64| Interval {
            lo: m * 0.9,
            median: m,
            hi: m * 1.1,
            samples: 10,
            halves: None,
        };
        DeviceReport {
            dir: dir.into(),
            device: device.into(),
            driver: driver.into(),
            scene: scene.into(),
            width: 320,
            height: 180,
            rounds: 10,
            beside_load: 0,
            busy_elsewhere: None,
            depth_bounds: false,
            rows: vec![(
                "stencil".into(),
                vec![
                    MergedCell {
                        brdfs: 1,
                        lighting: i(1.0),
                        overhead: None,
                    },
                    MergedCell {
                        brdfs: 2,
                        lighting: i(if device == "slow" { 3.0 } else { 1.05 }),
                        overhead: Some((i(1.05), "within ±5 %".into())),
                    },
                ],
            )],
            sizes: vec![MergedSize {
                coverage: 0.01,
                stencil_over_branching: i(0.9),
                faster: "undecided".into(),
            }],
            settings: Value::Null,
        }
    }

    #[test]
    fn merging_refuses_what_is_not_one_workload() {
        let a = report("a", "fast", "Mesa 22.3", "huge-lights");
        let err = |reports| Merged::new(reports).unwrap_err().to_string();
        assert!(err(vec![a.clone()]).contains("two or more runs"));
        assert!(
            err(vec![a.clone(), report("b", "fast", "Mesa 25.0", "town")])
                .contains("merge runs of one workload")
        );
        // A repeat of one device, driver and conditions merges: its reversals are what the
        // merge judges.
        assert!(Merged::new(vec![
            a.clone(),
            report("b", "fast", "Mesa 22.3", "huge-lights")
        ])
        .is_ok());
        // The depth bounds test on and off: one device under two conditions.
        let mut bounded = report("b", "fast", "Mesa 22.3", "huge-lights");
        bounded.depth_bounds = true;
        assert!(Merged::new(vec![a.clone(), bounded.clone()]).is_ok());
        assert!(bounded.conditions().contains("depth bounds test"));
        let mut other_sizes = report("b", "slow", "Mesa 25.0", "huge-lights");
        other_sizes.sizes[0].coverage = 0.1;
        assert!(err(vec![a.clone(), other_sizes]).contains("swept light sizes"));
    }

    #[test]
    fn the_merged_table_names_every_device_and_the_lower_only_where_intervals_part() {
        let merged = Merged::new(vec![
            report("a", "fast", "Mesa 22.3; conformance 1.3", "huge-lights"),
            report("b", "slow", "Mesa 25.0; conformance 1.3", "huge-lights"),
        ])
        .unwrap();
        let md = merged.markdown();
        assert!(
            md.contains(
                "| stencil | 1 | 1.000 ms [0.900, 1.100] | 1.000 ms [0.900, 1.100] | overlap |"
            ),
            "{md}"
        );
        assert!(md.contains("| stencil | 2 |"), "{md}");
        assert!(
            md.contains("3.000 ms [2.700, 3.300] (+5.0 % [-5.5, +15.5], undecided) | run 1 |"),
            "{md}"
        );
        assert!(
            md.contains("| run 2 | slow | Mesa 25.0; conformance 1.3 | quiet | 10 | `b` |"),
            "{md}"
        );
        assert!(
            md.contains("| 1 % | 0.900 [0.810, 0.990] undecided |"),
            "{md}"
        );
        assert_eq!(merged.json()["devices"].as_array().unwrap().len(), 2);
    }

    #[test]
    fn a_verdict_turned_around_in_a_repeat_is_a_same_device_reversal_and_by_load_a_finding() {
        let interval = Interval::of_ten;
        let mut q = report("q", "fast", "Mesa 22.3", "huge-lights");
        let mut loaded = report("l", "fast", "Mesa 22.3", "huge-lights");
        // The verdicts come from the intervals, whatever word a report stored.
        q.sizes[0].stencil_over_branching = interval(1.1, 1.2, 1.3);
        q.sizes[0].faster = "stencil".into();
        loaded.sizes[0].stencil_over_branching = interval(0.96, 1.0, 1.04);
        let merged = Merged::new(vec![q.clone(), loaded.clone()]).unwrap();
        assert!(
            merged.same_device_reversals().is_empty(),
            "within the margin is no reversal"
        );
        assert!(
            merged.markdown().contains("Of 1 pairs"),
            "{}",
            merged.markdown()
        );
        assert!(merged
            .markdown()
            .contains("0 reverse (faster in one run, slower in another) and 1 differ otherwise"));
        // A repeat (the same conditions) that reverses: judged.
        loaded.sizes[0].stencil_over_branching = interval(0.7, 0.8, 0.9);
        let merged = Merged::new(vec![q.clone(), loaded.clone()]).unwrap();
        let reversed = merged.same_device_reversals();
        assert_eq!(reversed.len(), 1, "{reversed:?}");
        assert_eq!(reversed[0].0, "stencil over branching at 1 % light size");
        // The same reversal beside busy threads: listed, a finding, not judged.
        loaded.beside_load = 2;
        let merged = Merged::new(vec![q.clone(), loaded.clone()]).unwrap();
        assert_eq!(merged.reversals().len(), 1);
        assert!(merged.same_device_reversals().is_empty());
        let md = merged.markdown();
        assert!(md.contains("1 reverse"), "{md}");
        assert!(
            md.contains("slower in run 1, faster in run 2")
                && md.contains("| run 2 | fast | Mesa 22.3 | beside 2 busy threads |")
                && md.contains("| 1 % | 1.200 [1.100, 1.300] branching |"),
            "{md}"
        );
        // Across devices a reversal is a finding, not a failure.
        let mut other = loaded.clone();
        other.device = "slow".into();
        other.beside_load = 0;
        let merged = Merged::new(vec![q, other]).unwrap();
        assert_eq!(
            (
                merged.reversals().len(),
                merged.same_device_reversals().len()
            ),
            (1, 0)
        );
    }

    /// A run during which other processes kept cores busy (its steady clock's record) is a run
    /// of other conditions: it merges beside a quiet run of the same device and driver, and the
    /// merged table names the load.
    #[test]
    fn a_run_beside_other_processes_is_named_as_its_own_conditions() {
        use crate::steady::{CanaryTime, ClockSettings, SetStability, Stability};
        let stability = |loads: &[f64]| {
            let canary = loads.iter().enumerate().map(|(round, l)| CanaryTime {
                round,
                ms: 1.0,
                reference_ms: 1.0,
                foreign_load: Some(*l),
            });
            Stability {
                workload: "test".into(),
                settings: ClockSettings::default(),
                sets: vec![SetStability {
                    canary: canary.collect(),
                    ..SetStability::default()
                }],
            }
            .json()
        };
        assert_eq!(busy_elsewhere(&stability(&[0.0, 0.06, 0.02])), None);
        assert_eq!(busy_elsewhere(&stability(&[0.99, 1.03, 0.2])), Some(1.03));
        assert_eq!(
            busy_elsewhere(&json!({})),
            None,
            "a report before the clock read it"
        );
        let q = report("q", "fast", "Mesa 22.3", "huge-lights");
        let mut busy = report("b", "fast", "Mesa 22.3", "huge-lights");
        busy.busy_elsewhere = Some(1.03);
        // A reversal against it is listed, not judged (the CLI exits 0).
        let interval = Interval::of_ten;
        let mut q = q;
        q.sizes[0].stencil_over_branching = interval(1.1, 1.2, 1.3);
        busy.sizes[0].stencil_over_branching = interval(0.7, 0.8, 0.9);
        let merged = Merged::new(vec![q, busy]).unwrap();
        assert_eq!(merged.reversals().len(), 1);
        assert!(merged.same_device_reversals().is_empty());
        let md = merged.markdown();
        assert!(
            md.contains("| run 2 | fast | Mesa 22.3 | beside other processes (up to 1.03 cores) |"),
            "{md}"
        );
    }

    #[test]
    fn a_report_missing_a_value_is_refused_naming_it() {
        let dir = std::env::temp_dir().join(format!("histencil-merge-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(
            dir.join("report.json"),
            br#"{"rows": [], "light_sizes": []}"#,
        )
        .unwrap();
        let err = DeviceReport::read(&dir).unwrap_err().to_string();
        assert!(err.contains("report.json: has no device"), "{err}");
        std::fs::write(dir.join("report.json"), b"{").unwrap();
        assert!(DeviceReport::read(&dir)
            .unwrap_err()
            .to_string()
            .contains("is not JSON"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
