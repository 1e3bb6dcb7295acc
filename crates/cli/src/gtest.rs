//! `histencil check` as a googletest binary, so that Mesa's deqp-runner drives the matrix with
//! its own `gtest-runner`, list files and reports: `--gtest_list_tests` prints the selected cases
//! (`histencil_check::gtest` has the names), and `--gtest_filter=PATTERNS` runs the matching
//! ones in this process, one after the other, printing googletest's `[ RUN      ]`,
//! `[       OK ]`, `[  FAILED  ]` and `[  SKIPPED ]` lines on stdout. The device and driver line
//! comes first, and a failing or skipped case's reason, its messages and the files it wrote
//! (images, stencil dump, under `--out`) follow its end line, indented and with no square
//! brackets (gtest-runner reads any bracketed line inside a test as its end): gtest-runner keeps
//! stdout in its log of a group that failed. stderr stays empty unless the process cannot give
//! verdicts at all (no device, a muted layer), because gtest-runner reports every stderr line
//! as an error. The exit status is googletest's: 0 nothing failed, 1 a test failed; a crash or
//! a hang is the runner's to see (a RUN line with no end, a killed process).
//!
//! The validation layer's settings are pinned as for the check's own workers: before any case
//! runs, this process writes the pinned settings file under `--out` and replaces itself (`exec`,
//! the same process id, so gtest-runner's timeout still kills it) with a copy whose environment
//! holds none of the variables that could mute the layer.

use histencil_check::gtest::{end_line, run_line, GtestNames, GtestStatus};
use histencil_check::lists::Status;
use histencil_check::report::Record;
use histencil_check::{CheckOptions, CheckScene, Event};
use std::io::Write;
use std::path::Path;
use std::process::ExitCode;

/// Set in the environment of the copy that runs the cases: the settings are pinned.
const PINNED: &str = "HISTENCIL_CHECK_GTEST_PINNED";

/// `text` without square brackets, which gtest-runner would read as a test's status line.
fn plain(text: &str) -> String {
    text.replace('[', "(").replace(']', ")")
}

/// `--gtest_list_tests`: the selected cases' names.
pub fn list(names: &GtestNames, selected: &dyn Fn(&str) -> bool) -> ExitCode {
    print!("{}", names.list_text(selected));
    ExitCode::SUCCESS
}

/// Pins the layer's settings and replaces this process with a copy that runs under them;
/// returns only where that cannot be done (the error says why).
fn pin_and_reexec(out: &Path) -> std::io::Error {
    use std::os::unix::process::CommandExt;
    let settings = match crate::check::write_pinned_settings(out) {
        Ok(path) => path,
        Err(e) => return e,
    };
    let mut command = std::process::Command::new(match std::env::current_exe() {
        Ok(exe) => exe,
        Err(e) => return e,
    });
    command.args(std::env::args_os().skip(1));
    for (name, value) in std::env::vars().filter(|(n, _)| crate::check::muting_variable(n)) {
        // On stdout, outside any test: gtest-runner reports every stderr line as an error.
        println!(
            "histencil check: {name}={value} is cleared: the validation settings the verdict \
             rests on are pinned"
        );
        command.env_remove(name);
    }
    command
        .env("VK_LAYER_SETTINGS_PATH", settings)
        .env(PINNED, "1")
        .exec()
}

/// `--gtest_filter=...`: the cases of `options.only`, here, as googletest reports tests.
pub fn run(
    scenes: &[CheckScene],
    options: &CheckOptions,
    names: &GtestNames,
    expect_driver: Option<&str>,
) -> ExitCode {
    if std::env::var_os(PINNED).is_none() {
        let out = options.out.clone().unwrap_or_else(|| "out/check".into());
        let e = pin_and_reexec(&out);
        eprintln!("histencil check: cannot start the pinned copy of itself: {e}");
        return ExitCode::from(crate::check::EXIT_RUNNER);
    }
    let stdout = std::io::stdout();
    let line = |text: &str| {
        let mut out = stdout.lock();
        let _ = writeln!(out, "{text}");
        let _ = out.flush();
    };
    if let Some(settings) = crate::suite::settings_line(&|name| std::env::var(name).ok()) {
        line(&plain(&format!(
            "histencil check: settings from the environment: {settings}"
        )));
    }
    let gtest = |full: &str| names.gtest_name(full).unwrap_or(full).to_owned();
    let mut current: Option<String> = None;
    let mut failed = false;
    let report = histencil_check::run_check(scenes, options, |event| match event {
        Event::Context { device, driver } => {
            line(&plain(&format!(
                "histencil check: {device}; driver: {driver}"
            )));
            if let Some(expected) = expect_driver.filter(|e| !driver.to_string().contains(e)) {
                eprintln!(
                    "histencil check: the driver is `{driver}`, not the `{expected}` \
                     --expect-driver names"
                );
                std::process::exit(i32::from(crate::check::EXIT_NO_DEVICE));
            }
        }
        Event::Started(full) => {
            let name = gtest(full);
            line(&run_line(&name));
            current = Some(name);
        }
        Event::Finished(result, _) => {
            let record = Record::from_result(result);
            if record.scene == "device" {
                // The canary (before a context's first case) and the teardown check (after its
                // last): a failing one stops the process with exit 3, which gtest-runner
                // charges as a Crash to the last test it saw end (the teardown's case, or the
                // previous context's); the reason is on stderr, in its log. Tests that ended
                // before keep their results: they ran under a context whose canary passed.
                if record.status.is_failure() {
                    eprintln!(
                        "histencil check: {}: {} {}",
                        record.full_name(),
                        record.reason.as_deref().unwrap_or(""),
                        record.details
                    );
                    std::process::exit(i32::from(crate::check::EXIT_NO_DEVICE));
                }
                return;
            }
            let name = gtest(&record.full_name());
            if current.as_deref() != Some(name.as_str()) {
                // A case skipped before it started (a depth format the device lacks).
                line(&run_line(&name));
            }
            current = None;
            let status = match record.status {
                Status::Pass => GtestStatus::Ok,
                Status::Skip => GtestStatus::Skipped,
                _ => GtestStatus::Failed,
            };
            failed |= status == GtestStatus::Failed;
            line(&end_line(status, &name, (record.seconds * 1000.0) as u64));
            if status != GtestStatus::Ok {
                let why = format!(
                    "{} ({}): {}",
                    record.full_name(),
                    record.status,
                    record.reason.as_deref().unwrap_or("")
                );
                for text in std::iter::once(why.as_str()).chain(record.details.lines()) {
                    line(&format!("    {}", plain(text)));
                }
            }
        }
    });
    match report {
        Ok(_) if failed => ExitCode::from(crate::check::EXIT_FAILING),
        Ok(_) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("histencil check: {e}");
            ExitCode::from(crate::check::EXIT_NO_DEVICE)
        }
    }
}
