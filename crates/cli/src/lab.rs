//! `compare`, `sweep` and `calibrate`: the lab's runs with a progress bar.

use crate::on_device;
use anyhow::{bail, Result};
use histencil_lab::{CompareSettings, SweepParam};
use histencil_scene::DefaultLights;
use histencil_vk::ImageKind;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;

/// What every lab run takes: the frame size, the timed frames and validation.
#[derive(clap::Args)]
pub struct RunArgs {
    #[arg(long, default_value_t = 1280)]
    width: u32,
    #[arg(long, default_value_t = 720)]
    height: u32,
    /// Timed frames per measurement (after one warm-up frame), at least 1.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u64).range(1..))]
    frames: u64,
    /// Run under the validation layer; any message fails the run.
    #[arg(long)]
    validate: bool,
    /// Leave the device's depth bounds test unused where it has one (`depthBounds`): the path
    /// of a device without it, for comparing the two.
    #[arg(long)]
    no_depth_bounds: bool,
    /// Apply no driver quirk (tile side and classification shape): the general path every
    /// other driver takes, on this one.
    #[arg(long)]
    general_path: bool,
}

impl RunArgs {
    fn device(&self) -> crate::DeviceArgs {
        crate::DeviceArgs {
            validate: self.validate,
            no_depth_bounds: self.no_depth_bounds,
            general_path: self.general_path,
            spec_minimum_limits: false,
        }
    }
}

#[derive(clap::Args)]
pub struct CompareArgs {
    /// An embedded scene or a `.gltf` / `.glb` file; its objects' BRDFs are folded onto 1, 2
    /// and 3 models for the table's columns.
    #[arg(long, default_value = "huge-lights")]
    scene: String,
    /// With it, the columns' models are the folder's BRDFs first (each with its defaults), then
    /// the built-ins it keeps, and the light-size wall is striped in the first three: the
    /// talk's question asked of your shading models.
    #[command(flatten)]
    brdfs: crate::brdfs::BrdfsArg,
    #[command(flatten)]
    run: RunArgs,
    /// Light sizes of the light-size sweep, in percent of the screen.
    #[arg(long, value_delimiter = ',', default_value = "0.1,0.3,1,3,10,30,100")]
    light_sizes: Vec<f64>,
    /// Costs from `histencil calibrate` for the adaptive technique (default: fitted to the
    /// talk's figures).
    #[arg(long)]
    costs: Option<PathBuf>,
    /// Output directory: report.md, report.json and PNG plots.
    #[arg(long, default_value = "out/compare")]
    out: PathBuf,
    #[command(flatten)]
    sampling: SamplingArgs,
    /// When the table and each light size stop sampling: `decided`, once the talk's cells
    /// (the overheads of branching and stencil x360/ps3/native at 2 and 3 BRDFs, every stencil
    /// row against branching at 2 and 3 BRDFs; each size's stencil against branching) are
    /// decided, at least --frames rounds, within a budget a 10-round pilot
    /// predicts unless --budget-s sets it; `rounds`, after --frames rounds exactly (or at
    /// --target-ci's width).
    #[arg(long, value_enum, default_value_t = Until::Decided, conflicts_with = "target_ci")]
    until: Until,
    /// With --until decided and no --budget-s: the most the pilot's predicted budget may be,
    /// per measurement set, in seconds (a lent machine's time, say).
    #[arg(long, default_value_t = PREDICTED_BUDGET_CAP_S, conflicts_with = "budget_s")]
    budget_cap_s: f64,
    /// Run this many busy threads beside the measurement: the same run under contention, to
    /// merge with a quiet one (`compare merge`), which lists the verdicts the load turned round
    /// (on a CPU driver a load on the cores changes the techniques' ratios themselves).
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u16).range(0..=64))]
    beside_load: u16,
    /// Start the --beside-load threads as the table's round N (from 1) begins instead of before
    /// the run: conditions that change part way, which the steady clock must see (its rounds
    /// retaken and its canary warmed up again there, in the report's "Steady clock").
    #[arg(long, value_name = "N", requires = "beside_load", value_parser = clap::value_parser!(u32).range(1..))]
    beside_load_from_round: Option<u32>,
    #[command(flatten)]
    clock: ClockArgs,
    /// A first answer in minutes (3 min 9 s on lavapipe with 2 cores, where its table decided
    /// all 10 of the talk's verdicts, the steady clock's retakes included): 320x180, light sizes
    /// 1, 10 and 100 %, each of the four measurement sets (the table, three sizes) sampled until
    /// decided within at most 90 s. A default run (1280x720, seven light sizes, up to 1800 s a
    /// set) takes hours on lavapipe and is meant for a GPU: on an NVIDIA H200 (a run before the
    /// steady clock) its eight sets sampled for 6 s in all, each decided in 10 to 12 rounds,
    /// the references and pipelines around them taking most of its time. Progress goes to
    /// stderr either way.
    #[arg(long, conflicts_with_all = ["width", "height", "light_sizes", "budget_cap_s", "budget_s"])]
    quick: bool,
    #[command(subcommand)]
    command: Option<CompareCommand>,
}

/// `compare --quick`'s size, light sizes (percent) and budget cap per set (seconds).
const QUICK: (u32, u32, [f64; 3], f64) = (320, 180, [1.0, 10.0, 100.0], 90.0);

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Until {
    Decided,
    Rounds,
}

#[derive(clap::Subcommand)]
enum CompareCommand {
    /// Put several `compare` runs (devices, drivers, one device quiet and loaded, or repeats) side
    /// by side: one table and one plot, the device and driver named in each column. Exits 1 when
    /// a decided verdict reverses between two runs of one device, driver and conditions (a
    /// repeat); a reversal between a quiet and a loaded run is listed as a finding.
    Merge(CompareMergeArgs),
    /// Whether a change moved the lighting time: two builds (or two settings) of one workload,
    /// their runs alternated on one device (before, after, then after, before ...); per cell the
    /// after run's median over the before run's, pair by pair, and the lab's verdict on their
    /// median at --margin (none from fewer than 10 pairs). Writes paired.md and paired.json.
    Pair(ComparePairArgs),
}

#[derive(clap::Args)]
struct ComparePairArgs {
    /// The before runs' output folders, in the order the pairs ran.
    #[arg(long, required = true, num_args = 1..)]
    before: Vec<PathBuf>,
    /// The after runs' output folders, in the same order: the i-th ran next to the i-th before
    /// run, which of the two went first alternating from pair to pair (so that a drift of the
    /// machine does not always favour one).
    #[arg(long, required = true, num_args = 1..)]
    after: Vec<PathBuf>,
    /// A tie within ± this many percent.
    #[arg(long, default_value_t = 2.0)]
    margin: f64,
    /// What the before runs ran (a commit, say), for the table.
    #[arg(long, default_value = "before")]
    before_name: String,
    /// What the after runs ran, for the table.
    #[arg(long, default_value = "after")]
    after_name: String,
    /// A setting of the reports (a key of report.json's `settings`) that may differ between
    /// the runs: the one under test (`depth_bounds`, say). Every other setting both reports
    /// hold must agree.
    #[arg(long, value_name = "KEY")]
    differs: Vec<String>,
    /// Where paired.md and paired.json go.
    #[arg(long, default_value = "out/compare-paired")]
    out: PathBuf,
}

fn compare_pair(args: &ComparePairArgs) -> Result<()> {
    use histencil_lab::compare::{merge::DeviceReport, pair::Paired};
    let paired = Paired::new(
        DeviceReport::read_all(&args.before)?,
        DeviceReport::read_all(&args.after)?,
        (args.before_name.clone(), args.after_name.clone()),
        args.margin / 100.0,
        &args.differs,
    )?;
    histencil_vk::check_output_dir(&args.out)?;
    for path in paired.write(&args.out)? {
        println!("wrote {}", path.display());
    }
    print!("{}", paired.markdown());
    Ok(())
}

#[derive(clap::Args)]
struct CompareMergeArgs {
    /// The runs' output folders (each holding the report.json `compare` wrote).
    #[arg(required = true, num_args = 2..)]
    runs: Vec<PathBuf>,
    /// Where merged.md, merged.json and merged-lighting.png go.
    #[arg(long, default_value = "out/compare-merged")]
    out: PathBuf,
}

fn compare_merge(args: &CompareMergeArgs) -> Result<()> {
    histencil_vk::check_output_dir(&args.out)?;
    let reports = histencil_lab::compare::merge::DeviceReport::read_all(&args.runs)?;
    let merged = histencil_lab::compare::merge::Merged::new(reports)?;
    for path in merged.write(&args.out)? {
        println!("wrote {}", path.display());
    }
    print!("{}", merged.markdown());
    let reversed = merged.same_device_reversals();
    if !reversed.is_empty() {
        bail!(
            "{} decided verdict(s) reversed between runs of one device, driver and conditions: {}",
            reversed.len(),
            reversed
                .iter()
                .map(|(what, _, _)| what.as_str())
                .collect::<Vec<_>>()
                .join("; ")
        );
    }
    Ok(())
}

/// The steady clock under a measurement's rounds (compare, calibrate, sweep).
#[derive(clap::Args)]
pub struct ClockArgs {
    /// The steady clock's tolerance in percent: a canary frame (branching's lighting at 1 BRDF,
    /// timed between every two rounds after a warm-up until it settles) further than this from
    /// its reference has its round thrown away and retaken.
    #[arg(long, value_name = "PERCENT", default_value_t = 10.0)]
    clock_tolerance: f64,
    /// No steady clock: no canary, no warm-up until it settles, every round kept as taken.
    #[arg(long, conflicts_with = "clock_tolerance")]
    no_steady_clock: bool,
}

impl ClockArgs {
    /// The clock's settings, `None` without one.
    fn settings(&self) -> Result<Option<histencil_lab::steady::ClockSettings>> {
        let tolerance = self.clock_tolerance;
        if !(tolerance > 0.0 && tolerance < 100.0) {
            bail!("--clock-tolerance: {tolerance} is not a percentage in (0, 100)");
        }
        Ok(
            (!self.no_steady_clock).then_some(histencil_lab::steady::ClockSettings {
                tolerance: tolerance / 100.0,
                ..Default::default()
            }),
        )
    }
}

/// How long a measurement samples (compare, calibrate).
#[derive(clap::Args)]
pub struct SamplingArgs {
    /// Keep sampling (past --frames rounds) until every tracked 95 % interval is within ±this
    /// many percent, or --budget-s runs out. Without it: calibrate takes --frames rounds
    /// exactly; compare samples until its verdicts are decided (--until decided, its default),
    /// or --frames rounds exactly with --until rounds.
    #[arg(long)]
    target_ci: Option<f64>,
    /// Seconds each measurement set (compare: the table, each light size) may sample for
    /// (default: compare until its cells are decided lets a pilot predict it, at most 1800 s;
    /// otherwise 60 s).
    #[arg(long)]
    budget_s: Option<f64>,
}

/// The most a predicted budget may be, per measurement set, when `--budget-s` does not say.
const PREDICTED_BUDGET_CAP_S: f64 = 1800.0;

impl SamplingArgs {
    /// The sampling rule, at least `frames` rounds; refuses percentages and budgets that make
    /// no sense.
    fn sampling(&self, frames: u64) -> Result<histencil_lab::stats::Sampling> {
        if let Some(bad) = self.target_ci.filter(|c| !(*c > 0.0 && *c < 100.0)) {
            bail!("--target-ci: {bad} is not a percentage in (0, 100)");
        }
        let budget = self.budget_s.unwrap_or(60.0);
        if !(budget.is_finite() && (0.0..=86_400.0).contains(&budget)) {
            bail!("--budget-s: {budget} is not between 0 and 86400 seconds");
        }
        let rounds = frames as usize;
        Ok(histencil_lab::stats::Sampling {
            min_rounds: rounds,
            target: self.target_ci.map(|c| c / 100.0),
            budget: std::time::Duration::from_secs_f64(budget),
            max_rounds: if self.target_ci.is_some() {
                histencil_lab::MAX_ROUNDS.max(rounds)
            } else {
                rounds
            },
            until_decided: false,
            predict_budget: false,
        })
    }
}

#[derive(Clone, Copy, clap::ValueEnum)]
pub enum ParamArg {
    LutRes,
    LightmapRes,
    Slices,
    TileSize,
}

#[derive(clap::Args)]
pub struct SweepArgs {
    /// The setting to sweep.
    #[arg(long, value_enum)]
    param: ParamArg,
    /// Values to try (default: lut-res 8..96, lightmap-res 4..128, slices 1..32, tile-size
    /// 2..64).
    #[arg(long, value_delimiter = ',')]
    values: Vec<u32>,
    /// Scene (default: `default` for lut-res and tile-size, `alpha` for lightmap-res, `volume`
    /// for slices).
    #[arg(long)]
    scene: Option<String>,
    #[command(flatten)]
    run: RunArgs,
    /// Output directory: sweep.csv, sweep.json, pareto.png.
    #[arg(long, default_value = "out/sweep")]
    out: PathBuf,
    #[command(flatten)]
    clock: ClockArgs,
}

#[derive(clap::Args)]
pub struct CalibrateArgs {
    #[command(flatten)]
    run: RunArgs,
    /// The wall striped in the folder's BRDFs: the costs of your shading models, for
    /// `--costs` of `render --technique adaptive` and `compare`.
    #[command(flatten)]
    brdfs: crate::brdfs::BrdfsArg,
    /// Where the costs go (read back by `--costs`).
    #[arg(long, default_value = "out/costs.json")]
    out: PathBuf,
    #[command(flatten)]
    sampling: SamplingArgs,
    #[command(flatten)]
    clock: ClockArgs,
}

#[derive(clap::Args)]
pub struct DemoArgs {
    /// An embedded scene or a `.gltf` / `.glb` file.
    #[arg(long, default_value = "default")]
    scene: String,
    #[command(flatten)]
    run: RunArgs,
    /// The contact sheet, in the format its extension names (`.png`, `.jpg` or `.jpeg`).
    #[arg(long, default_value = "out/demo.png")]
    out: PathBuf,
    #[command(flatten)]
    brdfs: crate::brdfs::BrdfsArg,
}

#[derive(clap::Args)]
pub struct TodaysGpusArgs {
    /// The scenes, embedded or `.gltf` / `.glb` files.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "default,huge-lights,town"
    )]
    scenes: Vec<String>,
    #[arg(long, default_value_t = 640)]
    width: u32,
    #[arg(long, default_value_t = 360)]
    height: u32,
    /// Output directory: todays-gpus.md and todays-gpus.json.
    #[arg(long, default_value = "out/todays-gpus")]
    out: PathBuf,
    /// Run under the validation layer; any message fails the run.
    #[arg(long)]
    validate: bool,
}

pub fn todays_gpus(args: &TodaysGpusArgs, lights: DefaultLights) -> Result<()> {
    histencil_vk::check_output_dir(&args.out)?;
    let scenes = args
        .scenes
        .iter()
        .map(|s| crate::load_scene_arg(s, lights))
        .collect::<Result<Vec<_>>>()?;
    let report = on_device(args.validate, |ctx| {
        Ok(with_spinner(|step| {
            histencil_lab::todays_gpus::run_todays_gpus(ctx, &scenes, args.width, args.height, step)
        })?)
    })?;
    for path in report.write(&args.out)? {
        println!("wrote {}", path.display());
    }
    print!("{}", report.markdown());
    // The table is the simulator's; the GPU's emulation must have counted the same.
    let disagreements = report.disagreements();
    if !disagreements.is_empty() {
        let list: Vec<String> = disagreements
            .iter()
            .map(|(p, s)| format!("{p} on {s}"))
            .collect();
        bail!(
            "the GPU's counts differ from the simulator's for {}",
            list.join(", ")
        );
    }
    Ok(())
}

#[derive(clap::Args)]
pub struct ScaleArgs {
    /// An embedded scene or a `.gltf` / `.glb` file.
    #[arg(long, default_value = "town")]
    scene: String,
    #[command(flatten)]
    run: RunArgs,
    /// The report (markdown).
    #[arg(long, default_value = "out/scale.md")]
    out: PathBuf,
}

/// A spinner with a message, or a bar when the number of steps is known.
fn spinner() -> ProgressBar {
    ProgressBar::new_spinner().with_style(
        ProgressStyle::with_template("{spinner} {elapsed} {msg}").expect("valid template"),
    )
}

/// Runs `body` under a spinner that shows the step it last reported, where stderr is a
/// terminal; elsewhere (a CI log, a pipe) each step as a plain line with the seconds since the
/// start, a round's line at most every 10 s (a GPU runs many a second).
fn with_spinner<T>(body: impl FnOnce(&mut dyn FnMut(&str)) -> T) -> T {
    use std::io::IsTerminal;
    if !std::io::stderr().is_terminal() {
        let start = std::time::Instant::now();
        // When the last line went out, and what it was about (the text before `round`).
        let mut last: Option<(std::time::Instant, String)> = None;
        return body(&mut |what| {
            let about = what.split("round ").next().unwrap_or(what).to_owned();
            let recent = last.as_ref().is_some_and(|(t, a)| {
                *a == about && t.elapsed().as_secs_f64() < 10.0 && what.contains("round ")
            });
            if recent {
                return;
            }
            last = Some((std::time::Instant::now(), about));
            eprintln!(
                "histencil: {:>6.0} s  {what}",
                start.elapsed().as_secs_f64()
            );
        });
    }
    let bar = spinner();
    let out = body(&mut |what| {
        bar.set_message(what.to_owned());
        bar.tick();
    });
    bar.finish_and_clear();
    out
}

/// The `--costs` file's cost model and its BRDF weights for `set`'s BRDFs, if one was given.
pub fn read_costs_arg(
    path: Option<&std::path::Path>,
    set: &histencil_brdf::BrdfSet,
) -> Result<(
    Option<histencil_vk::CostModel>,
    Option<histencil_brdf::BrdfWeights>,
)> {
    let Some(path) = path else {
        return Ok((None, None));
    };
    let costs = histencil_lab::read_costs(path)?;
    Ok((Some(costs), histencil_lab::read_brdf_weights(path, set)?))
}

/// llvmpipe's timings are steadiest with one rasteriser thread: at 320x180, 15 interleaved
/// rounds gave overhead intervals of ±2.7 to ±3.6 % with `LP_NUM_THREADS=1` against ±4.4 to
/// ±8.8 % with 2 on a 2-core machine (README, "Measured"), at 1.6 times the time per round, so
/// tighter per second too. The lab's timing commands take it as their default unless the caller
/// set it; other drivers ignore the variable. Runs before any thread or Vulkan object exists.
fn steady_llvmpipe() {
    if std::env::var_os("LP_NUM_THREADS").is_none() {
        std::env::set_var("LP_NUM_THREADS", "1");
    }
}

pub fn compare(args: &CompareArgs, lights: DefaultLights) -> Result<()> {
    match &args.command {
        Some(CompareCommand::Merge(merge)) => return compare_merge(merge),
        Some(CompareCommand::Pair(pair)) => return compare_pair(pair),
        None => {}
    }
    steady_llvmpipe();
    histencil_vk::check_output_dir(&args.out)?;
    let (width, height, light_sizes, budget_cap_s) = if args.quick {
        (QUICK.0, QUICK.1, QUICK.2.to_vec(), QUICK.3)
    } else {
        let r = &args.run;
        (
            r.width,
            r.height,
            args.light_sizes.clone(),
            args.budget_cap_s,
        )
    };
    if let Some(bad) = light_sizes.iter().find(|s| !(**s > 0.0 && **s <= 100.0)) {
        bail!("--light-sizes: {bad} is not a percentage in (0, 100]");
    }
    let mut sampling = args.sampling.sampling(args.run.frames)?;
    if args.until == Until::Decided && args.sampling.target_ci.is_none() {
        sampling.until_decided = true;
        sampling.max_rounds = histencil_lab::MAX_ROUNDS.max(sampling.min_rounds);
        if args.sampling.budget_s.is_none() {
            let cap = budget_cap_s;
            if !(cap.is_finite() && cap > 0.0 && cap <= 86_400.0) {
                bail!("--budget-cap-s: {cap} is not between 0 and 86400 seconds");
            }
            sampling.predict_budget = true;
            sampling.budget = std::time::Duration::from_secs_f64(cap);
        }
    }
    let least = histencil_lab::stats::MIN_VERDICT_ROUNDS;
    if sampling.max_rounds < least {
        eprintln!(
            "histencil compare: {} rounds decide no verdict (every one needs {least}): give \
             --frames {least} or more, or --target-ci",
            sampling.max_rounds
        );
    }
    let mut settings = CompareSettings::talk(width, height, args.run.frames as usize);
    settings.target_ci = sampling.target;
    settings.budget = sampling.budget;
    settings.until_decided = sampling.until_decided;
    settings.predict_budget = sampling.predict_budget;
    settings.brdfs = args.brdfs.modules()?;
    settings.scene = crate::brdfs::load_scene(&args.scene, lights, settings.brdfs)?;
    settings.light_sizes = light_sizes.iter().map(|s| s / 100.0).collect();
    (settings.costs, settings.brdf_weights) =
        read_costs_arg(args.costs.as_deref(), &settings.brdfs.set)?;
    settings.beside_load = usize::from(args.beside_load);
    settings.load_from_round = args.beside_load_from_round.map(|r| r as usize - 1);
    settings.clock = args.clock.settings()?;
    settings.first_row = true;
    let report = on_device(args.run.device(), |ctx| {
        Ok(with_spinner(|step| {
            histencil_lab::run_compare(ctx, &settings, step)
        })?)
    })?;
    for path in report.write(&args.out)? {
        println!("wrote {}", path.display());
    }
    print!("{}", report.markdown());
    Ok(())
}

pub fn sweep(args: &SweepArgs, lights: DefaultLights) -> Result<()> {
    steady_llvmpipe();
    histencil_vk::check_output_dir(&args.out)?;
    let param = match args.param {
        ParamArg::LutRes => SweepParam::LutRes,
        ParamArg::LightmapRes => SweepParam::LightmapRes,
        ParamArg::Slices => SweepParam::Slices,
        ParamArg::TileSize => SweepParam::TileSize,
    };
    let values = if args.values.is_empty() {
        param.default_values()
    } else {
        args.values.clone()
    };
    let scene = crate::load_scene_arg(
        args.scene.as_deref().unwrap_or(param.default_scene()),
        lights,
    )?;
    let clock = args.clock.settings()?;
    let report = on_device(args.run.device(), |ctx| {
        let report = with_spinner(|step| {
            histencil_lab::run_sweep(
                ctx,
                scene,
                param,
                &values,
                (args.run.width, args.run.height),
                args.run.frames as usize,
                clock,
                step,
            )
        });
        Ok(report?)
    })?;
    for path in report.write(&args.out)? {
        println!("wrote {}", path.display());
    }
    Ok(())
}

pub fn calibrate(args: &CalibrateArgs) -> Result<()> {
    steady_llvmpipe();
    histencil_vk::check_output_file(&args.out)?;
    let sampling = args.sampling.sampling(args.run.frames)?;
    let clock = args.clock.settings()?;
    let modules = args.brdfs.modules()?;
    let calibration = on_device(args.run.device(), |ctx| {
        let c = with_spinner(|step| {
            let size = (args.run.width, args.run.height);
            histencil_lab::calibrate_with(ctx, size, modules, &sampling, clock, step)
        });
        Ok(c?)
    })?;
    calibration.write(&args.out)?;
    let c = &calibration.costs;
    let iv = c.interval.unwrap_or_default();
    let with = |x: f64, i: usize| format!("{x:.4} ms [{:.4}, {:.4}]", iv[i].0, iv[i].1);
    println!(
        "wrote {} ({}; {} rounds, {}): pass overhead {}, stencil {} and branch tax {} per extra \
         BRDF per full-screen light, shade {} (medians over rounds, 95 % intervals); stencil \
         wins above {}",
        args.out.display(),
        calibration.device,
        calibration.sampled.rounds,
        calibration.sampled.stop.word(),
        with(c.pass_overhead_ms, 0),
        with(c.stencil_per_brdf_ms, 1),
        with(c.branch_tax_per_brdf_ms, 2),
        with(c.shade_ms, 3),
        match c.crossover_coverage() {
            Some(x) if x <= 1.0 => format!("{:.2} % of the screen", x * 100.0),
            Some(x) => format!(
                "no light (it would at {:.0} % of the screen, past the whole of it)",
                x * 100.0
            ),
            None => "no light".to_owned(),
        }
    );
    if !calibration.brdf_weights.is_empty() {
        let weights: Vec<String> = calibration
            .brdf_weights
            .iter()
            .map(|(name, w)| format!("{name} {:.3} [{:.3}, {:.3}]", w.median, w.lo, w.hi))
            .collect();
        println!(
            "BRDF weights (shading alone over their mean; branching's tax is weighted by them): {}",
            weights.join(", ")
        );
    }
    if let Some(t) = c.tiled {
        let iv = t.interval.unwrap_or_default();
        println!(
            "tiled: classification {:.4} ms [{:.4}, {:.4}] per frame, shade {:.4} ms [{:.4}, \
             {:.4}] per full-screen light (the adaptive technique lights a frame tiled where \
             these predict it surely cheaper than its plan)",
            t.classify_ms, iv[0].0, iv[0].1, t.shade_ms, iv[1].0, iv[1].1
        );
    }
    Ok(())
}

pub fn scale(args: &ScaleArgs, lights: DefaultLights) -> Result<()> {
    histencil_vk::check_output_file(&args.out)?;
    let start = std::time::Instant::now();
    let scene = crate::load_scene_arg(&args.scene, lights)?;
    let settings = histencil_lab::ScaleSettings {
        scene,
        load_ms: start.elapsed().as_secs_f64() * 1e3,
        width: args.run.width,
        height: args.run.height,
        rounds: args.run.frames as usize,
    };
    let report = on_device(args.run.device(), |ctx| {
        Ok(with_spinner(|step| {
            histencil_lab::run_scale(ctx, settings, step)
        })?)
    })?;
    let markdown = format!("# `{}` at scale\n\n{}", args.scene, report.markdown());
    histencil_vk::write_atomically(&args.out, markdown.as_bytes())?;
    print!("{markdown}");
    println!("\nwrote {}", args.out.display());
    Ok(())
}

pub fn demo(args: &DemoArgs, lights: DefaultLights) -> Result<()> {
    histencil_vk::check_image_output(&args.out, ImageKind::Colour)?;
    let brdfs = args.brdfs.modules()?;
    let settings = histencil_lab::DemoSettings {
        scene: crate::brdfs::load_scene(&args.scene, lights, brdfs)?,
        width: args.run.width,
        height: args.run.height,
        frames: args.run.frames as usize,
        brdfs,
    };
    let report = on_device(args.run.device(), |ctx| {
        Ok(with_spinner(|step| {
            histencil_lab::run_demo(ctx, settings, step)
        })?)
    })?;
    let sheet = image::DynamicImage::from(report.sheet.clone());
    histencil_vk::save_image_as(&sheet, &args.out, ImageKind::Colour)?;
    println!("The talk on `{}`:\n", args.scene);
    print!("{}", report.table());
    println!(
        "\nwrote {}: forward | stencil 360-like | difference x16 | stencil byte, then the \
         talk's failures next to their fixes",
        args.out.display()
    );
    println!(
        "\nnext:\n  histencil compare --out out/compare        the talk's table on this device\n  \
         histencil check --quick --junit out/junit.xml   the validation-CI matrix\n  \
         histencil render --scene your.gltf --technique stencil --backend x360 --out out/yours.png"
    );
    Ok(())
}
