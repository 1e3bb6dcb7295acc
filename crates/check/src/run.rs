//! Running the matrix on a device: one validated context per depth-stencil format, one renderer
//! per scene and resolution, the forward reference rendered first in the same process, then
//! every case rendered, judged and given the validation messages that arrived while it ran.

use crate::judge::{self, ImageVerdict, StencilInputs, ALPHA_LIGHTMAP, ALPHA_PROBE};
use crate::lists::AcceptedMessages;
use crate::matrix::{self, Case, Config, Expect, KnownWrong, Platform, SceneNeeds};
use histencil_model::FlushPolicy;
use histencil_scene::Scene;
use histencil_vk::{
    AlphaMode, Context, ContextDesc, DepthStencilFormat, DriverInfo, FrameDesc, Readback, Renderer,
    Shading, SimulatorInputs, Technique, ValidationLog, ValidationMessage,
};
use image::{GrayImage, RgbaImage};
use std::collections::{HashMap, HashSet};
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// A scene to check, with the name it was asked for by (an embedded name or a glTF path).
pub struct CheckScene {
    pub name: String,
    pub scene: Scene,
    /// The BRDFs its cases shade with, forward reference included: histencil's, or an
    /// engine's set (`--brdfs`).
    pub brdfs: &'static histencil_vk::BrdfModules,
}

impl CheckScene {
    /// The scene's name as a file-name component: the embedded name, or a glTF file's stem.
    pub fn file_name(&self) -> String {
        let stem = Path::new(&self.name)
            .file_stem()
            .map_or_else(|| self.name.clone(), |s| s.to_string_lossy().into_owned());
        stem.chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                    c
                } else {
                    '_'
                }
            })
            .collect()
    }
}

/// Best-practices messages histencil accepts under `--best-practices`, with the reason; they
/// are counted per case ([`CaseResult::accepted`]) instead of failing it. Only best-practices
/// ids can be here: a validation or synchronisation message always fails.
pub const ACCEPTED_BEST_PRACTICES: [(&str, &str); 1] = [(
    "UNASSIGNED-BestPractices-SpirvDeprecated_WorkgroupSize",
    "glslang declares the WorkgroupSize built-in for every compute shader's local size; the \
     LocalSizeId mode that replaces it needs SPIR-V 1.6 (VK_KHR_maintenance4), and the shaders \
     target SPIR-V 1.3 so that naga can validate them",
)];

/// The messages since `mark`, less the accepted ones (histencil's best-practices ones and the
/// user's `--accept-messages`), which are returned as a count.
fn messages_since(
    log: &ValidationLog,
    mark: usize,
    user: &AcceptedMessages,
) -> (Vec<ValidationMessage>, usize) {
    let (accepted, failing): (Vec<_>, Vec<_>) = log.since(mark).into_iter().partition(|m| {
        ACCEPTED_BEST_PRACTICES.iter().any(|(id, _)| m.id == *id) || user.accepts(&m.id)
    });
    (failing, accepted.len())
}

/// A deliberate defect, for proving that the check can fail (tests and `--inject-fault`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum InjectedFault {
    /// Every case on a hi-stencil backend is rendered without flushes, whatever it says.
    DropFlushes,
    /// Cases whose `scene/case` name contains this never finish (a hung device, as a runner
    /// sees one): the runner's `--timeout` must end them.
    Hang(String),
    /// Cases whose `scene/case` name contains this abort the process (a driver crash, as a
    /// runner sees one); `device/teardown-<format>` names a context's destruction.
    Crash(String),
    /// Cases whose `scene/case` name contains this fail the first time they run with a given
    /// `--out` folder and pass after (a marker file there remembers): a flaky driver, as a
    /// runner that reruns failures sees one.
    Flaky(String),
}

/// A device-limit refusal: a skip where the device is below a need histencil states
/// (`histencil_vk::NEEDS`), for it cannot run the configuration; a failure where the device meets
/// every stated need, for then the code needs more than its own table says (a regression the
/// table must not hide as skips).
fn device_limit_outcome(ctx: &Context, why: String) -> Outcome {
    let limits = ctx.device_limits();
    let below = histencil_vk::NEEDS
        .iter()
        .any(|n| limits.get(n.limit) < n.most);
    if below {
        Outcome::Skipped(why)
    } else {
        Outcome::Failed(format!(
            "{why}, more than histencil's own NEEDS table states, on a device that meets it"
        ))
    }
}

/// What an injected hang or crash does: never return, or abort the process.
fn strike(fault: &InjectedFault) {
    match fault {
        InjectedFault::Hang(_) => loop {
            std::thread::sleep(std::time::Duration::from_secs(3600));
        },
        InjectedFault::Crash(_) => std::process::abort(),
        _ => {}
    }
}

/// How to run the matrix.
#[derive(Clone, Debug, Default)]
pub struct CheckOptions {
    /// The resolutions 1x1, 7x5 and 257x129 only (the full run adds 1280x720).
    pub quick: bool,
    /// The validation layer's best-practices checks as well.
    pub best_practices: bool,
    /// No driver quirk and no depth bounds test: the general path, on any device
    /// (`ContextDesc::general_path`, `ContextDesc::without_depth_bounds`).
    pub general_path: bool,
    /// The device's limits capped at the spec's minimums (`ContextDesc::spec_minimum_limits`).
    pub spec_minimum_limits: bool,
    /// Print each step of the work on stdout as it begins, `step <what>` a line
    /// (`Context::observe_steps`): a runner reading them knows what a crashed or hung process
    /// was recording or waiting on.
    pub trace_steps: bool,
    /// Where a failing case writes its images, stencil dump and validation messages.
    pub out: Option<PathBuf>,
    /// Only cases whose `scene/case` name contains this.
    pub filter: Option<String>,
    /// Only the cases named here (`scene/case`), after `filter`: a runner's case list.
    pub only: Option<HashSet<String>>,
    /// Validation messages the user accepts: counted per case, never failing it.
    pub accepted: AcceptedMessages,
    pub inject: Vec<InjectedFault>,
}

/// What [`run_check`] tells its caller as it goes.
pub enum Event<'a> {
    /// A context was made for the next cases: the device and its driver.
    Context {
        device: &'a str,
        driver: &'a DriverInfo,
    },
    /// A case (`scene/case`) begins; a group's first case begins before the group's setup
    /// (renderer and forward reference), which counts as its time.
    Started(&'a str),
    /// A case, a canary or a teardown ended, with the number of cases planned.
    Finished(&'a CaseResult, usize),
}

/// How a case ended.
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    Passed,
    Failed(String),
    Skipped(String),
    /// The validation layer did not report the canary's deliberate invalid calls.
    Muted(String),
}

/// One case's result, with every number it was judged on.
#[derive(Clone, Debug)]
pub struct CaseResult {
    /// The scene's name as asked for; `device` for a context's teardown.
    pub scene: String,
    pub name: String,
    /// `None` for a teardown.
    pub case: Option<Case>,
    pub outcome: Outcome,
    pub seconds: f64,
    pub image: Option<ImageVerdict>,
    pub stencil_problems: Vec<String>,
    pub validation: Vec<ValidationMessage>,
    /// Messages of [`ACCEPTED_BEST_PRACTICES`] that arrived during the case.
    pub accepted: usize,
    /// A known-wrong case's evidence, or why a reference passed.
    pub note: Option<String>,
    /// Files written for a failure.
    pub artifacts: Vec<PathBuf>,
}

impl CaseResult {
    fn new(scene: &str, name: String, case: Option<Case>) -> Self {
        Self {
            scene: scene.to_owned(),
            name,
            case,
            outcome: Outcome::Passed,
            seconds: 0.0,
            image: None,
            stencil_problems: Vec::new(),
            validation: Vec::new(),
            accepted: 0,
            note: None,
            artifacts: Vec::new(),
        }
    }
}

/// The whole run.
#[derive(Clone, Debug)]
pub struct CheckReport {
    pub device: String,
    /// The driver and validation layer of the last context the run made.
    pub driver: DriverInfo,
    pub best_practices: bool,
    pub quick: bool,
    pub results: Vec<CaseResult>,
    pub seconds: f64,
}

impl CheckReport {
    /// Failed cases, a muted validation layer included.
    pub fn failed(&self) -> usize {
        self.count(|o| matches!(o, Outcome::Failed(_) | Outcome::Muted(_)))
    }

    pub fn skipped(&self) -> usize {
        self.count(|o| matches!(o, Outcome::Skipped(_)))
    }

    pub fn passed(&self) -> usize {
        self.count(|o| *o == Outcome::Passed)
    }

    fn count(&self, f: impl Fn(&Outcome) -> bool) -> usize {
        self.results.iter().filter(|r| f(&r.outcome)).count()
    }
}

/// What cannot be a case's failure: the device or its validation layer is not there at all.
#[derive(Debug, thiserror::Error)]
pub enum CheckError {
    #[error(transparent)]
    Vulkan(#[from] histencil_vk::Error),
    #[error("scene `{scene}`: {source}")]
    Layout {
        scene: String,
        source: histencil_model::LayoutError,
    },
}

/// Every case of `scenes`, per format and resolution, after `options.filter`: what `--list`
/// prints and what [`run_check`] runs.
pub fn planned_cases(
    scenes: &[CheckScene],
    options: &CheckOptions,
) -> Result<Vec<(usize, Case)>, CheckError> {
    let mut planned = Vec::new();
    for format in DepthStencilFormat::ALL {
        for (index, scene) in scenes.iter().enumerate() {
            let needs = SceneNeeds::of(&scene.scene).map_err(|source| CheckError::Layout {
                scene: scene.name.clone(),
                source,
            })?;
            for size in matrix::resolutions(options.quick) {
                for case in matrix::cases(needs, format, size) {
                    let full = format!("{}/{}", scene.name, case.name());
                    if options.filter.as_ref().is_none_or(|f| full.contains(f))
                        && options
                            .only
                            .as_ref()
                            .is_none_or(|only| only.contains(&full))
                    {
                        planned.push((index, case));
                    }
                }
            }
        }
    }
    Ok(planned)
}

/// Runs the matrix. `progress` sees each case begin and every result as it is made, with the
/// number of cases planned (canaries and teardowns come on top).
///
/// Each context first runs the validation canary ([`Context::validation_canary`]): its result
/// is the case `device/canary-<format>`, [`Outcome::Muted`] where the layer did not report every
/// deliberate call.
///
/// # Errors
/// No Vulkan device or no validation layer. Everything a case can do wrong (a renderer error
/// included) is that case's failure instead.
pub fn run_check(
    scenes: &[CheckScene],
    options: &CheckOptions,
    mut progress: impl FnMut(Event),
) -> Result<CheckReport, CheckError> {
    let start = Instant::now();
    let planned = planned_cases(scenes, options)?;
    let total = planned.len();
    let mut results: Vec<CaseResult> = Vec::new();
    let mut device = String::new();
    let mut driver = DriverInfo::default();
    let progress = std::cell::RefCell::new(&mut progress);
    let started = |name: &str| (progress.borrow_mut())(Event::Started(name));
    let emit = |result: CaseResult, results: &mut Vec<CaseResult>| {
        (progress.borrow_mut())(Event::Finished(&result, total));
        results.push(result);
    };
    let armed: Arc<Mutex<Option<InjectedFault>>> = Arc::default();
    for format in DepthStencilFormat::ALL {
        let mine: Vec<&(usize, Case)> =
            planned.iter().filter(|(_, c)| c.format == format).collect();
        if mine.is_empty() {
            continue;
        }
        let ctx = match Context::new(ContextDesc {
            validation: true,
            best_practices: options.best_practices,
            depth_stencil: Some(format),
            general_path: options.general_path,
            without_depth_bounds: options.general_path,
            spec_minimum_limits: options.spec_minimum_limits,
            ..ContextDesc::default()
        }) {
            Ok(ctx) => ctx,
            Err(histencil_vk::Error::MissingFormat(reason)) => {
                for (scene, case) in mine {
                    let mut r = CaseResult::new(&scenes[*scene].name, case.name(), Some(*case));
                    r.outcome = Outcome::Skipped(reason.clone());
                    emit(r, &mut results);
                }
                continue;
            }
            Err(e) => return Err(e.into()),
        };
        if options.trace_steps {
            let armed = Arc::clone(&armed);
            ctx.observe_steps(Some(Box::new(move |step: &str| {
                {
                    let mut out = std::io::stdout().lock();
                    // No square brackets: a googletest runner reads a bracketed line as a status.
                    let step = step.replace('[', "(").replace(']', ")");
                    let _ = writeln!(out, "step {step}");
                    let _ = out.flush();
                }
                // An injected hang or crash strikes where a GPU's would: while the frame runs.
                if step.starts_with("waiting on the GPU for") {
                    let fault = armed.lock().unwrap_or_else(|e| e.into_inner()).take();
                    if let Some(fault) = fault {
                        strike(&fault);
                    }
                }
            })));
        }
        device = ctx.device_name().to_owned();
        driver = ctx.driver().clone();
        (progress.borrow_mut())(Event::Context {
            device: &device,
            driver: &driver,
        });
        let log = ctx.validation_log();
        let canary_start = Instant::now();
        let canary = ctx.validation_canary();
        let mut r = CaseResult::new(
            "device",
            format!("canary-{}", format.vk_name().to_lowercase()),
            None,
        );
        r.seconds = canary_start.elapsed().as_secs_f64();
        r.note = Some(canary.to_string());
        if !canary.heard() {
            r.outcome = Outcome::Muted(format!(
                "validation-layer-muted: {canary}; a message-id filter, a duplicate-message \
                 limit or disabled checks (VK_LAYER_* variables, vk_layer_settings.txt) are in \
                 force, so no validation verdict of this run can be trusted"
            ));
        }
        emit(r, &mut results);
        // Group by scene and resolution, in plan order: one renderer each.
        let mut groups: Vec<((usize, u32, u32), Vec<Case>)> = Vec::new();
        for (scene, case) in mine {
            let key = (*scene, case.width, case.height);
            match groups.last_mut() {
                Some((k, cases)) if *k == key => cases.push(*case),
                _ => groups.push((key, vec![*case])),
            }
        }
        for ((scene, width, height), cases) in groups {
            let scene = &scenes[scene];
            let needs = SceneNeeds::of(&scene.scene).map_err(|source| CheckError::Layout {
                scene: scene.name.clone(),
                source,
            })?;
            let group = Group {
                armed: &armed,
                ctx: &ctx,
                log: &log,
                scene,
                needs,
                size: (width, height),
                options,
            };
            group.run(&cases, &started, &mut |r| emit(r, &mut results));
        }
        let mark = log.len();
        let teardown_start = Instant::now();
        let teardown = format!("teardown-{}", format.vk_name().to_lowercase());
        for fault in &options.inject {
            // A driver that crashes destroying its device, after every case reported.
            if let InjectedFault::Crash(part) = fault {
                if format!("device/{teardown}").contains(part.as_str()) {
                    std::process::abort();
                }
            }
        }
        drop(ctx);
        let mut r = CaseResult::new("device", teardown, None);
        (r.validation, r.accepted) = messages_since(&log, mark, &options.accepted);
        r.seconds = teardown_start.elapsed().as_secs_f64();
        if let Some(first) = r.validation.first() {
            r.outcome = Outcome::Failed(format!(
                "{} validation message(s) at device destruction (leaked objects), first {}",
                r.validation.len(),
                first.id
            ));
        }
        emit(r, &mut results);
    }
    Ok(CheckReport {
        device,
        driver,
        best_practices: options.best_practices,
        quick: options.quick,
        results,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// One scene at one resolution on one context.
struct Group<'a> {
    ctx: &'a Context,
    log: &'a ValidationLog,
    scene: &'a CheckScene,
    /// What the scene holds that its cases' bounds depend on.
    needs: SceneNeeds,
    size: (u32, u32),
    options: &'a CheckOptions,
    /// A hang or crash `--inject-fault` set for the case running, which the step observer
    /// strikes at the case's first wait on the GPU (with `trace_steps`).
    armed: &'a Arc<Mutex<Option<InjectedFault>>>,
}

/// What every case of a group is judged against.
struct References {
    forward: RgbaImage,
    /// The forward frame without alpha entities (groups with alpha cases).
    background: Option<RgbaImage>,
}

const IMAGES: Readback = Readback {
    ldr: true,
    hdr: false,
    stencil: true,
    brdf_ids: true,
};

impl Group<'_> {
    fn run(&self, cases: &[Case], started: &dyn Fn(&str), emit: &mut dyn FnMut(CaseResult)) {
        let start = Instant::now();
        let mark = self.log.len();
        if let Some(first) = cases.first() {
            started(&self.full_name(first));
        }
        let setup = self.setup(cases);
        let (setup_messages, setup_accepted) =
            messages_since(self.log, mark, &self.options.accepted);
        let (mut renderer, references) = match setup {
            Ok(built) if setup_messages.is_empty() => built,
            outcome => {
                // A device below a limit the lighting needs runs none of the group: skips that
                // name the limit, as a missing depth format's do.
                let skip = match &outcome {
                    Err(histencil_vk::Error::DeviceLimit(why)) => {
                        match device_limit_outcome(self.ctx, why.clone()) {
                            Outcome::Skipped(why) => Some(why),
                            _ => None,
                        }
                    }
                    _ => None,
                };
                let reason = match outcome {
                    Err(e) => format!("setting up the scene failed: {e}"),
                    Ok(_) => format!(
                        "{} validation message(s) while building the renderer and the forward \
                         reference, first {}",
                        setup_messages.len(),
                        setup_messages[0].id
                    ),
                };
                for case in cases {
                    let mut r = self.result(case);
                    r.validation.clone_from(&setup_messages);
                    r.accepted = setup_accepted;
                    r.outcome = match &skip {
                        Some(why) => Outcome::Skipped(why.clone()),
                        None => Outcome::Failed(reason.clone()),
                    };
                    emit(r);
                }
                return;
            }
        };
        let setup_seconds = start.elapsed().as_secs_f64();
        let mut simulated: HashMap<u8, Result<SimulatorInputs, String>> = HashMap::new();
        // Accepted messages of the setup count towards the group's first case.
        let mut setup_accepted = setup_accepted;
        for (i, case) in cases.iter().enumerate() {
            let start = Instant::now();
            if i > 0 {
                started(&self.full_name(case));
            }
            self.inject_runner_fault(case);
            // A fault armed for this case and not struck (it ended before waiting on the GPU)
            // never passes to the next one.
            let disarm = || drop(self.armed.lock().unwrap_or_else(|e| e.into_inner()).take());
            if let Some(why) = self.injected_flake(case) {
                let mut r = self.result(case);
                r.outcome = Outcome::Failed(why);
                disarm();
                emit(r);
                continue;
            }
            let mut r = match case.config {
                None => self.reference(case, &references, setup_seconds),
                Some(config) => self.case(case, config, &mut renderer, &references, &mut simulated),
            };
            if case.config.is_some() {
                r.seconds = start.elapsed().as_secs_f64();
            }
            r.accepted += std::mem::take(&mut setup_accepted);
            disarm();
            emit(r);
        }
    }

    fn full_name(&self, case: &Case) -> String {
        format!("{}/{}", self.scene.name, case.name())
    }

    /// `--inject-fault flaky=`: the first run of a matching case in this `--out` folder fails
    /// (and leaves the marker), every later one runs as usual.
    fn injected_flake(&self, case: &Case) -> Option<String> {
        let name = self.full_name(case);
        let flaky = self
            .options
            .inject
            .iter()
            .any(|f| matches!(f, InjectedFault::Flaky(part) if name.contains(part.as_str())));
        let out = self.options.out.as_ref().filter(|_| flaky)?;
        let marker = out.join(format!("flaky-{}-{}", self.scene.file_name(), case.name()));
        let first = std::fs::create_dir_all(out).is_ok()
            && std::fs::OpenOptions::new()
                .write(true)
                .create_new(true)
                .open(&marker)
                .is_ok();
        first.then(|| format!("injected flake: first run ({} written)", marker.display()))
    }

    /// `--inject-fault hang=` and `crash=`: what a hung or crashing driver does to a runner.
    fn inject_runner_fault(&self, case: &Case) {
        let name = self.full_name(case);
        for fault in &self.options.inject {
            let hits = match fault {
                InjectedFault::Hang(part) | InjectedFault::Crash(part) => {
                    name.contains(part.as_str())
                }
                _ => false,
            };
            // A reference case waits on nothing (its frame was rendered with the group's
            // setup): it strikes at once, as every case did before the step trace.
            if hits && self.options.trace_steps && case.config.is_some() {
                *self.armed.lock().unwrap_or_else(|e| e.into_inner()) = Some(fault.clone());
            } else if hits {
                strike(fault);
            }
        }
    }

    fn result(&self, case: &Case) -> CaseResult {
        CaseResult::new(&self.scene.name, case.name(), Some(*case))
    }

    /// The renderer and the forward frames every case is judged against.
    fn setup(&self, cases: &[Case]) -> histencil_vk::Result<(Renderer<'_>, References)> {
        let (width, height) = self.size;
        let scene = &self.scene.scene;
        let forward = |renderer: &mut Renderer| -> histencil_vk::Result<RgbaImage> {
            let forward = FrameDesc {
                alpha: AlphaMode::Forward,
                ..FrameDesc::new(Shading::Forward, IMAGES)
            };
            let frame = renderer.render_frame(&forward)?;
            Ok(frame.images.ldr.expect("asked for"))
        };
        let desc = histencil_vk::RendererDesc {
            brdfs: self.scene.brdfs,
            ..histencil_vk::RendererDesc::new(width, height)
        };
        let mut renderer = Renderer::with_desc(self.ctx, scene.clone(), &desc)?;
        let reference = forward(&mut renderer)?;
        let background = if cases.iter().any(|c| c.expect == Expect::Alpha) {
            let mut bare = Renderer::with_desc(self.ctx, scene.without_alpha(), &desc)?;
            Some(forward(&mut bare)?)
        } else {
            None
        };
        Ok((
            renderer,
            References {
                forward: reference,
                background,
            },
        ))
    }

    /// The forward reference's own case: it built and rendered under validation (checked by the
    /// caller), and a frame of a lit scene with more than a handful of pixels is not black.
    fn reference(&self, case: &Case, references: &References, seconds: f64) -> CaseResult {
        let mut r = self.result(case);
        r.seconds = seconds;
        let lit = references
            .forward
            .pixels()
            .filter(|p| p.0[..3].iter().any(|c| *c > 0))
            .count();
        let pixels = (case.width * case.height) as usize;
        r.note = Some(format!("{lit} of {pixels} pixels lit"));
        if lit == 0 && pixels >= 1000 && !self.scene.scene.lights.is_empty() {
            r.outcome = Outcome::Failed("the forward reference is black".into());
        }
        r
    }

    fn case(
        &self,
        case: &Case,
        config: Config,
        renderer: &mut Renderer,
        references: &References,
        simulated: &mut HashMap<u8, Result<SimulatorInputs, String>>,
    ) -> CaseResult {
        let mut r = self.result(case);
        let mut technique = config.technique();
        // Deferred runs on the native backend: no hi-stencil, nothing to drop.
        if self.options.inject.contains(&InjectedFault::DropFlushes)
            && config.platform.has_hi_stencil()
        {
            technique = matrix::Config {
                flush: FlushPolicy::Never,
                ..config
            }
            .technique();
        }
        let desc = FrameDesc {
            preserved_pattern: config.pattern,
            alpha: config.alpha,
            ..FrameDesc::new(technique, IMAGES)
        };
        let mark = self.log.len();
        let frame = renderer.render_frame(&desc);
        (r.validation, r.accepted) = messages_since(self.log, mark, &self.options.accepted);
        let frame = match frame {
            Ok(frame) => frame,
            // A device below a limit the configuration needs (a spec-minimum device and the
            // tiled kernels' 7 storage buffers, say) cannot run it: a skip that says why, as a
            // missing depth format is.
            Err(histencil_vk::Error::DeviceLimit(why)) => {
                r.outcome = device_limit_outcome(self.ctx, why);
                return r;
            }
            Err(e) => {
                r.outcome = Outcome::Failed(format!("rendering failed: {e}"));
                return r;
            }
        };
        let images = frame.images;
        let (ldr, stencil, ids) = (
            images.ldr.expect("asked for"),
            images.stencil.expect("asked for"),
            images.brdf_ids.expect("asked for"),
        );
        let alpha_bound = match config.alpha {
            AlphaMode::Lightmap | AlphaMode::Directional => ALPHA_LIGHTMAP,
            _ => ALPHA_PROBE,
        };
        let alpha = (case.expect == Expect::Alpha)
            .then(|| references.background.as_ref().map(|b| (b, alpha_bound)))
            .flatten();
        let exact = match case.expect {
            // Read only by the coverage test: where no alpha entity is, no layer is blended.
            Expect::Alpha => SceneNeeds {
                alpha_layers: 0,
                ..self.needs
            }
            .exact_tolerance(config.lighting),
            _ => self.needs.exact_tolerance(config.lighting),
        };
        let verdict = judge::judge_image(case.expect, &ldr, &references.forward, exact, alpha);

        // The simulator's stencil pins down where 360-like zeroing may happen; it needs the
        // GPU's own f32 depths, and preserved bits to zero.
        let needs_simulator = matches!(case.expect, Expect::Wrong(_))
            || (config.platform == Platform::X360 && config.pattern != 0);
        let inputs = if !needs_simulator {
            Err(String::new())
        } else if case.format != DepthStencilFormat::D32S8 {
            Err("the simulator reads f32 depth: D32_SFLOAT_S8_UINT only".to_owned())
        } else {
            simulated
                .entry(config.pattern)
                .or_insert_with(|| capture(renderer, config.pattern))
                .as_ref()
                .map_err(Clone::clone)
        };
        let inputs = inputs.as_ref().copied();
        let brdfs = renderer.brdfs();
        let slots: Vec<Option<u32>> = ids
            .iter()
            .map(|id| id.and_then(|id| brdfs.iter().position(|b| *b == id).map(|s| s as u32)))
            .collect();
        let predicted = match inputs {
            // What the configuration should do, whatever was rendered.
            Ok(inputs) if case.expect == Expect::Exact => {
                Some(predict(renderer, inputs, config.technique()).map(|(_, stencil)| stencil))
            }
            _ => None,
        };
        let predicted = match predicted.transpose() {
            Ok(p) => p,
            Err(e) => {
                r.outcome = Outcome::Failed(format!("simulating the case failed: {e}"));
                return r;
            }
        };
        r.stencil_problems = judge::judge_stencil(
            stencil.as_raw(),
            &StencilInputs {
                layout: *renderer.stencil_layout(),
                slots: &slots,
                pattern: config.pattern,
                platform: config.platform,
                width: case.width,
            },
            predicted.as_deref(),
        );
        let judged_ok = verdict.passed() && r.stencil_problems.is_empty();
        r.outcome = if let Some(first) = r.validation.first() {
            Outcome::Failed(format!(
                "{} validation message(s), first {}",
                r.validation.len(),
                if first.id.is_empty() {
                    first.text.as_str()
                } else {
                    first.id.as_str()
                }
            ))
        } else {
            match case.expect {
                Expect::Wrong(wrong) => {
                    match known_wrong(renderer, inputs, config, wrong, judged_ok, &verdict) {
                        Ok((outcome, note)) => {
                            r.note = Some(note);
                            outcome
                        }
                        Err(e) => Outcome::Failed(format!("simulating the case failed: {e}")),
                    }
                }
                _ if judged_ok => Outcome::Passed,
                _ => {
                    let mut why = Vec::new();
                    if !verdict.passed() {
                        why.push(format!("image: {}", verdict.describe()));
                    }
                    why.extend(r.stencil_problems.iter().map(|p| format!("stencil: {p}")));
                    Outcome::Failed(why.join("; "))
                }
            }
        };
        r.image = Some(verdict);
        if matches!(r.outcome, Outcome::Failed(_)) {
            if let Some(out) = &self.options.out {
                r.artifacts = write_artifacts(
                    &out.join(self.scene.file_name()),
                    &case.name(),
                    &ldr,
                    &references.forward,
                    &stencil,
                    &r.validation,
                );
            }
        }
        r
    }
}

/// The simulator's inputs with the preserved `pattern` in the G-buffer stencil, captured for
/// the stencil technique (the footprints are per light, the plan is swapped per case), or why
/// the device cannot give them.
fn capture(renderer: &mut Renderer, pattern: u8) -> Result<SimulatorInputs, String> {
    let technique = Technique::Stencil {
        backend: Platform::X360.backend(),
        flush: FlushPolicy::Auto,
    };
    let desc = FrameDesc {
        preserved_pattern: pattern,
        ..technique.into()
    };
    renderer
        .simulator_inputs(desc)
        .map_err(|e| format!("capturing the simulator's inputs failed: {e}"))
}

/// The simulator run on `inputs` with `technique`'s plan.
fn predict(
    renderer: &Renderer,
    inputs: &SimulatorInputs,
    technique: Technique,
) -> histencil_vk::Result<(histencil_model::SimResult, Vec<u8>)> {
    let plan = renderer.plan(technique)?;
    let (result, target) = inputs.predict_on(&plan, technique.backend());
    Ok((result, target.stencil))
}

/// A known-wrong case's outcome: where the simulator predicts it shades fewer fragments than
/// its corrected configuration, it must fail the image or stencil judgement (passing means the
/// check has gone blind); where it predicts no difference it is skipped as not applicable.
fn known_wrong(
    renderer: &Renderer,
    inputs: Result<&SimulatorInputs, &String>,
    config: Config,
    wrong: KnownWrong,
    judged_ok: bool,
    verdict: &ImageVerdict,
) -> histencil_vk::Result<(Outcome, String)> {
    let inputs = match inputs {
        Ok(inputs) => inputs,
        Err(why) => {
            let why = format!("cannot tell whether the failure must show here: {why}");
            return Ok((Outcome::Skipped(why), String::new()));
        }
    };
    let fixed = matrix::corrected(config);
    let (broken, _) = predict(renderer, inputs, config.technique())?;
    let (correct, _) = predict(renderer, inputs, fixed.technique())?;
    let (lost, shaded) = (
        correct
            .stats
            .fragments_shaded
            .saturating_sub(broken.stats.fragments_shaded),
        correct.stats.fragments_shaded,
    );
    let note = format!(
        "{}: the simulator predicts {lost} of {shaded} fragments lost",
        wrong.describe()
    );
    Ok(if lost == 0 {
        (
            Outcome::Skipped(format!(
                "not applicable here: the simulator predicts that {} loses no fragment",
                wrong.describe()
            )),
            note,
        )
    } else if judged_ok {
        (
            Outcome::Failed(format!(
                "the check has gone blind: a known-wrong configuration passed ({note}; {})",
                verdict.describe()
            )),
            note,
        )
    } else {
        (Outcome::Passed, format!("failed as expected: {note}"))
    })
}

/// Writes a failing case's `-actual.png`, `-expected.png`, `-difference.png`, `-stencil.png`
/// (the raw stencil byte per pixel) and `-validation.txt`; returns what was written. A file that
/// cannot be written is left out (the failure itself is what matters).
fn write_artifacts(
    dir: &Path,
    name: &str,
    actual: &RgbaImage,
    expected: &RgbaImage,
    stencil: &GrayImage,
    validation: &[ValidationMessage],
) -> Vec<PathBuf> {
    let path = |suffix: &str| dir.join(format!("{name}-{suffix}"));
    let mut written = Vec::new();
    let mut keep = |p: PathBuf, ok: bool| {
        if ok {
            written.push(p);
        }
    };
    let p = path("actual.png");
    keep(p.clone(), histencil_vk::save_png(actual, &p).is_ok());
    let p = path("expected.png");
    keep(p.clone(), histencil_vk::save_png(expected, &p).is_ok());
    let p = path("difference.png");
    let difference = histencil_vk::difference_image(actual, expected, 32);
    keep(p.clone(), histencil_vk::save_png(&difference, &p).is_ok());
    let p = path("stencil.png");
    keep(p.clone(), histencil_vk::save_png(stencil, &p).is_ok());
    if !validation.is_empty() {
        let text: String = validation.iter().map(|m| format!("{m}\n")).collect();
        let p = path("validation.txt");
        keep(
            p.clone(),
            histencil_vk::write_atomically(&p, text.as_bytes()).is_ok(),
        );
    }
    written
}
