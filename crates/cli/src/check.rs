//! `histencil check`: the validation-CI matrix (histencil-check) with a progress bar, its
//! reports written, and an exit code a CI system reads: 0 all passed, 1 any failure, 2 a usage
//! error (bad arguments, an unknown or malformed scene, an output that cannot be written).

use anyhow::Result;
use histencil_check::{CheckOptions, CheckScene, InjectedFault, Outcome};
use histencil_scene::DefaultLights;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(clap::Args)]
pub struct CheckArgs {
    /// An embedded scene or a `.gltf` / `.glb` file; repeat for several (default: every
    /// embedded scene).
    #[arg(long = "scene")]
    scenes: Vec<String>,
    /// Resolutions 1x1, 7x5 and 257x129 only; the full run adds 1280x720.
    #[arg(long)]
    quick: bool,
    /// Print the matrix (scene, case, expectation) without running it.
    #[arg(long)]
    list: bool,
    /// Write JUnit XML here (a testsuite per scene, a testcase per configuration).
    #[arg(long)]
    junit: Option<PathBuf>,
    /// Write every case's numbers here as JSON.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Where failing cases write -actual.png, -expected.png, -difference.png, -stencil.png and
    /// -validation.txt, in a folder per scene.
    #[arg(long, default_value = "out/check")]
    out: PathBuf,
    /// Enable the validation layer's best-practices checks too.
    #[arg(long)]
    best_practices: bool,
    /// Run only the cases whose `scene/case` name contains this.
    #[arg(long)]
    filter: Option<String>,
    /// Break the renderer on purpose, to see the check fail (for tests of the check itself).
    #[arg(long, value_enum, hide = true)]
    inject_fault: Option<FaultArg>,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum FaultArg {
    /// Render every hi-stencil case without flushes.
    DropFlushes,
}

/// A usage error: printed and exit code 2.
fn usage(e: impl std::fmt::Display) -> ExitCode {
    eprintln!("histencil: {e:#}");
    ExitCode::from(2)
}

pub fn check(args: &CheckArgs, lights: DefaultLights) -> ExitCode {
    let names = if args.scenes.is_empty() {
        histencil_scene::EMBEDDED
            .iter()
            .map(|(name, _)| (*name).to_owned())
            .collect()
    } else {
        args.scenes.clone()
    };
    let mut scenes = Vec::new();
    for name in names {
        match crate::load_scene_arg(&name, lights) {
            Ok(scene) => scenes.push(CheckScene { name, scene }),
            Err(e) => return usage(e),
        }
    }
    let options = CheckOptions {
        quick: args.quick,
        best_practices: args.best_practices,
        out: Some(args.out.clone()),
        filter: args.filter.clone(),
        inject: args.inject_fault.map(|f| match f {
            FaultArg::DropFlushes => InjectedFault::DropFlushes,
        }),
    };
    if args.list {
        return match list(&scenes, &options) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => usage(e),
        };
    }
    let outputs = [args.junit.as_ref(), args.json.as_ref()];
    for path in outputs.into_iter().flatten() {
        if let Err(e) = histencil_vk::check_output_file(path) {
            return usage(e);
        }
    }
    if let Err(e) = histencil_vk::check_output_dir(&args.out) {
        return usage(e);
    }
    match run(args, &scenes, &options) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("histencil: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn list(scenes: &[CheckScene], options: &CheckOptions) -> Result<()> {
    let planned = histencil_check::planned_cases(scenes, options)?;
    for (scene, case) in &planned {
        println!(
            "{}\t{}\t{:?}",
            scenes[*scene].name,
            case.name(),
            case.expect
        );
    }
    println!(
        "{} cases ({} scenes; a format the device lacks is skipped when run)",
        planned.len(),
        scenes.len()
    );
    Ok(())
}

fn run(args: &CheckArgs, scenes: &[CheckScene], options: &CheckOptions) -> Result<ExitCode> {
    // A bar on a terminal; nothing when stderr is a log file.
    let bar = ProgressBar::with_draw_target(
        None,
        if std::io::stderr().is_terminal() {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        },
    )
    .with_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} {elapsed} {msg}")
            .expect("valid template"),
    );
    let (mut failed, mut done) = (0, 0u64);
    let report = histencil_check::run_check(scenes, options, |result, total| {
        bar.set_length(total as u64);
        if result.case.is_some() {
            done += 1;
        }
        if let Outcome::Failed(why) = &result.outcome {
            failed += 1;
            bar.suspend(|| eprintln!("FAILED {}/{}: {why}", result.scene, result.name));
        }
        bar.set_position(done);
        bar.set_message(format!("{failed} failed; {}/{}", result.scene, result.name));
    });
    bar.finish_and_clear();
    let report = report?;
    if let Some(path) = &args.junit {
        histencil_vk::write_atomically(path, histencil_check::report::junit(&report).as_bytes())?;
        println!("wrote {}", path.display());
    }
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&histencil_check::report::json(&report))?;
        histencil_vk::write_atomically(path, text.as_bytes())?;
        println!("wrote {}", path.display());
    }
    print!("{}", histencil_check::report::summary(&report));
    Ok(if report.failed() == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}
