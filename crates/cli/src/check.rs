//! `histencil check`: the validation-CI matrix (histencil-check) as a CI runner. The parent
//! plans the cases (scenes, `--filter`, `--caselist`, `--shard`, `--skips`), runs them in worker
//! processes (`--jobs`, `--timeout`; a worker is this program with the hidden `--worker` flag)
//! whose environment cannot mute the validation layer, applies `--baseline` and `--flakes`,
//! streams `results.csv`, and writes `failures.csv`, JUnit and JSON at the end or when stopped
//! by SIGINT/SIGTERM. `histencil check merge` joins shards' JSON reports.
//!
//! Exit codes: 0 nothing fails; 1 a case fails (a regression, crash, timeout, muted validation
//! layer or unexpected pass); 2 usage error; 3 no Vulkan device, no validation layer, or not the
//! driver `--expect-driver` names; 4 no case selected; 5 stopped before the end (a signal) with
//! nothing failing so far; 6 the runner itself failed (its files could not be written, a worker
//! could not be started).

use anyhow::{Context as _, Result};
use histencil_check::lists::{AcceptedMessages, Baseline, Patterns, Shard, Status};
use histencil_check::report::{self, Record, RunReport};
use histencil_check::runner::{self, PlannedCase, RunnerOptions};
use histencil_check::{CheckOptions, CheckScene, Event, InjectedFault};
use histencil_scene::DefaultLights;
use std::collections::HashSet;
use std::ffi::OsString;
use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// Exit codes apart, as a CI script reads them.
pub(crate) const EXIT_FAILING: u8 = 1;
const EXIT_USAGE: u8 = 2;
pub(crate) const EXIT_NO_DEVICE: u8 = runner::NO_DEVICE_EXIT as u8;
const EXIT_NO_CASES: u8 = 4;
const EXIT_INCOMPLETE: u8 = 5;
pub(crate) const EXIT_RUNNER: u8 = 6;

#[derive(clap::Args)]
#[command(args_conflicts_with_subcommands = true, after_help = crate::suite::help())]
pub struct CheckArgs {
    #[command(subcommand)]
    command: Option<CheckCommand>,
    /// An embedded scene or a `.gltf` / `.glb` file; repeat for several (default: every
    /// embedded scene).
    #[arg(long = "scene")]
    scenes: Vec<String>,
    #[command(flatten)]
    brdfs: crate::brdfs::BrdfsArg,
    /// Resolutions 1x1, 7x5 and 257x129 only; the full run adds 1280x720.
    #[arg(long)]
    quick: bool,
    /// Print the cases selected, `scene/case` a line, without running them (the count goes
    /// to stderr): a valid `--caselist`, and the first column of a baseline.
    #[arg(long)]
    list: bool,
    /// What `--list` prints: `names` (`scene/case`), or `table` (scene, case and what the case
    /// expects, tab-separated).
    #[arg(long, value_enum, default_value_t = ListFormat::Names)]
    list_format: ListFormat,
    /// Print the selected cases as googletest lists tests (`Group.` lines, then indented
    /// names), for Mesa's deqp-runner (`gtest-runner`); see the book's Validation CI.
    #[arg(long = "gtest_list_tests")]
    gtest_list_tests: bool,
    /// Run the selected cases whose googletest name matches, in this process, printing
    /// googletest's RUN/OK/FAILED/SKIPPED lines (`POSITIVE[-NEGATIVE]`, `:`-separated, `*`
    /// and `?` wildcards), as deqp-runner's `gtest-runner` runs a group.
    #[arg(long = "gtest_filter")]
    gtest_filter: Option<String>,
    /// Print --baseline in googletest spelling (`Group.name,Status`, each line's reason kept as
    /// a `#` comment above it), the form deqp-runner's gtest-runner reads, and exit: one
    /// baseline file kept in `scene/case` spelling serves both runners.
    #[arg(long, requires = "baseline")]
    print_gtest_baseline: bool,
    /// The prefix a deqp-runner suite entry gives histencil's cases (`histencil-`, as in
    /// ci/mesa/histencil.toml): `--print-gtest-baseline` writes it before each name, and
    /// `--baseline` keeps only the lines that carry it, without it (a driver's fails file holds
    /// every suite's lines).
    #[arg(long)]
    gtest_prefix: Option<String>,
    /// Print the cases of the matrix the --flakes files match, each as a regular expression of
    /// its googletest name (after --gtest-prefix), and exit: the flakes list gtest-runner and a
    /// suite entry read (histencil's own lists match either spelling).
    #[arg(long, requires = "flakes")]
    print_gtest_flakes: bool,
    /// Write JUnit XML here (a testsuite per scene, a testcase per configuration).
    #[arg(long)]
    junit: Option<PathBuf>,
    /// Write every case's numbers here as JSON (what `check merge` joins).
    #[arg(long)]
    json: Option<PathBuf>,
    /// Write the summary here too, headed by the command line and the date (UTC): a run's
    /// figures as the runner wrote them, for a document to include.
    #[arg(long)]
    summary: Option<PathBuf>,
    /// The run's folder: results.csv (streamed as cases finish), failures.csv (in --baseline
    /// format), each failing case's images and messages in a folder per scene, and workers/
    /// (case lists and logs).
    #[arg(long, default_value = "out/check")]
    out: PathBuf,
    /// Enable the validation layer's best-practices checks too.
    #[arg(long)]
    best_practices: bool,
    /// Apply no driver quirk and leave the depth bounds test unused: the general path every
    /// device without them takes, on this one (the driver line says `quirks: none`).
    #[arg(long)]
    general_path: bool,
    /// Act as a device that offers only the Vulkan spec's minimum of every limit histencil
    /// checks: a case that needs more is a skip that names the limit.
    #[arg(long)]
    spec_minimum_limits: bool,
    /// Run only the cases whose `scene/case` name contains this.
    #[arg(long)]
    filter: Option<String>,
    /// Run exactly the cases named in this file (a `scene/case` or googletest name per line,
    /// or a results.csv or failures.csv; a line naming a `.txt` file includes that file).
    #[arg(long)]
    caselist: Option<PathBuf>,
    /// Run one shard of the cases, K of N (from 1), by a stable hash of each case's name.
    #[arg(long, value_parser = Shard::parse, conflicts_with = "fraction")]
    shard: Option<Shard>,
    /// Run every Nth case of the run's order (Mesa's split, as deqp-runner's `--fraction`:
    /// `--fraction $CI_NODE_TOTAL --fraction-start $CI_NODE_INDEX`).
    #[arg(long)]
    fraction: Option<u32>,
    /// With `--fraction`: start at the Kth case (from 1).
    #[arg(long, requires = "fraction", default_value_t = 1)]
    fraction_start: u32,
    /// Worker processes at once (default: the machine's cores).
    #[arg(long)]
    jobs: Option<usize>,
    /// Seconds a case may run (a group's first case includes the group's setup) before its
    /// worker is killed and the case ends as Timeout.
    #[arg(long, default_value_t = 300.0)]
    timeout: f64,
    /// Stop after this many failing cases.
    #[arg(long)]
    max_fails: Option<usize>,
    /// At most this many cases per worker process: a fresh process bounds a driver's growth.
    #[arg(long, default_value_t = 100)]
    cases_per_worker: usize,
    /// Expected results, `scene/case,Status` per line (Fail, Crash or Timeout; `#` comments;
    /// a case may be named as googletest names it, so deqp-runner's baseline serves too): a
    /// failure listed is ExpectedFail, a listed case that passes is UnexpectedPass.
    #[arg(long)]
    baseline: Option<PathBuf>,
    /// Regular expressions (one per line) of cases not to run; repeat for several files.
    #[arg(long)]
    skips: Vec<PathBuf>,
    /// Regular expressions (one per line) of cases known to be flaky: a failure is a Flake.
    #[arg(long)]
    flakes: Vec<PathBuf>,
    /// Refuse to run (exit 3) unless the driver line (`VkPhysicalDeviceDriverProperties`'
    /// name and build, e.g. `Mesa 25.0.7`) contains this: a CI job meant for one driver cannot
    /// pass on another that the loader picked instead.
    #[arg(long)]
    expect_driver: Option<String>,
    /// An unexpected pass does not fail the run (it is still reported).
    #[arg(long)]
    allow_unexpected_pass: bool,
    /// Validation messages to accept: `MESSAGE-ID reason` per line. Accepted messages are
    /// counted per case in the reports, never dropped silently.
    #[arg(long)]
    accept_messages: Option<PathBuf>,
    /// Break the renderer on purpose, to see the check fail (a baseline's or a CI job's own
    /// test): `drop-flushes` (the hi-stencil emulation skips its flushes: the 360-like and
    /// PS3-like cases that need one fail), `hang=PART` or `crash=PART` (cases whose name
    /// contains PART hang or abort), `flaky=PART` (they fail the first time they run with this
    /// `--out` folder, then pass); repeat for several.
    #[arg(long, value_parser = parse_fault)]
    inject_fault: Vec<InjectedFault>,
    /// Run the cases in this process and report them on stdout, a line each (what the runner
    /// starts; the environment is not cleaned here).
    #[arg(long, hide = true)]
    worker: bool,
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum ListFormat {
    Names,
    Table,
}

#[derive(clap::Subcommand)]
enum CheckCommand {
    /// Join the JSON reports of several shards into one JUnit, JSON and summary, and the
    /// joined failures or the next baseline; the exit code is the joined run's.
    Merge(MergeArgs),
}

#[derive(clap::Args)]
struct MergeArgs {
    /// The shards' JSON reports.
    #[arg(required = true)]
    reports: Vec<PathBuf>,
    #[arg(long)]
    junit: Option<PathBuf>,
    #[arg(long)]
    json: Option<PathBuf>,
    /// Write the joined run's failures.csv here (every case that ended failing, expected or
    /// not, in --baseline format).
    #[arg(long)]
    failures: Option<PathBuf>,
    /// Rewrite this baseline (the one the shards ran with) as the next one: each line whose
    /// case still fails as it says kept with its reason, a changed or new failure marked `#
    /// NEEDS A REASON`, a line whose case now passes removed and listed on stderr; lines for
    /// cases the run did not include stay.
    #[arg(long)]
    update_baseline: Option<PathBuf>,
}

fn parse_fault(text: &str) -> Result<InjectedFault, String> {
    match text.split_once('=') {
        None if text == "drop-flushes" => Ok(InjectedFault::DropFlushes),
        Some(("hang", part)) if !part.is_empty() => Ok(InjectedFault::Hang(part.to_owned())),
        Some(("crash", part)) if !part.is_empty() => Ok(InjectedFault::Crash(part.to_owned())),
        Some(("flaky", part)) if !part.is_empty() => Ok(InjectedFault::Flaky(part.to_owned())),
        _ => Err(format!(
            "`{text}`: expected drop-flushes, hang=PART, crash=PART or flaky=PART"
        )),
    }
}

/// A usage error: printed and exit code 2.
fn usage(e: impl std::fmt::Display) -> ExitCode {
    eprintln!("histencil: {e:#}");
    ExitCode::from(EXIT_USAGE)
}

/// The validation layer's settings that can silence it, by their environment variables: every
/// `VK_LAYER_*` setting variable (message-id filter, duplicate limit, disables, report flags,
/// debug action, a settings file's path...), the newer `VK_KHRONOS_VALIDATION_*` spellings, and
/// the loader's switch that disables layers. `VK_LAYER_PATH` (where layers are found) stays.
pub(crate) fn muting_variable(name: &str) -> bool {
    (name.starts_with("VK_LAYER_") && name != "VK_LAYER_PATH")
        || name.starts_with("VK_KHRONOS_VALIDATION_")
        || name == "VK_LOADER_LAYERS_DISABLE"
}

/// The settings file the workers' layer reads instead of any `vk_layer_settings.txt` in the
/// working folder or named by the user's `VK_LAYER_SETTINGS_PATH`: the layer's defaults, with
/// duplicate limiting off and synchronisation validation on.
const PINNED_SETTINGS: &str = "\
# Written by histencil check: the validation layer settings its verdict rests on.
khronos_validation.enable_message_limit = false
khronos_validation.validate_sync = true
";

/// Writes [`PINNED_SETTINGS`] as `vk_layer_settings.txt` in `out` (made if missing), whole or
/// not at all (processes running side by side write the same file), and returns its absolute
/// path.
pub(crate) fn write_pinned_settings(out: &std::path::Path) -> std::io::Result<PathBuf> {
    std::fs::create_dir_all(out)?;
    let path = out.join("vk_layer_settings.txt");
    let partial = out.join(format!(".vk_layer_settings.{}.txt", std::process::id()));
    std::fs::write(&partial, PINNED_SETTINGS)?;
    std::fs::rename(&partial, &path)?;
    std::fs::canonicalize(&path)
}

pub fn check(args: &CheckArgs, lights: DefaultLights) -> ExitCode {
    if let Some(CheckCommand::Merge(merge_args)) = &args.command {
        return merge(merge_args);
    }
    let names = if args.scenes.is_empty() {
        histencil_scene::EMBEDDED
            .iter()
            .map(|(name, _)| (*name).to_owned())
            .collect()
    } else {
        args.scenes.clone()
    };
    let brdfs = match args.brdfs.modules() {
        Ok(modules) => modules,
        Err(e) => return usage(e),
    };
    let mut scenes = Vec::new();
    for name in names {
        match crate::brdfs::load_scene(&name, lights, brdfs) {
            Ok(scene) => scenes.push(CheckScene { name, scene, brdfs }),
            Err(e) => return usage(e),
        }
    }
    let accepted = match &args.accept_messages {
        Some(path) => match AcceptedMessages::load(path) {
            Ok(a) => a,
            Err(e) => return usage(e),
        },
        None => AcceptedMessages::default(),
    };
    let only = match &args.caselist {
        Some(path) => match histencil_check::lists::load_caselist(path) {
            Ok(names) => Some(names.into_iter().collect::<HashSet<_>>()),
            Err(e) => return usage(e),
        },
        None => None,
    };
    let mut options = CheckOptions {
        quick: args.quick,
        best_practices: args.best_practices,
        general_path: args.general_path,
        spec_minimum_limits: args.spec_minimum_limits,
        trace_steps: false,
        out: Some(args.out.clone()),
        filter: args.filter.clone(),
        only,
        accepted,
        inject: args.inject_fault.clone(),
    };
    if args.worker {
        let traced = CheckOptions {
            trace_steps: true,
            ..options
        };
        return worker(&scenes, &traced, args.expect_driver.as_deref());
    }
    // Every case's googletest name, over the whole matrix of these scenes, so that a case list
    // or baseline in either spelling selects the same cases.
    let gtest_mode = args.gtest_list_tests || args.gtest_filter.is_some();
    let names = match gtest_names(&scenes, &options) {
        Ok(n) => n,
        // Two cases that would share a googletest name matter only where that name is used.
        Err(e) if gtest_mode => return usage(e),
        Err(e) => {
            eprintln!("histencil check: no googletest names for this run: {e}");
            histencil_check::gtest::GtestNames::default()
        }
    };
    if args.print_gtest_flakes {
        return print_gtest_flakes(&args.flakes, args.gtest_prefix.as_deref(), &names);
    }
    if args.print_gtest_baseline {
        return print_gtest_baseline(
            args.baseline.as_deref(),
            args.gtest_prefix.as_deref(),
            &names,
        );
    }
    if let Some(only) = options.only.take() {
        let full = |name: String| names.full_name(&name).map(str::to_owned).unwrap_or(name);
        options.only = Some(only.into_iter().map(full).collect());
    }
    let split = match args.fraction {
        Some(count) => match Shard::new(args.fraction_start, count, true) {
            Ok(s) => Some(s),
            Err(e) => return usage(format!("--fraction-start/--fraction: {e}")),
        },
        None => args.shard,
    };
    let mut skips = Patterns::default();
    for path in &args.skips {
        match Patterns::load(path) {
            Ok(p) => skips.extend(p),
            Err(e) => return usage(e),
        }
    }
    let planned = match histencil_check::planned_cases(&scenes, &options) {
        Ok(p) => p,
        Err(e) => return usage(e),
    };
    if let (Some(only), Some(path)) = (&options.only, &args.caselist) {
        // A name that selects nothing (a typo, another run's scene) would shrink the run
        // silently.
        let planned_names: HashSet<String> = planned
            .iter()
            .map(|(s, c)| format!("{}/{}", scenes[*s].name, c.name()))
            .collect();
        let mut unmatched: Vec<&String> = only
            .iter()
            .filter(|n| !planned_names.contains(*n))
            .collect();
        unmatched.sort();
        if let Some(first) = unmatched.first() {
            eprintln!(
                "histencil check: {} name(s) in {} select no case of this run (scenes, --quick), \
                 the first `{first}`",
                unmatched.len(),
                path.display()
            );
        }
    }
    let (mut cases, mut skipped) = (Vec::new(), Vec::new());
    for (position, (scene, case)) in planned.iter().enumerate() {
        let planned = PlannedCase {
            scene: scenes[*scene].name.clone(),
            case: case.name(),
            group: format!(
                "{}/{}x{}-{}",
                scenes[*scene].name,
                case.width,
                case.height,
                case.format.vk_name()
            ),
            pixels: u64::from(case.width) * u64::from(case.height),
        };
        let full = planned.full_name();
        if split.is_some_and(|s| !s.holds(position, &full)) {
            continue;
        }
        let gtest = names.gtest_name(&full).unwrap_or_default();
        if skips.matches(&full) || skips.matches(gtest) {
            skipped.push(Record {
                scene: planned.scene.clone(),
                name: planned.case.clone(),
                status: Status::Skip,
                seconds: 0.0,
                reason: Some("skipped by --skips".into()),
                failure_type: None,
                details: String::new(),
                data: serde_json::Value::Null,
            });
            continue;
        }
        cases.push((planned, format!("{:?}", case.expect)));
    }
    if args.list {
        for (c, expect) in &cases {
            match args.list_format {
                ListFormat::Names => println!("{}", c.full_name()),
                ListFormat::Table => println!("{}\t{}\t{expect}", c.scene, c.case),
            }
        }
        eprintln!(
            "{} cases ({} scenes{}; a format the device lacks is skipped when run)",
            cases.len(),
            scenes.len(),
            split.map(|s| format!(", shard {s}")).unwrap_or_default()
        );
        return ExitCode::SUCCESS;
    }
    let selected: HashSet<String> = cases.iter().map(|(c, _)| c.full_name()).collect();
    if args.gtest_list_tests {
        return crate::gtest::list(&names, &|full| selected.contains(full));
    }
    if let Some(filter) = &args.gtest_filter {
        let filter = histencil_check::gtest::GtestFilter::parse(filter);
        let chosen = names.select(&filter);
        options.only = Some(
            chosen
                .into_iter()
                .filter(|full| selected.contains(*full))
                .map(str::to_owned)
                .collect(),
        );
        options.trace_steps = true;
        return crate::gtest::run(&scenes, &options, &names, args.expect_driver.as_deref());
    }
    if cases.is_empty() {
        eprintln!(
            "histencil: no case selected (scenes, --filter, --caselist, --shard and --skips \
             leave none)"
        );
        return ExitCode::from(EXIT_NO_CASES);
    }
    let outputs = [
        args.junit.as_ref(),
        args.json.as_ref(),
        args.summary.as_ref(),
    ];
    for path in outputs.into_iter().flatten() {
        if let Err(e) = histencil_vk::check_output_file(path) {
            return usage(e);
        }
    }
    if let Err(e) = histencil_vk::check_output_dir(&args.out) {
        return usage(e);
    }
    let baseline = match &args.baseline {
        Some(path) => match load_baseline(path, args.gtest_prefix.as_deref(), &names) {
            Ok(b) => b,
            Err(e) => return usage(e),
        },
        None => Baseline::default(),
    };
    let mut flakes = Patterns::default();
    for path in &args.flakes {
        match Patterns::load(path) {
            Ok(p) => flakes.extend(p),
            Err(e) => return usage(e),
        }
    }
    let cases: Vec<PlannedCase> = cases.into_iter().map(|(c, _)| c).collect();
    match run(args, &options, cases, skipped, baseline, flakes, split) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("histencil: {e:#}");
            let no_device = matches!(
                e.downcast_ref::<runner::RunnerError>(),
                Some(runner::RunnerError::NoDevice(_))
            );
            ExitCode::from(if no_device {
                EXIT_NO_DEVICE
            } else {
                EXIT_RUNNER
            })
        }
    }
}

/// The baseline at `path`, each line in `scene/case` spelling: with `prefix`, only the lines
/// that carry it, without it. A line naming no case of this matrix (a baseline shared by a
/// quick and a full job) is kept, matching nothing here, and counted on stderr, as
/// `--print-gtest-baseline` does.
fn load_baseline(
    path: &std::path::Path,
    prefix: Option<&str>,
    names: &histencil_check::gtest::GtestNames,
) -> Result<Baseline, histencil_check::lists::ListError> {
    let mut baseline = Baseline::load(path)?;
    let mut outside = Vec::new();
    let mut reasons = std::mem::take(&mut baseline.reasons);
    let mut renamed_reasons = std::collections::BTreeMap::new();
    baseline.expected = std::mem::take(&mut baseline.expected)
        .into_iter()
        .filter_map(|(name, status)| match prefix {
            Some(p) => name
                .strip_prefix(p)
                .map(|n| (name.clone(), n.to_owned(), status)),
            None => Some((name.clone(), name, status)),
        })
        .map(|(written, name, status)| {
            let full = names
                .full_name(&name)
                .map(str::to_owned)
                .or_else(|| names.gtest_name(&name).map(|_| name.clone()));
            let name = full.unwrap_or_else(|| {
                outside.push(name.clone());
                name
            });
            // A line's reason follows it under its new name.
            if let Some(reason) = reasons.remove(&written) {
                renamed_reasons.insert(name.clone(), reason);
            }
            (name, status)
        })
        .collect();
    baseline.reasons = renamed_reasons;
    note_outside(path, &outside);
    Ok(baseline)
}

/// Says on stderr how many baseline lines name no case of this matrix, and the first.
fn note_outside(path: &std::path::Path, outside: &[String]) {
    if let Some(first) = outside.first() {
        eprintln!(
            "histencil check: {} line(s) of {} name no case of this matrix (scenes, --quick), \
             first `{first}`: kept, they match nothing here",
            outside.len(),
            path.display()
        );
    }
}

/// `--print-gtest-baseline`: the baseline's lines with googletest names, each after `prefix`.
/// A line naming no case of this matrix is written as the naming rule spells it (a `scene/case`
/// line's scene and case, each an identifier) and counted on stderr, as `--baseline` keeps it:
/// both accept the same files.
fn print_gtest_baseline(
    path: Option<&std::path::Path>,
    prefix: Option<&str>,
    names: &histencil_check::gtest::GtestNames,
) -> ExitCode {
    let Some(path) = path else {
        return usage("--print-gtest-baseline needs --baseline");
    };
    let baseline = match load_baseline(path, None, names) {
        Ok(b) => b,
        Err(e) => return usage(e),
    };
    let mut out = String::new();
    for (name, status) in &baseline.expected {
        let gtest = match (names.gtest_name(name), name.split_once('/')) {
            (Some(g), _) => g.to_owned(),
            (None, Some((scene, case))) => histencil_check::gtest::test_name(scene, case),
            (None, None) => name.clone(),
        };
        // The reason goes with the line into the driver's fails file (deqp-runner skips `#`
        // lines), so its team reads why beside what.
        if let Some(reason) = baseline.reasons.get(name) {
            out.push_str(&format!("# {reason}\n"));
        }
        out.push_str(&format!("{}{gtest},{status}\n", prefix.unwrap_or("")));
    }
    print!("{out}");
    ExitCode::SUCCESS
}

/// `--print-gtest-flakes`: every case of the matrix a flakes pattern matches (in either
/// spelling), as an anchored regular expression of `prefix` and its googletest name.
fn print_gtest_flakes(
    paths: &[PathBuf],
    prefix: Option<&str>,
    names: &histencil_check::gtest::GtestNames,
) -> ExitCode {
    let mut flakes = Patterns::default();
    for path in paths {
        match Patterns::load(path) {
            Ok(p) => flakes.extend(p),
            Err(e) => return usage(e),
        }
    }
    // A gtest name is letters, digits, `_` and one `.`; the prefix is the user's.
    let escape = |text: &str| -> String {
        text.chars()
            .flat_map(|c| {
                let special = !(c.is_ascii_alphanumeric() || c == '_' || c == '-');
                special.then_some('\\').into_iter().chain([c])
            })
            .collect()
    };
    for (gtest, full) in names.iter() {
        if flakes.matches(full) || flakes.matches(gtest) {
            println!("^{}{}$", escape(prefix.unwrap_or("")), escape(gtest));
        }
    }
    ExitCode::SUCCESS
}

/// Every case of `scenes`' matrix (whatever `options.only` selects), named for googletest.
fn gtest_names(
    scenes: &[CheckScene],
    options: &CheckOptions,
) -> Result<histencil_check::gtest::GtestNames, String> {
    let all = CheckOptions {
        only: None,
        filter: None,
        ..options.clone()
    };
    let planned = histencil_check::planned_cases(scenes, &all).map_err(|e| e.to_string())?;
    let named: Vec<(String, String, String)> = planned
        .iter()
        .map(|(scene, case)| {
            let s = &scenes[*scene];
            (
                s.file_name(),
                format!("{}/{}", s.name, case.name()),
                case.name(),
            )
        })
        .collect();
    histencil_check::gtest::GtestNames::new(
        named
            .iter()
            .map(|(f, full, case)| (f.as_str(), full.as_str(), case.as_str())),
    )
}

/// Set by SIGINT and SIGTERM; the runner stops, keeps what finished and writes its reports.
static STOP: AtomicBool = AtomicBool::new(false);

extern "C" fn on_signal(_: libc::c_int) {
    STOP.store(true, Ordering::SeqCst);
}

fn run(
    args: &CheckArgs,
    options: &CheckOptions,
    cases: Vec<PlannedCase>,
    skipped: Vec<Record>,
    baseline: Baseline,
    flakes: Patterns,
    split: Option<Shard>,
) -> Result<ExitCode> {
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let settings_path = args.out.join("vk_layer_settings.txt");
    std::fs::write(&settings_path, PINNED_SETTINGS)?;
    let settings_path = std::fs::canonicalize(&settings_path)?;
    let cleared: Vec<(String, String)> = std::env::vars()
        .filter(|(name, _)| muting_variable(name))
        .collect();
    for (name, value) in &cleared {
        eprintln!(
            "histencil check: {name}={value} is not passed to the workers: the validation \
             settings the verdict rests on are pinned (use --accept-messages to accept a \
             message)"
        );
    }
    let mut settings = vec![
        "duplicate-message limit: off (enable_message_limit = false)".to_owned(),
        "message-id filter: none".to_owned(),
        "synchronisation validation: on".to_owned(),
        format!("settings file: {}", settings_path.display()),
    ];
    settings.extend(
        cleared
            .iter()
            .map(|(n, v)| format!("cleared from the environment: {n}={v}")),
    );
    // The worker: this program with the same scene and matrix arguments.
    let mut worker_args: Vec<OsString> = Vec::new();
    if std::env::args_os().any(|a| a == "--no-default-lights") {
        worker_args.push("--no-default-lights".into());
    }
    worker_args.extend(["check".into(), "--worker".into()]);
    if let Some(dir) = &args.brdfs.brdfs {
        worker_args.extend(["--brdfs".into(), dir.clone().into_os_string()]);
    }
    for scene in &args.scenes {
        worker_args.extend(["--scene".into(), scene.into()]);
    }
    if args.quick {
        worker_args.push("--quick".into());
    }
    if args.best_practices {
        worker_args.push("--best-practices".into());
    }
    if args.general_path {
        worker_args.push("--general-path".into());
    }
    if args.spec_minimum_limits {
        worker_args.push("--spec-minimum-limits".into());
    }
    worker_args.extend(["--out".into(), args.out.clone().into_os_string()]);
    if let Some(path) = &args.accept_messages {
        worker_args.extend(["--accept-messages".into(), path.clone().into_os_string()]);
    }
    if let Some(driver) = &args.expect_driver {
        worker_args.extend(["--expect-driver".into(), driver.into()]);
    }
    for fault in &args.inject_fault {
        let text = match fault {
            InjectedFault::DropFlushes => "drop-flushes".to_owned(),
            InjectedFault::Hang(p) => format!("hang={p}"),
            InjectedFault::Crash(p) => format!("crash={p}"),
            InjectedFault::Flaky(p) => format!("flaky={p}"),
        };
        worker_args.extend(["--inject-fault".into(), text.into()]);
    }
    // SAFETY: installing async-signal-safe handlers (they only store an atomic) before the
    // workers' threads start.
    unsafe {
        libc::signal(libc::SIGINT, on_signal as *const () as libc::sighandler_t);
        libc::signal(libc::SIGTERM, on_signal as *const () as libc::sighandler_t);
    }
    let jobs = args.jobs.unwrap_or_else(|| {
        std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1)
    });
    let runner_options = RunnerOptions {
        program: std::env::current_exe().context("finding this program for its workers")?,
        args: worker_args,
        env_remove: cleared.iter().map(|(n, _)| n.clone()).collect(),
        env_set: vec![(
            "VK_LAYER_SETTINGS_PATH".into(),
            settings_path.clone().into_os_string(),
        )],
        jobs,
        timeout: Duration::from_secs_f64(args.timeout.max(0.001)),
        max_fails: args.max_fails,
        cases_per_worker: args.cases_per_worker,
        baseline,
        flakes,
        out: args.out.clone(),
        stop: &STOP,
        progress_every: Duration::from_secs(if std::io::stderr().is_terminal() {
            2
        } else {
            10
        }),
    };
    let mut report = RunReport {
        settings,
        accepted: options.accepted.accepted.clone(),
        best_practices: args.best_practices,
        quick: args.quick,
        shards: split.map(|s| vec![s.to_string()]).unwrap_or_default(),
        allow_unexpected_pass: args.allow_unexpected_pass,
        ..RunReport::default()
    };
    let selected = cases.len() + skipped.len();
    eprintln!(
        "histencil check: {selected} cases, {jobs} worker(s), timeout {:.0} s; results stream \
         to {}",
        args.timeout,
        args.out.join("results.csv").display()
    );
    runner::run(&cases, skipped, &runner_options, &mut report)?;
    // The device and driver as the workers' canaries and teardowns reported them.
    if let Some(first) = report.records.iter().find(|r| r.scene == "device") {
        report.device = first.data["device"].as_str().unwrap_or("").to_owned();
        report.driver = first.data["driver"].as_str().unwrap_or("").to_owned();
    }
    write_reports(args.junit.as_ref(), args.json.as_ref(), &report)?;
    let summary = report::summary(&report);
    if let Some(path) = &args.summary {
        let command: Vec<String> = std::env::args().skip(1).collect();
        let text = format!(
            "$ histencil {}
# {}
{summary}",
            command.join(" "),
            utc_now()
        );
        histencil_vk::write_atomically(path, text.as_bytes())?;
        println!("wrote {}", path.display());
    }
    print!("{summary}");
    Ok(exit_code(&report))
}

/// What a worker prints on stderr before it exits with [`EXIT_NO_DEVICE`].
const NO_DEVICE_MARK: &str = "histencil check worker: no device";

/// The date and time now, UTC, as `YYYY-MM-DD HH:MM UTC`.
fn utc_now() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs()) as i64;
    let (days, rest) = (secs.div_euclid(86_400), secs.rem_euclid(86_400));
    // Howard Hinnant's days-to-civil: the proleptic Gregorian date of a day count.
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02} {:02}:{:02} UTC",
        rest / 3600,
        rest % 3600 / 60
    )
}

fn exit_code(report: &RunReport) -> ExitCode {
    if !report.failing().is_empty() {
        ExitCode::from(EXIT_FAILING)
    } else if report.incomplete.is_some() {
        ExitCode::from(EXIT_INCOMPLETE)
    } else {
        ExitCode::SUCCESS
    }
}

fn write_reports(
    junit: Option<&PathBuf>,
    json: Option<&PathBuf>,
    report: &RunReport,
) -> Result<()> {
    if let Some(path) = junit {
        histencil_vk::write_atomically(path, report::junit(report).as_bytes())?;
        println!("wrote {}", path.display());
    }
    if let Some(path) = json {
        let text = serde_json::to_string_pretty(&report::json(report))?;
        histencil_vk::write_atomically(path, text.as_bytes())?;
        println!("wrote {}", path.display());
    }
    Ok(())
}

/// `--worker`: the cases in this process, a line per event on stdout (see the runner), and the
/// process's peak memory at the end.
fn worker(scenes: &[CheckScene], options: &CheckOptions, expect_driver: Option<&str>) -> ExitCode {
    let stdout = std::io::stdout();
    let line = |text: String| {
        let mut out = stdout.lock();
        let _ = writeln!(out, "{text}");
        let _ = out.flush();
    };
    let mut device = (String::new(), String::new());
    let report = histencil_check::run_check(scenes, options, |event| match event {
        Event::Context {
            device: name,
            driver,
        } => {
            device = (name.to_owned(), driver.to_string());
            if let Some(expected) = expect_driver.filter(|e| !device.1.contains(e)) {
                eprintln!(
                    "{NO_DEVICE_MARK}: the driver is `{}`, not the `{expected}` --expect-driver \
                     names",
                    device.1
                );
                std::process::exit(i32::from(EXIT_NO_DEVICE));
            }
        }
        Event::Started(name) => line(format!("start {name}")),
        Event::Finished(result, _) => {
            let mut record = Record::from_result(result);
            if record.scene == "device" {
                // The runner names the device and driver from its device rows.
                record.data["device"] = serde_json::json!(device.0);
                record.data["driver"] = serde_json::json!(device.1);
            }
            line(format!("result {}", record.to_json()));
        }
    });
    if let Some(peak) = own_peak_mib() {
        line(format!("peak {peak:.1}"));
    }
    match report {
        Ok(_) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("{NO_DEVICE_MARK}: {e}");
            ExitCode::from(EXIT_NO_DEVICE)
        }
    }
}

fn own_peak_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    Some(line.split_whitespace().nth(1)?.parse::<f64>().ok()? / 1024.0)
}

fn merge(args: &MergeArgs) -> ExitCode {
    let mut runs = Vec::new();
    for path in &args.reports {
        let parsed = std::fs::read_to_string(path)
            .map_err(|e| e.to_string())
            .and_then(|t| serde_json::from_str(&t).map_err(|e| e.to_string()))
            .and_then(|v| report::from_json(&v));
        match parsed {
            Ok(run) => runs.push(run),
            Err(e) => return usage(format!("{}: {e}", path.display())),
        }
    }
    let merged = match report::merge(runs) {
        Ok(m) => m,
        Err(e) => return usage(e),
    };
    if let Err(e) = write_reports(args.junit.as_ref(), args.json.as_ref(), &merged) {
        eprintln!("histencil: {e:#}");
        return ExitCode::FAILURE;
    }
    if let Some(path) = &args.failures {
        if let Err(e) =
            histencil_vk::write_atomically(path, report::failures_csv(&merged).as_bytes())
        {
            eprintln!("histencil: {e:#}");
            return ExitCode::FAILURE;
        }
    }
    if let Some(path) = &args.update_baseline {
        if let Err(e) = update_baseline(path, &merged) {
            eprintln!("histencil: {e:#}");
            return ExitCode::FAILURE;
        }
    }
    print!("{}", report::summary(&merged));
    exit_code(&merged)
}

/// `check merge --update-baseline PATH`: PATH rewritten as the next baseline of `merged`
/// ([`histencil_check::baseline_update`]), what changed on stderr.
fn update_baseline(path: &std::path::Path, merged: &report::RunReport) -> anyhow::Result<()> {
    let old = std::fs::read_to_string(path)
        .map_err(|e| anyhow::anyhow!("{}: cannot read: {e}", path.display()))?;
    // Refuse what the runner would refuse before writing anything.
    Baseline::parse(&old, &path.display().to_string())?;
    let failing = report::failing(merged).into_iter().collect();
    let ran: HashSet<String> = merged.records.iter().map(|r| r.full_name()).collect();
    let update = histencil_check::baseline_update::update_baseline(&old, &failing, &|name| {
        ran.contains(name)
    });
    histencil_vk::write_atomically(path, update.text.as_bytes())?;
    eprintln!(
        "histencil check: {}: {} line(s) kept with their reasons, {} changed and {} added \
         (marked `# {}`), {} removed (now passing)",
        path.display(),
        update.kept,
        update.changed.len(),
        update.added.len(),
        histencil_check::baseline_update::NEEDS_REASON,
        update.now_pass.len()
    );
    for line in update.changed.iter().chain(&update.added) {
        eprintln!("  needs a reason: {line}");
    }
    for line in &update.now_pass {
        eprintln!("  now passes: {line}");
    }
    Ok(())
}
