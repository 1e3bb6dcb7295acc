//! The run's reports: JUnit XML (a testsuite per scene, a testcase per configuration) that
//! GitHub Actions, GitLab and Jenkins read as is, JSON with every case's numbers (which `check
//! merge` reads back to join shards), `results.csv` and `failures.csv` as deqp-runner writes
//! them, and a summary that fits on one screen. All of it is written from [`Record`]s, the
//! rows a worker process sends the runner.

use crate::judge::{ImageError, Tolerance};
use crate::lists::Status;
use crate::matrix::{alpha_name, flush_name, Expect, KnownWrong};
use crate::run::{CaseResult, CheckReport, Outcome};
use serde_json::{json, Value};
use std::collections::BTreeMap;
use std::fmt::Write as _;

/// What kind of failure a failed case is: `validation` (any message), `image`, `stencil`,
/// `blind` (a known-wrong case passed) or `error` (the case could not run).
pub fn failure_type(r: &CaseResult) -> &'static str {
    if !r.validation.is_empty() {
        "validation"
    } else if matches!(r.case.map(|c| c.expect), Some(Expect::Wrong(_))) {
        "blind"
    } else if r.image.as_ref().is_some_and(|v| !v.passed()) {
        "image"
    } else if !r.stencil_problems.is_empty() {
        "stencil"
    } else {
        "error"
    }
}

/// Everything known about a case, as the body of its JUnit element.
fn details(r: &CaseResult) -> String {
    let mut out = String::new();
    if let Some(note) = &r.note {
        let _ = writeln!(out, "{note}");
    }
    if let Some(v) = &r.image {
        let _ = writeln!(out, "image: {}", v.describe());
    }
    for p in &r.stencil_problems {
        let _ = writeln!(out, "stencil: {p}");
    }
    for m in &r.validation {
        let _ = writeln!(out, "{m}");
    }
    for a in &r.artifacts {
        let _ = writeln!(out, "wrote {}", a.display());
    }
    out
}

fn error_json(e: &ImageError, t: &Tolerance) -> Value {
    json!({
        "max": e.max, "mean": e.mean, "pixels": e.pixels, "beyond_max": e.over,
        "bound_max": t.max, "bound_mean": t.mean,
    })
}

/// Text safe inside an XML attribute or element: the five entities escaped, and characters XML
/// 1.0 cannot hold (most control characters) replaced.
fn xml(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\t' | '\n' | '\r' => out.push(c),
            c if (c as u32) < 0x20 || c == '\u{FFFE}' || c == '\u{FFFF}' => out.push('\u{FFFD}'),
            c => out.push(c),
        }
    }
    out
}

/// A case's numbers as JSON: its configuration, image error, stencil problems and validation
/// messages.
fn case_json(r: &CaseResult) -> Value {
    let config = r.case.map(|case| {
        let expect = match case.expect {
            Expect::Reference => "reference".to_owned(),
            Expect::Exact => "exact".to_owned(),
            Expect::Lut => "lut".to_owned(),
            Expect::Alpha => "alpha".to_owned(),
            Expect::Wrong(KnownWrong::PreservedBitsNotZeroed) => {
                "known-wrong: preserved bits not zeroed".to_owned()
            }
            Expect::Wrong(KnownWrong::StaleHiStencil) => "known-wrong: stale hi-stencil".to_owned(),
            Expect::Wrong(KnownWrong::AndOrReadMaskIgnored) => {
                "known-wrong: AND/OR without the read mask".to_owned()
            }
        };
        let mut v = json!({
            "format": case.format.vk_name(),
            "width": case.width,
            "height": case.height,
            "expect": expect,
        });
        if let Some(c) = case.config {
            v["lighting"] = json!(c.lighting.name());
            v["backend"] = json!(c.platform.name());
            v["flush"] = json!(flush_name(c.flush));
            v["preserved_pattern"] = json!(c.pattern);
            v["alpha"] = json!(alpha_name(c.alpha));
        }
        v
    });
    let image = r.image.as_ref().map(|v| {
        let mut image = error_json(&v.error, &v.tolerance);
        image["pixels_judged"] = json!(if v.alpha_covered {
            "alpha-covered"
        } else {
            "all"
        });
        image
    });
    json!({
        "config": config,
        "image": image,
        "stencil_problems": r.stencil_problems,
        "validation": r.validation.iter().map(|m| json!({
            "severity": m.severity, "id": m.id, "text": m.text
        })).collect::<Vec<_>>(),
        "accepted_messages": r.accepted,
        "note": r.note,
        "artifacts": r.artifacts.iter().map(|a| a.display().to_string()).collect::<Vec<_>>(),
    })
}

/// One case as the runner keeps it: what a worker sends its parent (a JSON line), what the
/// reports and CSV files are written from, and what `check merge` reads back from JSON.
#[derive(Clone, Debug, PartialEq)]
pub struct Record {
    /// The scene as asked for; `device` for a context's canary and teardown.
    pub scene: String,
    pub name: String,
    pub status: Status,
    pub seconds: f64,
    /// Why it failed, was skipped, or how the runner classified it.
    pub reason: Option<String>,
    /// `validation`, `image`, `stencil`, `blind`, `error`, `crash`, `timeout` or `muted`.
    pub failure_type: Option<String>,
    /// Everything known about it, as text (the body of its JUnit element).
    pub details: String,
    /// Its numbers (see `case_json`); `null` for a case that never reported.
    pub data: Value,
}

impl Record {
    /// `scene/case`: the name baselines, case lists, shards and filters use.
    pub fn full_name(&self) -> String {
        format!("{}/{}", self.scene, self.name)
    }

    pub fn from_result(r: &CaseResult) -> Record {
        let (status, reason, failure) = match &r.outcome {
            Outcome::Passed => (Status::Pass, None, None),
            Outcome::Failed(why) => (Status::Fail, Some(why.clone()), Some(failure_type(r))),
            Outcome::Skipped(why) => (Status::Skip, Some(why.clone()), None),
            Outcome::Muted(why) => (
                Status::ValidationLayerMuted,
                Some(why.clone()),
                Some("muted"),
            ),
        };
        Record {
            scene: r.scene.clone(),
            name: r.name.clone(),
            status,
            seconds: r.seconds,
            reason,
            failure_type: failure.map(str::to_owned),
            details: details(r),
            data: case_json(r),
        }
    }

    pub fn to_json(&self) -> Value {
        json!({
            "scene": self.scene,
            "name": self.name,
            "status": self.status.name(),
            "seconds": self.seconds,
            "reason": self.reason,
            "failure_type": self.failure_type,
            "details": self.details,
            "data": self.data,
        })
    }

    /// The inverse of [`Record::to_json`]; `None` for anything else.
    pub fn from_json(v: &Value) -> Option<Record> {
        let text = |k: &str| v.get(k).and_then(Value::as_str).map(str::to_owned);
        Some(Record {
            scene: text("scene")?,
            name: text("name")?,
            status: Status::parse(v.get("status")?.as_str()?)?,
            seconds: v.get("seconds")?.as_f64()?,
            reason: text("reason"),
            failure_type: text("failure_type"),
            details: text("details").unwrap_or_default(),
            data: v.get("data").cloned().unwrap_or(Value::Null),
        })
    }
}

/// A worker that ran: how many cases it finished and its peak resident memory.
#[derive(Clone, Debug, PartialEq)]
pub struct WorkerInfo {
    pub cases: usize,
    /// Peak resident set (VmHWM) in MiB, as the worker last reported or as read before it was
    /// killed; `None` where neither could be read.
    pub peak_mib: Option<f64>,
    /// How the worker ended: `ok`, `crash: ...`, `timeout`, `stopped`.
    pub end: String,
}

/// A whole run (or several shards merged): what every report is written from.
#[derive(Clone, Debug, Default)]
pub struct RunReport {
    pub device: String,
    /// Driver name, build, conformance and the validation layer's version.
    pub driver: String,
    /// The validation settings the verdict rests on, and what was cleared from the environment.
    pub settings: Vec<String>,
    /// User-accepted message ids, reasons and how often each arrived.
    pub accepted: Vec<(String, String)>,
    pub best_practices: bool,
    pub quick: bool,
    /// `K/N` where the run was one shard; several where shards were merged.
    pub shards: Vec<String>,
    pub seconds: f64,
    pub records: Vec<Record>,
    pub workers: Vec<WorkerInfo>,
    /// Unexpected passes do not fail the run.
    pub allow_unexpected_pass: bool,
    /// The run stopped early (a signal, `--max-fails`): the records are what completed.
    pub incomplete: Option<String>,
}

impl RunReport {
    pub fn count(&self, status: Status) -> usize {
        self.records.iter().filter(|r| r.status == status).count()
    }

    /// Cases whose final status fails the run.
    pub fn failing(&self) -> Vec<&Record> {
        self.records
            .iter()
            .filter(|r| r.status.fails_run(self.allow_unexpected_pass))
            .collect()
    }

    /// A run from an in-process [`CheckReport`] (no runner, no baseline).
    pub fn from_check(report: &CheckReport) -> RunReport {
        RunReport {
            device: report.device.clone(),
            driver: report.driver.to_string(),
            best_practices: report.best_practices,
            quick: report.quick,
            seconds: report.seconds,
            records: report.results.iter().map(Record::from_result).collect(),
            ..RunReport::default()
        }
    }

    /// The suites in first-seen order: scenes as given, then `device`.
    fn suites(&self) -> Vec<(&str, Vec<&Record>)> {
        let mut suites: Vec<(&str, Vec<&Record>)> = Vec::new();
        for r in &self.records {
            match suites.iter_mut().find(|(name, _)| *name == r.scene) {
                Some((_, cases)) => cases.push(r),
                None => suites.push((&r.scene, vec![r])),
            }
        }
        suites
    }
}

/// The JUnit XML of a run. A case that fails the run is a `<failure>` (an unexpected pass
/// included, unless allowed); skips and expected failures are `<skipped>` with their reason;
/// flakes pass with their story in `<system-out>`.
pub fn junit(report: &RunReport) -> String {
    let mut out = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let skipped = |r: &Record| matches!(r.status, Status::Skip | Status::ExpectedFail);
    let _ = writeln!(
        out,
        "<testsuites name=\"histencil check\" tests=\"{}\" failures=\"{}\" errors=\"0\" \
         skipped=\"{}\" time=\"{:.3}\">",
        report.records.len(),
        report.failing().len(),
        report.records.iter().filter(|r| skipped(r)).count(),
        report.seconds
    );
    let validation = if report.best_practices {
        "Khronos validation layer, synchronization validation, best practices"
    } else {
        "Khronos validation layer, synchronization validation"
    };
    let mut properties = vec![
        ("device", report.device.clone()),
        ("driver", report.driver.clone()),
        ("validation", validation.to_owned()),
    ];
    properties.extend(report.settings.iter().map(|s| ("setting", s.clone())));
    properties.extend(
        report
            .accepted
            .iter()
            .map(|(id, why)| ("accepted-message", format!("{id}: {why}"))),
    );
    if let Some(why) = &report.incomplete {
        properties.push(("incomplete", why.clone()));
    }
    for (scene, cases) in report.suites() {
        let failed = cases
            .iter()
            .filter(|r| r.status.fails_run(report.allow_unexpected_pass))
            .count();
        let time: f64 = cases.iter().map(|r| r.seconds).sum();
        let _ = writeln!(
            out,
            "  <testsuite name=\"{}\" tests=\"{}\" failures=\"{failed}\" errors=\"0\" \
             skipped=\"{}\" time=\"{time:.3}\">",
            xml(scene),
            cases.len(),
            cases.iter().filter(|r| skipped(r)).count(),
        );
        let _ = writeln!(out, "    <properties>");
        for (name, value) in &properties {
            let _ = writeln!(
                out,
                "      <property name=\"{name}\" value=\"{}\"/>",
                xml(value)
            );
        }
        let _ = writeln!(out, "    </properties>");
        let classname = format!("histencil.{}", xml(&scene.replace(['.', '/', '\\'], "_")));
        for r in cases {
            let _ = write!(
                out,
                "    <testcase name=\"{}\" classname=\"{classname}\" time=\"{:.3}\"",
                xml(&r.name),
                r.seconds
            );
            let reason = r.reason.clone().unwrap_or_default();
            if r.status.fails_run(report.allow_unexpected_pass) {
                let kind = r.failure_type.as_deref().unwrap_or("unexpected-pass");
                let _ = writeln!(
                    out,
                    ">\n      <failure message=\"{}: {}\" type=\"{kind}\">{}</failure>\n    </testcase>",
                    r.status,
                    xml(&reason),
                    xml(&r.details)
                );
            } else if skipped(r) {
                let _ = writeln!(
                    out,
                    ">\n      <skipped message=\"{}: {}\"/>\n    </testcase>",
                    r.status,
                    xml(&reason)
                );
            } else if r.details.is_empty() && r.reason.is_none() {
                out.push_str("/>\n");
            } else {
                let body = format!("{}{}{}", r.status, reason_line(r), r.details);
                let _ = writeln!(
                    out,
                    ">\n      <system-out>{}</system-out>\n    </testcase>",
                    xml(&body)
                );
            }
        }
        let _ = writeln!(out, "  </testsuite>");
    }
    out.push_str("</testsuites>\n");
    out
}

fn reason_line(r: &Record) -> String {
    r.reason
        .as_ref()
        .map(|why| format!(": {why}\n"))
        .unwrap_or_else(|| "\n".to_owned())
}

/// The JSON of a run: the device, driver and settings, the tally by status, the workers, and
/// every case with its numbers. `check merge` reads it back ([`from_json`]).
pub fn json(report: &RunReport) -> Value {
    let tally: serde_json::Map<String, Value> = Status::ALL
        .iter()
        .map(|s| (s.name().to_owned(), json!(report.count(*s))))
        .collect();
    json!({
        "device": report.device,
        "driver": report.driver,
        "validation_settings": report.settings,
        "accepted_messages": report.accepted.iter()
            .map(|(id, why)| json!({"id": id, "reason": why})).collect::<Vec<_>>(),
        "quick": report.quick,
        "best_practices": report.best_practices,
        "shards": report.shards,
        "seconds": report.seconds,
        "tests": report.records.len(),
        "failing": report.failing().len(),
        "allow_unexpected_pass": report.allow_unexpected_pass,
        "incomplete": report.incomplete,
        "statuses": tally,
        "workers": report.workers.iter().map(|w| json!({
            "cases": w.cases, "peak_mib": w.peak_mib, "end": w.end,
        })).collect::<Vec<_>>(),
        "cases": report.records.iter().map(Record::to_json).collect::<Vec<_>>(),
    })
}

/// A run read back from [`json()`]'s output, or why it is not one.
pub fn from_json(v: &Value) -> Result<RunReport, String> {
    let cases = v
        .get("cases")
        .and_then(Value::as_array)
        .ok_or("no `cases` array: not a histencil check JSON report")?;
    let records = cases
        .iter()
        .enumerate()
        .map(|(i, c)| Record::from_json(c).ok_or(format!("case {i} is not a check record")))
        .collect::<Result<Vec<_>, _>>()?;
    let text = |k: &str| v.get(k).and_then(Value::as_str).unwrap_or("").to_owned();
    let strings = |k: &str| -> Vec<String> {
        v.get(k)
            .and_then(Value::as_array)
            .map(|a| {
                a.iter()
                    .filter_map(|s| s.as_str().map(str::to_owned))
                    .collect()
            })
            .unwrap_or_default()
    };
    let flag = |k: &str| v.get(k).and_then(Value::as_bool).unwrap_or(false);
    Ok(RunReport {
        device: text("device"),
        driver: text("driver"),
        settings: strings("validation_settings"),
        accepted: v
            .get("accepted_messages")
            .and_then(Value::as_array)
            .map(|a| {
                a.iter()
                    .map(|m| {
                        let t = |k: &str| m.get(k).and_then(Value::as_str).unwrap_or("").to_owned();
                        (t("id"), t("reason"))
                    })
                    .collect()
            })
            .unwrap_or_default(),
        best_practices: flag("best_practices"),
        quick: flag("quick"),
        shards: strings("shards"),
        seconds: v.get("seconds").and_then(Value::as_f64).unwrap_or(0.0),
        records,
        workers: v
            .get("workers")
            .and_then(Value::as_array)
            .map(|a| {
                a.iter()
                    .map(|w| WorkerInfo {
                        cases: w.get("cases").and_then(Value::as_u64).unwrap_or(0) as usize,
                        peak_mib: w.get("peak_mib").and_then(Value::as_f64),
                        end: w
                            .get("end")
                            .and_then(Value::as_str)
                            .unwrap_or("")
                            .to_owned(),
                    })
                    .collect()
            })
            .unwrap_or_default(),
        allow_unexpected_pass: flag("allow_unexpected_pass"),
        incomplete: v
            .get("incomplete")
            .and_then(Value::as_str)
            .map(str::to_owned),
    })
}

/// Several shards' runs as one: their cases in order, device rows (canaries, teardowns) kept
/// per shard, the slowest shard's time. Shards of different devices or drivers are refused, and
/// so is a set of shards with one missing (a shard whose job died before writing its report
/// would otherwise leave a green merge) or one twice.
pub fn merge(runs: Vec<RunReport>) -> Result<RunReport, String> {
    let shards: Vec<crate::lists::Shard> = runs
        .iter()
        .flat_map(|r| &r.shards)
        .map(|s| crate::lists::Shard::parse(s).map_err(|e| format!("a report names {e}")))
        .collect::<Result<_, _>>()?;
    if let Some(first) = shards.first() {
        let (count, interleaved) = (first.count, first.interleaved);
        if shards
            .iter()
            .any(|s| s.count != count || s.interleaved != interleaved)
            || runs.iter().any(|r| r.shards.is_empty())
        {
            return Err("the reports are shards of different splits (or some not a shard)".into());
        }
        if let Some(twice) = shards
            .iter()
            .enumerate()
            .find(|(i, s)| shards[..*i].contains(s))
            .map(|(_, s)| s)
        {
            return Err(format!("shard {twice} is given twice"));
        }
        let missing: Vec<String> = (1..=count)
            .filter(|k| !shards.iter().any(|s| s.index == *k))
            .map(|k| {
                crate::lists::Shard::new(k, count, interleaved)
                    .map(|s| s.to_string())
                    .unwrap_or_default()
            })
            .collect();
        if !missing.is_empty() {
            return Err(format!(
                "shard {} missing: no report of it",
                missing.join(", ")
            ));
        }
    }
    let mut runs = runs.into_iter();
    let mut merged = runs.next().ok_or("nothing to merge")?;
    for run in runs {
        if run.driver != merged.driver || run.device != merged.device {
            return Err(format!(
                "shards ran on different drivers: `{} / {}` and `{} / {}`",
                merged.device, merged.driver, run.device, run.driver
            ));
        }
        let seen: std::collections::HashSet<String> =
            merged.records.iter().map(Record::full_name).collect();
        for r in run.records {
            if r.scene != "device" && seen.contains(&r.full_name()) {
                return Err(format!("`{}` is in two shards", r.full_name()));
            }
            merged.records.push(r);
        }
        merged.shards.extend(run.shards);
        merged.workers.extend(run.workers);
        merged.seconds = merged.seconds.max(run.seconds);
        merged.quick &= run.quick;
        merged.allow_unexpected_pass &= run.allow_unexpected_pass;
        merged.incomplete = merged.incomplete.or(run.incomplete);
        for s in run.settings {
            if !merged.settings.contains(&s) {
                merged.settings.push(s);
            }
        }
    }
    Ok(merged)
}

/// A `results.csv` line: `scene/case,Status,seconds` (deqp-runner's columns).
pub fn results_line(r: &Record) -> String {
    format!("{},{},{:.3}\n", r.full_name(), r.status, r.seconds)
}

/// Every matrix case that ended failing, in run order, as the failure it ended with
/// (`Fail`, `Crash` or `Timeout`), expected failures as the failure they are. Flakes and
/// unexpected passes are left out (the baseline shrinks); device rows cannot be baselined.
pub fn failing(report: &RunReport) -> Vec<(String, Status)> {
    report
        .records
        .iter()
        .filter(|r| r.scene != "device")
        .filter_map(|r| {
            let status = match r.status {
                // The failure it was expected as, from the kind the worker or runner gave it.
                Status::ExpectedFail => match r.failure_type.as_deref() {
                    Some("crash") => Status::Crash,
                    Some("timeout") => Status::Timeout,
                    _ => Status::Fail,
                },
                s if s.is_failure() => s,
                _ => return None,
            };
            Some((r.full_name(), status))
        })
        .collect()
}

/// `failures.csv`: [`failing`] in the baseline's own format, so that a run's failures are a
/// baseline ([`crate::baseline_update`] keeps an old one's reasons).
pub fn failures_csv(report: &RunReport) -> String {
    let mut out = String::from(
        "# histencil check failures, in --baseline format: copy to a baseline to expect them\n",
    );
    for (name, status) in failing(report) {
        let _ = writeln!(out, "{name},{status}");
    }
    out
}

/// The summary: the device and driver, totals by status, a line per scene, the workers, the
/// known-wrong cases' tally, skip reasons grouped, and the first failures with their reasons.
pub fn summary(report: &RunReport) -> String {
    let mut out = String::new();
    // The device's own rows (each worker's canary and teardown) are records too, but not cases
    // of the matrix: they are tallied apart, so the case count matches what `--list` and the
    // progress lines counted.
    let is_device = |r: &&Record| r.scene == "device";
    let tally = |device: bool| -> String {
        let counts: Vec<String> = Status::ALL
            .iter()
            .map(|s| {
                let of = |r: &&Record| is_device(r) == device && r.status == *s;
                (s, report.records.iter().filter(of).count())
            })
            .filter(|(_, n)| *n > 0)
            .map(|(s, n)| format!("{n} {s}"))
            .collect();
        if counts.is_empty() {
            "none".to_owned()
        } else {
            counts.join(", ")
        }
    };
    let device_rows = report.records.iter().filter(is_device).count();
    let checks = match device_rows {
        0 => String::new(),
        _ => format!("; device checks (canaries, teardowns): {}", tally(true)),
    };
    let _ = writeln!(
        out,
        "histencil check: {} cases on {} in {:.1} s: {}{checks}",
        report.records.len() - device_rows,
        report.device,
        report.seconds,
        tally(false),
    );
    let _ = writeln!(out, "driver: {}", report.driver);
    if let Some(why) = &report.incomplete {
        let _ = writeln!(out, "INCOMPLETE: {why}");
    }
    let suites = report.suites();
    let width = suites
        .iter()
        .map(|(s, _)| s.len())
        .max()
        .unwrap_or(0)
        .max(5);
    let _ = writeln!(
        out,
        "  {:<width$} {:>6} {:>7} {:>7} {:>8} {:>9}",
        "scene", "cases", "passed", "failing", "skipped", "time"
    );
    for (scene, cases) in &suites {
        let n = |f: &dyn Fn(&Record) -> bool| cases.iter().filter(|r| f(r)).count();
        let time: f64 = cases.iter().map(|r| r.seconds).sum();
        let _ = writeln!(
            out,
            "  {:<width$} {:>6} {:>7} {:>7} {:>8} {:>7.1} s",
            scene,
            cases.len(),
            n(&|r| matches!(r.status, Status::Pass | Status::Flake)),
            n(&|r| r.status.fails_run(report.allow_unexpected_pass)),
            n(&|r| matches!(r.status, Status::Skip | Status::ExpectedFail)),
            time
        );
    }
    if !report.workers.is_empty() {
        let peak = report
            .workers
            .iter()
            .filter_map(|w| w.peak_mib)
            .fold(0.0f64, f64::max);
        let ends: BTreeMap<&str, usize> =
            report.workers.iter().fold(BTreeMap::new(), |mut m, w| {
                *m.entry(w.end.split(':').next().unwrap_or("")).or_default() += 1;
                m
            });
        let ends: Vec<String> = ends.iter().map(|(e, n)| format!("{n} {e}")).collect();
        let _ = writeln!(
            out,
            "workers: {} ({}), peak resident {peak:.0} MiB",
            report.workers.len(),
            ends.join(", ")
        );
    }
    let wrong: Vec<&Record> = report
        .records
        .iter()
        .filter(|r| {
            r.data["config"]["expect"]
                .as_str()
                .is_some_and(|e| e.starts_with("known-wrong"))
        })
        .collect();
    if !wrong.is_empty() {
        let n = |s: &dyn Fn(Status) -> bool| wrong.iter().filter(|r| s(r.status)).count();
        let _ = writeln!(
            out,
            "known-wrong cases: {} failed as expected, {} not applicable (skipped), {} failed \
             to fail or did not run",
            n(&|s| s == Status::Pass),
            n(&|s| s == Status::Skip),
            n(&|s| s.is_failure())
        );
    }
    let mut skips: BTreeMap<String, usize> = BTreeMap::new();
    for r in &report.records {
        if r.status == Status::Skip {
            *skips
                .entry(r.reason.clone().unwrap_or_default())
                .or_default() += 1;
        }
    }
    for (why, count) in &skips {
        let _ = writeln!(out, "skipped {count} x: {why}");
    }
    for status in [Status::ExpectedFail, Status::Flake] {
        let n = report.count(status);
        if n > 0 {
            let _ = writeln!(out, "{status}: {n} (see failures.csv and the JSON report)");
        }
    }
    let failures = report.failing();
    for r in failures.iter().take(20) {
        let _ = writeln!(
            out,
            "{} {}: {}",
            r.status,
            r.full_name(),
            r.reason.as_deref().unwrap_or("")
        );
    }
    if failures.len() > 20 {
        let _ = writeln!(
            out,
            "... and {} more failing cases (see results.csv and the JUnit or JSON report)",
            failures.len() - 20
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::matrix::{cases, SceneNeeds};
    use histencil_vk::{DepthStencilFormat, ValidationMessage};

    fn report() -> RunReport {
        let needs = SceneNeeds {
            preserved_mask: 0xFC,
            has_alpha: false,
            lut: true,
            lights_at_a_point: 8,
            emissive: false,
            alpha_layers: 0,
        };
        let all = cases(needs, DepthStencilFormat::D32S8, (7, 5));
        let result = |case: crate::matrix::Case, outcome| CaseResult {
            scene: "a<b>&\"c\"".into(),
            name: case.name(),
            case: Some(case),
            outcome,
            seconds: 0.25,
            image: None,
            stencil_problems: vec![],
            validation: vec![],
            accepted: 0,
            note: None,
            artifacts: vec![],
        };
        let mut failed = result(all[1], Outcome::Failed("max 9/255 > 1/255".into()));
        failed.validation.push(ValidationMessage {
            severity: "ERROR",
            id: "SYNC-HAZARD-WRITE-AFTER-READ".into(),
            text: "bad \u{1} <thing>".into(),
        });
        RunReport::from_check(&CheckReport {
            device: "llvmpipe".into(),
            driver: Default::default(),
            best_practices: false,
            quick: true,
            results: vec![
                result(all[0], Outcome::Passed),
                failed,
                result(all[2], Outcome::Skipped("missing format: D24".into())),
            ],
            seconds: 1.5,
        })
    }

    #[test]
    fn junit_counts_escapes_and_types_failures() {
        let xml = junit(&report());
        assert!(xml.starts_with("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites"));
        assert!(xml.contains("tests=\"3\" failures=\"1\" errors=\"0\" skipped=\"1\""));
        assert!(xml.contains("<testsuite name=\"a&lt;b&gt;&amp;&quot;c&quot;\""));
        assert!(xml.contains("type=\"validation\""));
        assert!(xml.contains("bad \u{FFFD} &lt;thing&gt;"));
        assert!(xml.contains("<skipped message=\"Skip: missing format: D24\"/>"));
        assert_eq!(xml.matches("<testcase ").count(), 3);
        assert_eq!(xml.matches("</testsuite>").count(), 1);
        assert!(!xml.contains('\u{1}'));
    }

    #[test]
    fn json_and_summary_carry_every_case_and_json_reads_back() {
        let r = report();
        let v = json(&r);
        assert_eq!(v["cases"].as_array().unwrap().len(), 3);
        assert_eq!(v["failing"], 1);
        assert_eq!(v["cases"][1]["failure_type"], "validation");
        assert_eq!(
            v["cases"][1]["data"]["validation"][0]["id"],
            "SYNC-HAZARD-WRITE-AFTER-READ"
        );
        let s = summary(&r);
        assert!(s.contains("1 Pass, 1 Fail, 1 Skip"), "{s}");
        assert!(s.contains("Fail a<b>&\"c\"/"), "{s}");
        let back = from_json(&v).unwrap();
        assert_eq!(back.records, r.records);
        assert_eq!(junit(&back), junit(&r));
    }

    #[test]
    fn the_summary_counts_cases_as_listed_and_the_device_checks_apart() {
        let mut r = report();
        let mut canary = r.records[0].clone();
        (canary.scene, canary.name) = ("device".into(), "canary-d32_sfloat_s8_uint".into());
        r.records.push(canary);
        let first = summary(&r).lines().next().unwrap().to_owned();
        assert!(
            first.starts_with("histencil check: 3 cases on llvmpipe in 1.5 s: 1 Pass, 1 Fail"),
            "{first}"
        );
        assert!(
            first.ends_with("; device checks (canaries, teardowns): 1 Pass"),
            "{first}"
        );
    }

    #[test]
    fn failures_csv_is_a_baseline_and_merge_refuses_overlaps() {
        let mut r = report();
        r.records[2].status = Status::ExpectedFail;
        r.records[2].reason = Some("expected Crash (baseline)".into());
        r.records[2].failure_type = Some("crash".into());
        let csv = failures_csv(&r);
        let baseline = crate::lists::Baseline::parse(&csv, "failures.csv").unwrap();
        assert_eq!(baseline.expected.len(), 2, "{csv}");
        assert_eq!(baseline.expected[&r.records[1].full_name()], Status::Fail);
        assert_eq!(baseline.expected[&r.records[2].full_name()], Status::Crash);
        assert!(merge(vec![report(), report()]).is_err());
        let (mut a, mut b) = (report(), report());
        a.records.truncate(1);
        b.records.remove(0);
        assert_eq!(
            merge(vec![a.clone(), b.clone()]).unwrap().records,
            report().records
        );
        // Shards: all of them, once each.
        a.shards = vec!["1/3".into()];
        b.shards = vec!["3/3".into()];
        let err = merge(vec![a.clone(), b.clone()]).unwrap_err();
        assert!(err.contains("shard 2/3 missing"), "{err}");
        b.shards = vec!["1/3".into()];
        assert!(merge(vec![a.clone(), b.clone()]).is_err());
        // Mesa's interleaved parts join the same way, never with hash shards.
        a.shards = vec!["fraction 1/2".into()];
        b.shards = vec!["2/2".into()];
        let err = merge(vec![a.clone(), b.clone()]).unwrap_err();
        assert!(err.contains("different splits"), "{err}");
        b.shards = vec!["fraction 2/2".into()];
        assert_eq!(
            merge(vec![a, b]).unwrap().shards,
            ["fraction 1/2", "fraction 2/2"]
        );
    }
}
