//! The run's reports: JUnit XML (a testsuite per scene, a testcase per configuration) that
//! GitHub Actions, GitLab and Jenkins read as is, JSON with every case's numbers, and a summary
//! that fits on one screen.

use crate::judge::{ImageError, Tolerance};
use crate::matrix::{alpha_name, flush_name, Expect, KnownWrong};
use crate::run::{CaseResult, CheckReport, Outcome};
use serde_json::{json, Value};
use std::collections::BTreeMap;
use std::fmt::Write as _;

/// The suites in first-seen order: scenes as given, then `device` (the teardowns).
fn suites(report: &CheckReport) -> Vec<(&str, Vec<&CaseResult>)> {
    let mut suites: Vec<(&str, Vec<&CaseResult>)> = Vec::new();
    for r in &report.results {
        match suites.iter_mut().find(|(name, _)| *name == r.scene) {
            Some((_, cases)) => cases.push(r),
            None => suites.push((&r.scene, vec![r])),
        }
    }
    suites
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

/// The JUnit XML of a run.
pub fn junit(report: &CheckReport) -> String {
    let mut out = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(
        out,
        "<testsuites name=\"histencil check\" tests=\"{}\" failures=\"{}\" errors=\"0\" \
         skipped=\"{}\" time=\"{:.3}\">",
        report.results.len(),
        report.failed(),
        report.skipped(),
        report.seconds
    );
    let validation = if report.best_practices {
        "Khronos validation layer, synchronization validation, best practices"
    } else {
        "Khronos validation layer, synchronization validation"
    };
    for (scene, cases) in suites(report) {
        let failed = cases
            .iter()
            .filter(|r| matches!(r.outcome, Outcome::Failed(_)))
            .count();
        let skipped = cases
            .iter()
            .filter(|r| matches!(r.outcome, Outcome::Skipped(_)))
            .count();
        let time: f64 = cases.iter().map(|r| r.seconds).sum();
        let _ = writeln!(
            out,
            "  <testsuite name=\"{}\" tests=\"{}\" failures=\"{failed}\" errors=\"0\" \
             skipped=\"{skipped}\" time=\"{time:.3}\">",
            xml(scene),
            cases.len()
        );
        let _ = writeln!(out, "    <properties>");
        let _ = writeln!(
            out,
            "      <property name=\"device\" value=\"{}\"/>",
            xml(&report.device)
        );
        let _ = writeln!(
            out,
            "      <property name=\"validation\" value=\"{validation}\"/>"
        );
        let _ = writeln!(out, "    </properties>");
        let classname = format!("histencil.{}", xml(&scene.replace(['.', '/', '\\'], "_")));
        for r in cases {
            let _ = write!(
                out,
                "    <testcase name=\"{}\" classname=\"{classname}\" time=\"{:.3}\"",
                xml(&r.name),
                r.seconds
            );
            let body = details(r);
            match &r.outcome {
                Outcome::Passed if body.is_empty() => out.push_str("/>\n"),
                Outcome::Passed => {
                    let _ = writeln!(
                        out,
                        ">\n      <system-out>{}</system-out>\n    </testcase>",
                        xml(&body)
                    );
                }
                Outcome::Failed(reason) => {
                    let _ = writeln!(
                        out,
                        ">\n      <failure message=\"{}\" type=\"{}\">{}</failure>\n    </testcase>",
                        xml(reason),
                        failure_type(r),
                        xml(&body)
                    );
                }
                Outcome::Skipped(reason) => {
                    let _ = writeln!(
                        out,
                        ">\n      <skipped message=\"{}\"/>\n    </testcase>",
                        xml(reason)
                    );
                }
            }
        }
        let _ = writeln!(out, "  </testsuite>");
    }
    out.push_str("</testsuites>\n");
    out
}

fn error_json(e: &ImageError, t: &Tolerance) -> Value {
    json!({
        "max": e.max, "mean": e.mean, "pixels": e.pixels, "beyond_max": e.over,
        "bound_max": t.max, "bound_mean": t.mean,
    })
}

/// The JSON of a run: the device, the settings, and every case with its numbers.
pub fn json(report: &CheckReport) -> Value {
    let cases: Vec<Value> = report
        .results
        .iter()
        .map(|r| {
            let (outcome, reason) = match &r.outcome {
                Outcome::Passed => ("passed", None),
                Outcome::Failed(why) => ("failed", Some(why)),
                Outcome::Skipped(why) => ("skipped", Some(why)),
            };
            let config = r.case.map(|case| {
                let expect = match case.expect {
                    Expect::Reference => "reference".to_owned(),
                    Expect::Exact => "exact".to_owned(),
                    Expect::Lut => "lut".to_owned(),
                    Expect::Alpha => "alpha".to_owned(),
                    Expect::Wrong(KnownWrong::PreservedBitsNotZeroed) => {
                        "known-wrong: preserved bits not zeroed".to_owned()
                    }
                    Expect::Wrong(KnownWrong::StaleHiStencil) => {
                        "known-wrong: stale hi-stencil".to_owned()
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
                "scene": r.scene,
                "name": r.name,
                "outcome": outcome,
                "reason": reason,
                "failure_type": (outcome == "failed").then(|| failure_type(r)),
                "seconds": r.seconds,
                "config": config,
                "image": image,
                "stencil_problems": r.stencil_problems,
                "validation": r.validation.iter().map(|m| json!({
                    "severity": m.severity, "id": m.id, "text": m.text
                })).collect::<Vec<_>>(),
                "accepted_best_practices_messages": r.accepted,
                "note": r.note,
                "artifacts": r.artifacts.iter().map(|a| a.display().to_string()).collect::<Vec<_>>(),
            })
        })
        .collect();
    json!({
        "device": report.device,
        "quick": report.quick,
        "best_practices": report.best_practices,
        "seconds": report.seconds,
        "tests": report.results.len(),
        "passed": report.passed(),
        "failed": report.failed(),
        "skipped": report.skipped(),
        "cases": cases,
    })
}

/// The summary: totals, a line per scene, the known-wrong cases' tally, skip reasons grouped,
/// and the first failures with their reasons.
pub fn summary(report: &CheckReport) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "histencil check: {} cases on {} in {:.1} s: {} passed, {} failed, {} skipped",
        report.results.len(),
        report.device,
        report.seconds,
        report.passed(),
        report.failed(),
        report.skipped()
    );
    let suites = suites(report);
    let width = suites
        .iter()
        .map(|(s, _)| s.len())
        .max()
        .unwrap_or(0)
        .max(5);
    let _ = writeln!(
        out,
        "  {:<width$} {:>6} {:>7} {:>7} {:>8} {:>9}",
        "scene", "cases", "passed", "failed", "skipped", "time"
    );
    for (scene, cases) in suites {
        let n = |f: fn(&Outcome) -> bool| cases.iter().filter(|r| f(&r.outcome)).count();
        let time: f64 = cases.iter().map(|r| r.seconds).sum();
        let _ = writeln!(
            out,
            "  {:<width$} {:>6} {:>7} {:>7} {:>8} {:>7.1} s",
            scene,
            cases.len(),
            n(|o| *o == Outcome::Passed),
            n(|o| matches!(o, Outcome::Failed(_))),
            n(|o| matches!(o, Outcome::Skipped(_))),
            time
        );
    }
    let wrong: Vec<&CaseResult> = report
        .results
        .iter()
        .filter(|r| matches!(r.case.map(|c| c.expect), Some(Expect::Wrong(_))))
        .collect();
    if !wrong.is_empty() {
        let n = |f: fn(&Outcome) -> bool| wrong.iter().filter(|r| f(&r.outcome)).count();
        let _ = writeln!(
            out,
            "known-wrong cases: {} failed as expected, {} not applicable (skipped), {} failed \
             to fail or did not run",
            n(|o| *o == Outcome::Passed),
            n(|o| matches!(o, Outcome::Skipped(_))),
            n(|o| matches!(o, Outcome::Failed(_)))
        );
    }
    let mut skips: BTreeMap<String, usize> = BTreeMap::new();
    for r in &report.results {
        if let Outcome::Skipped(why) = &r.outcome {
            // "not applicable here: the simulator predicts that X loses no fragment" and
            // format reasons repeat per case; count them once each.
            *skips.entry(why.clone()).or_default() += 1;
        }
    }
    for (why, count) in &skips {
        let _ = writeln!(out, "skipped {count} x: {why}");
    }
    let failures: Vec<&CaseResult> = report
        .results
        .iter()
        .filter(|r| matches!(r.outcome, Outcome::Failed(_)))
        .collect();
    for r in failures.iter().take(20) {
        if let Outcome::Failed(why) = &r.outcome {
            let _ = writeln!(out, "FAILED {}/{}: {why}", r.scene, r.name);
        }
    }
    if failures.len() > 20 {
        let _ = writeln!(
            out,
            "... and {} more failures (see the JUnit or JSON report)",
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

    fn report() -> CheckReport {
        let needs = SceneNeeds {
            preserved_mask: 0xFC,
            has_alpha: false,
            lut: true,
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
        CheckReport {
            device: "llvmpipe".into(),
            best_practices: false,
            quick: true,
            results: vec![
                result(all[0], Outcome::Passed),
                failed,
                result(all[2], Outcome::Skipped("missing format: D24".into())),
            ],
            seconds: 1.5,
        }
    }

    #[test]
    fn junit_counts_escapes_and_types_failures() {
        let xml = junit(&report());
        assert!(xml.starts_with("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites"));
        assert!(xml.contains("tests=\"3\" failures=\"1\" errors=\"0\" skipped=\"1\""));
        assert!(xml.contains("<testsuite name=\"a&lt;b&gt;&amp;&quot;c&quot;\""));
        assert!(xml.contains("type=\"validation\""));
        assert!(xml.contains("bad \u{FFFD} &lt;thing&gt;"));
        assert!(xml.contains("<skipped message=\"missing format: D24\"/>"));
        assert_eq!(xml.matches("<testcase ").count(), 3);
        assert_eq!(xml.matches("</testsuite>").count(), 1);
        assert!(!xml.contains('\u{1}'));
    }

    #[test]
    fn json_and_summary_carry_every_case() {
        let r = report();
        let v = json(&r);
        assert_eq!(v["cases"].as_array().unwrap().len(), 3);
        assert_eq!(v["failed"], 1);
        assert_eq!(v["cases"][1]["failure_type"], "validation");
        assert_eq!(
            v["cases"][1]["validation"][0]["id"],
            "SYNC-HAZARD-WRITE-AFTER-READ"
        );
        let s = summary(&r);
        assert!(s.contains("1 passed, 1 failed, 1 skipped"), "{s}");
        assert!(s.contains("FAILED a<b>&\"c\"/"), "{s}");
    }
}
