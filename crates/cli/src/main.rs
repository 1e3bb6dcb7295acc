//! `histencil`: render embedded scenes with the deferred renderer or the forward reference.

use anyhow::{bail, Context as _, Result};
use clap::{Parser, Subcommand};
use histencil_alpha::ParameterKind;
use histencil_scene::{with_default_lights, DefaultLights};
use histencil_vk::Platform;
use histencil_vk::{
    AlphaMode, Context, ContextDesc, FlushPolicy, FrameDesc, ImageKind, MixedTiles, Readback,
    Renderer, RendererDesc, Shading, Technique, TileSide, TileStats,
};
use image::DynamicImage;
use std::path::PathBuf;
use std::process::ExitCode;

mod brdf_eval;
mod brdf_report;
mod brdfs;
mod check;
mod gtest;
mod lab;
mod suite;

#[derive(Parser)]
#[command(
    name = "histencil",
    version,
    about = "Multi-BRDF deferred rendering with hierarchical stencil"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Render a scene without lights unlit (black) instead of lighting it with the default rig
    /// (a key directional light from the camera's upper left and a dim fill from the right).
    #[arg(long, global = true)]
    no_default_lights: bool,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to PNG (and optionally EXR and a stencil dump).
    Render(RenderArgs),
    /// A short tour of the talk: the stencil technique on each platform (the consoles, native and
    /// AMD's two) next to branching, tiled, depth-id and forward, with times, errors against
    /// forward, hi-stencil statistics and the engine's bits, and a contact sheet.
    Demo(lab::DemoArgs),
    /// List the embedded scenes, then any glTF files given: name, BRDFs in use, lights, alpha
    /// entities, description (which says when the default rig lights a scene).
    Scenes(ScenesArgs),
    /// The talk's table on this device: lighting time with 1, 2, 3 BRDFs per technique and
    /// platform backend, the per-BRDF breakdown, a light-size sweep, each next to its error
    /// against forward; writes report.md, report.json and PNG plots.
    Compare(lab::CompareArgs),
    /// The talk's questions asked of today's GPUs: per platform (the consoles, NVIDIA's ZCull
    /// stencil criterion assumed to cull as the PS3's, AMD's GFX9-11 pretests and GFX12 AND/OR
    /// tiles as modelled from AMD's driver sources, native Vulkan) whether the engine's bits
    /// break culling, what flush or reset it needs, how many BRDFs it culls hierarchically, and
    /// the simulator's tiles and fragments on frames captured here; and what the native plan's
    /// draws cost an Adreno's low-resolution Z.
    TodaysGpus(lab::TodaysGpusArgs),
    /// A scene at scale (default: the generated `town`): load time and device memory, then
    /// G-buffer, lighting and frame time of stencil (native, PS3-like) and branching next to
    /// forward, each with its error; writes a markdown report.
    Scale(lab::ScaleArgs),
    /// Speed against error for one setting (lut-res, lightmap-res, slices, tile-size): CSV, JSON and a
    /// Pareto plot.
    Sweep(lab::SweepArgs),
    /// Measure this device's per-pass overhead, branch tax and shade cost for the adaptive
    /// technique (`--costs`).
    Calibrate(lab::CalibrateArgs),
    /// The validation-CI matrix: every technique, backend, flush policy, preserved pattern,
    /// depth format and resolution a scene needs, under the validation layer, judged against
    /// forward, run in worker processes with baselines, shards and timeouts; results.csv,
    /// failures.csv, JUnit XML and JSON. Exit 0 nothing fails, 1 a case fails, 2 usage error,
    /// 3 no device or layer, 4 no case selected, 5 stopped by a signal, 6 runner error.
    Check(Box<check::CheckArgs>),
    /// Evaluate BRDF cases from a CSV file (id,brdf,params,N,T,V,L) into `id,value`.
    BrdfEval(BrdfEvalArgs),
    /// Print the error of the BRDF look-up tables against resolution and the error the G-buffer
    /// encodings add (markdown), both against the f64 reference.
    BrdfReport(BrdfReportArgs),
    /// Compile histencil's shaders for an engine's BRDFs and hooks into one file, at the
    /// engine's build: the C API reads it (`histencil_shaders_load`), so the engine's build
    /// needs no cargo and its users no glslc. Prints how many modules it holds.
    Shaders(ShadersArgs),
}

#[derive(clap::Args)]
struct ShadersArgs {
    /// The engine's BRDF folder (`brdfs.toml` and its GLSL); histencil's eight without it.
    #[arg(long)]
    brdfs: Option<PathBuf>,
    /// The engine's hook folder (`surface_decode.glsl`, `light_visibility.glsl`); histencil's
    /// G-buffer and no shadows without it.
    #[arg(long)]
    hooks: Option<PathBuf>,
    /// The file to write (whole or not at all).
    #[arg(long)]
    out: PathBuf,
    /// Also write what the engine's own shaders include to evaluate the set (`brdf_set/*.glsl`
    /// and the engine's GLSL under `engine/`) into this folder: put it before histencil's
    /// installed includes on glslc's path, and a forward reference that includes `light.glsl`
    /// shades the engine's BRDFs as histencil does.
    #[arg(long)]
    includes: Option<PathBuf>,
}

#[derive(clap::Args)]
struct ScenesArgs {
    /// `.gltf` / `.glb` files to list after the embedded scenes.
    files: Vec<String>,
}

#[derive(clap::Args)]
struct BrdfReportArgs {
    /// Table resolutions (grid points per axis), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "8,16,32,64")]
    lut_res: Vec<u32>,
    /// Size of the fixed direction sets.
    #[arg(long, default_value_t = 4096)]
    directions: usize,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum Device {
    /// The f64 reference.
    Cpu,
    /// The GLSL spelling, in a compute shader.
    Gpu,
}

#[derive(clap::Args)]
struct BrdfEvalArgs {
    #[arg(long)]
    cases: PathBuf,
    #[arg(long)]
    out: PathBuf,
    #[arg(long, value_enum, default_value = "cpu")]
    device: Device,
    /// With `--device gpu`: run under the validation layer; any message fails the run.
    #[arg(long)]
    validate: bool,
}

#[derive(clap::Args)]
struct RenderArgs {
    /// An embedded scene (see `histencil scenes`) or a `.gltf` / `.glb` file.
    #[arg(long, default_value = "default")]
    scene: String,
    /// How lights are applied: `stencil` (the talk's one pass per BRDF, masked by stencil),
    /// `branching` (one uber shader), `adaptive` (stencil or branching per light, by the cost
    /// model fitted to the talk's figures), `lut` (one pass per light, every BRDF from its
    /// material's look-up table), `deferred` (branching on the native backend), `forward` (the
    /// reference).
    #[arg(long, value_enum, default_value = "deferred")]
    technique: TechniqueArg,
    /// Platform behaviour of the stencil plan.
    #[arg(long, value_enum, default_value = "native")]
    backend: PlatformArg,
    /// When hi-stencil is flushed.
    #[arg(long, value_enum, default_value = "auto")]
    flush: FlushArg,
    /// With `--technique lut`: grid points per axis of every BRDF table (2..=512; a 3D table
    /// takes 12 * N^3 bytes, 16 * N^3 with a white part).
    #[arg(long, default_value_t = histencil_vk::DEFAULT_LUT_RESOLUTION)]
    lut_resolution: u32,
    /// How translucent objects and particles are lit: `lightmap` (the talk's per-entity GPU
    /// lightmaps), `directional` (lightmaps of incident light with a light-direction map, each
    /// fragment evaluating its own BRDF), `forward` (every light per pixel: the reference),
    /// `probe` (every light at one point per entity: the classic CPU light probe).
    #[arg(long, value_enum, default_value = "lightmap")]
    alpha: AlphaArg,
    /// Lightmap side in texels for every alpha entity (2..=4094: one region and its guard band
    /// fill the largest atlas, 4096; and at most what the device's maxStorageBufferRange holds
    /// an object's probes for, 32 bytes a texel: 2048 at the spec's guaranteed minimum, the
    /// refusal names the device's); default: from screen coverage (8 to 128 texels).
    #[arg(long)]
    lightmap_resolution: Option<u32>,
    /// Also render the alpha entities forward per pixel, and the scene without them, and print
    /// the written frame's error against the forward alpha over the pixels they cover.
    #[arg(long)]
    alpha_error: bool,
    /// Costs from `histencil calibrate` for `--technique adaptive` (default: fitted to the talk's
    /// figures).
    #[arg(long)]
    costs: Option<PathBuf>,
    /// The tiled techniques' tile side in pixels (default: the device's, 8 on a CPU rasteriser
    /// such as lavapipe, else 16).
    #[arg(long, value_enum)]
    tile_size: Option<TileSizeArg>,
    /// Time every lighting step and print the talk's pass groups (setup, mask and shade per BRDF,
    /// cleanup) and the most expensive lights. Timestamps between draws cost time of their own.
    #[arg(long)]
    timings: bool,
    /// Count the written frame's hi-stencil statistics (tiles tested and culled, fragments
    /// shaded, flushes) and check them against the CPU simulator run on the GPU's own inputs.
    #[arg(long)]
    stats: bool,
    /// The engine's bits written into the preserved stencil bits by the G-buffer pass, e.g. 0xA0.
    #[arg(long, value_parser = parse_byte, default_value = "0")]
    preserved_pattern: u8,
    #[arg(long, default_value_t = 1280)]
    width: u32,
    #[arg(long, default_value_t = 720)]
    height: u32,
    /// The tonemapped frame, in the format its extension names: `.png`, or `.jpg` / `.jpeg`
    /// (lossy, no alpha). Any other extension is refused before rendering.
    #[arg(long, default_value = "out/render.png")]
    out: PathBuf,
    /// The linear HDR frame, as OpenEXR (the name must end in `.exr`).
    #[arg(long)]
    hdr: Option<PathBuf>,
    /// The raw stencil byte of every pixel after lighting, as an 8-bit grey PNG (`.png` only:
    /// JPEG would change the values).
    #[arg(long)]
    dump_stencil: Option<PathBuf>,
    /// Frames to time after the written one; the median is printed.
    #[arg(long, default_value_t = 5)]
    frames: usize,
    /// Enable the Khronos validation layer (with synchronisation validation); any message makes
    /// the run fail.
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
    /// Act as a device that offers only the Vulkan spec's minimum of every limit histencil
    /// checks: what needs more is refused naming the limit (the driver line lists them).
    #[arg(long)]
    spec_minimum_limits: bool,
    #[command(flatten)]
    brdfs: brdfs::BrdfsArg,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum TechniqueArg {
    Stencil,
    Branching,
    Adaptive,
    Lut,
    /// Tile classification and one indirect dispatch per BRDF (today's engines); each BRDF's
    /// kernel shades its own pixels of a tile of several BRDFs. Tiles of --tile-size pixels.
    Tiled,
    /// As tiled, with a tile of several BRDFs shaded once by one kernel branching per pixel.
    TiledMixedBranching,
    /// Bevy's: each pixel's BRDF as a 16-bit depth id, one full-screen pass per BRDF with
    /// depth compare EQUAL, each pixel adding the lights of its --tile-size tile. The tiled
    /// image, bit for bit.
    DepthId,
    Deferred,
    Forward,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum TileSizeArg {
    #[value(name = "8")]
    Eight,
    #[value(name = "16")]
    Sixteen,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum AlphaArg {
    Lightmap,
    Forward,
    Probe,
    Directional,
}

impl AlphaArg {
    fn mode(self) -> AlphaMode {
        match self {
            AlphaArg::Lightmap => AlphaMode::Lightmap,
            AlphaArg::Forward => AlphaMode::Forward,
            AlphaArg::Probe => AlphaMode::Probe,
            AlphaArg::Directional => AlphaMode::Directional,
        }
    }
}

/// A platform on the command line: histencil's own [`Platform`], named and described by it.
#[derive(Clone, Copy)]
struct PlatformArg(Platform);

impl clap::ValueEnum for PlatformArg {
    fn value_variants<'a>() -> &'a [Self] {
        static ALL: std::sync::OnceLock<[PlatformArg; 8]> = std::sync::OnceLock::new();
        ALL.get_or_init(|| Platform::ALL.map(PlatformArg))
    }

    fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
        Some(clap::builder::PossibleValue::new(self.0.name()).help(self.0.about()))
    }
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum FlushArg {
    Auto,
    Always,
    Never,
}

impl RenderArgs {
    fn tile_side(&self, ctx: &Context) -> TileSide {
        match self.tile_size {
            Some(TileSizeArg::Eight) => TileSide::Eight,
            Some(TileSizeArg::Sixteen) => TileSide::Sixteen,
            None => TileSide::for_context(ctx),
        }
    }

    fn shading(&self, ctx: &Context) -> Shading {
        let backend = self.backend.0.backend();
        let flush = match self.flush {
            FlushArg::Auto => FlushPolicy::Auto,
            FlushArg::Always => FlushPolicy::Always,
            FlushArg::Never => FlushPolicy::Never,
        };
        match self.technique {
            TechniqueArg::Stencil => Technique::Stencil { backend, flush }.into(),
            TechniqueArg::Branching => Technique::Branching { backend, flush }.into(),
            TechniqueArg::Adaptive => Technique::Adaptive { backend, flush }.into(),
            TechniqueArg::Lut => Technique::Lut { backend, flush }.into(),
            TechniqueArg::Tiled => Technique::Tiled {
                mixed: MixedTiles::PerBrdf,
                side: self.tile_side(ctx),
            }
            .into(),
            TechniqueArg::TiledMixedBranching => Technique::Tiled {
                mixed: MixedTiles::Branching,
                side: self.tile_side(ctx),
            }
            .into(),
            TechniqueArg::DepthId => Technique::DepthId {
                side: self.tile_side(ctx),
            }
            .into(),
            TechniqueArg::Deferred => Technique::DEFERRED.into(),
            TechniqueArg::Forward => Shading::Forward,
        }
    }
}

/// The lighting breakdown as lines: each pass group, then the five most expensive lights.
fn describe_breakdown(lighting: &histencil_vk::LightingBreakdown) -> String {
    let mut out = String::from("lighting by pass group (median):\n");
    for (group, ms) in &lighting.groups {
        out += &format!("  {group:24} {ms:8.3} ms\n");
    }
    let mut lights = lighting.per_light.clone();
    lights.sort_by(|a, b| b.1.total_cmp(&a.1));
    out += &format!(
        "most expensive of {} lights drawn:\n",
        lighting.per_light.len()
    );
    for (light, ms) in lights.iter().take(5) {
        out += &format!("  light {light:<18} {ms:8.3} ms\n");
    }
    out
}

/// A byte as decimal or `0x` hexadecimal.
fn parse_byte(text: &str) -> Result<u8, String> {
    let parsed = match text.strip_prefix("0x").or_else(|| text.strip_prefix("0X")) {
        Some(hex) => u8::from_str_radix(hex, 16),
        None => text.parse(),
    };
    parsed.map_err(|_| format!("`{text}` is not a byte (0-255 or 0x00-0xFF)"))
}

/// The scene `--scene` names. What a glTF file holds but histencil does not render is said on
/// stderr, once per feature. A scene without lights gets the default rig unless `lights` is
/// `Off`, announced on stderr; left unlit it gets a warning, since its black image is correct
/// but looks like a failure.
pub(crate) fn load_scene_arg(spec: &str, lights: DefaultLights) -> Result<histencil_scene::Scene> {
    load_scene_in(spec, lights, &histencil_brdf::BrdfSet::default())
}

/// [`load_scene_arg`] where a glTF file's extras may name one of `set`'s own BRDFs.
pub(crate) fn load_scene_in(
    spec: &str,
    lights: DefaultLights,
    set: &histencil_brdf::BrdfSet,
) -> Result<histencil_scene::Scene> {
    let imported = histencil_scene::load_scene_in(spec, set)?;
    for note in &imported.unrendered {
        eprintln!("histencil: scene `{spec}`: not rendered: {note}");
    }
    let (scene, rigged) = with_default_lights(imported.scene, lights);
    if rigged {
        eprintln!(
            "histencil: scene `{spec}` has no lights: lit by the default rig (a key directional \
             light from the camera's upper left, a dim fill from the right); \
             --no-default-lights renders it unlit"
        );
    } else if scene.lights.is_empty() {
        eprintln!(
            "histencil: warning: scene `{spec}` has no lights, so every technique renders it \
             black (glTF lights come from KHR_lights_punctual)"
        );
    }
    Ok(scene)
}

fn render(args: &RenderArgs, lights: DefaultLights) -> Result<()> {
    let modules = args.brdfs.modules()?;
    let scene = brdfs::load_scene(&args.scene, lights, modules)?;
    let (costs, brdf_weights) = lab::read_costs_arg(args.costs.as_deref(), &modules.set)?;
    let outputs = [
        (Some(&args.out), ImageKind::Colour),
        (args.hdr.as_ref(), ImageKind::Hdr),
        (args.dump_stencil.as_ref(), ImageKind::Exact),
    ];
    for (path, kind) in outputs {
        if let Some(path) = path {
            histencil_vk::check_image_output(path, kind)?;
        }
    }
    let device = DeviceArgs {
        validate: args.validate,
        no_depth_bounds: args.no_depth_bounds,
        general_path: args.general_path,
        spec_minimum_limits: args.spec_minimum_limits,
    };
    on_device(device, |ctx| {
        let shading = args.shading(ctx);
        let desc = RendererDesc {
            lut_resolution: args.lut_resolution,
            lightmap_side: args.lightmap_resolution,
            cost_model: costs,
            brdf_weights,
            brdfs: modules,
            ..RendererDesc::new(args.width, args.height)
        };
        let mut renderer = Renderer::with_desc(ctx, scene, &desc)?;
        let readback = Readback {
            ldr: true,
            hdr: args.hdr.is_some(),
            stencil: args.dump_stencil.is_some(),
            brdf_ids: false,
        };
        let desc = FrameDesc {
            preserved_pattern: args.preserved_pattern,
            alpha: args.alpha.mode(),
            ..FrameDesc::new(shading, readback)
        };
        if args.stats {
            print_stats(&mut renderer, &desc)?;
        }
        let images = renderer.render_frame(&desc)?.images;
        if args.alpha_error {
            let ldr = images.ldr.as_ref().expect("requested");
            print_alpha_error(ctx, &mut renderer, &desc, ldr)?;
        }
        let ldr = images.ldr.clone().expect("requested");
        let written = [
            (
                Some(&args.out),
                Some(DynamicImage::from(ldr)),
                ImageKind::Colour,
            ),
            (
                args.hdr.as_ref(),
                images.hdr.clone().map(DynamicImage::from),
                ImageKind::Hdr,
            ),
            (
                args.dump_stencil.as_ref(),
                images.stencil.clone().map(DynamicImage::from),
                ImageKind::Exact,
            ),
        ];
        for (path, image, kind) in written {
            if let (Some(path), Some(image)) = (path, image) {
                histencil_vk::save_image_as(&image, path, kind)?;
                println!("wrote {}", path.display());
            }
        }
        let timed = FrameDesc {
            pass_timing: args.timings,
            ..desc
        };
        let timings = renderer.measure(timed, args.frames)?;
        if let Shading::Deferred(technique @ Technique::Adaptive { .. }) = shading {
            if let resolved @ Technique::Tiled { .. } = renderer.resolve(technique)? {
                println!("adaptive: the costs predict the whole frame cheaper tiled: {resolved:?}");
            }
        }
        let passes: Vec<String> = timings
            .passes
            .iter()
            .map(|(n, ms)| format!("{n} {ms:.2} ms"))
            .collect();
        println!(
            "frame time {:.2} ms ({}; median of {} frames at {}x{}, {:?}, device: {})",
            timings.total_ms(),
            passes.join(", "),
            args.frames.max(1),
            args.width,
            args.height,
            shading,
            ctx.device_name()
        );
        if let (Some(bookkeeping), Some(lighting)) = (
            timings.bookkeeping_ms,
            timings.pass_ms(histencil_vk::passes::names::LIGHTING),
        ) {
            // What the emulator does a GPU would not: the consoles' tile bookkeeping, or AMD's
            // tiles evaluated before each draw that tests stencil.
            let work = match shading.technique().map(Technique::backend) {
                Some(b) if b.has_gpu_hierarchy() => "resets, splits, tile evaluations",
                _ => "resets, splits, touch draws, tile updates, flush copies",
            };
            println!(
                "emulated hi-stencil (medians): the platform's technique {:.2} ms + the \
                 emulator's bookkeeping {bookkeeping:.2} ms ({work}) = lighting {lighting:.2} ms",
                timings.technique_ms(&[histencil_vk::passes::names::LIGHTING])
            );
        }
        if let Some(lighting) = &timings.lighting {
            print!("{}", describe_breakdown(lighting));
        }
        if let Some(lightmaps) = &timings.lightmaps {
            let names = renderer.scene().alpha_entity_names();
            println!(
                "alpha lightmaps (median): clear {:.3} ms",
                lightmaps.clear_ms
            );
            for &(entity, ms) in &lightmaps.per_entity {
                let name = names.get(entity as usize).copied().unwrap_or("?");
                println!("  entity {name:24} {ms:8.3} ms");
            }
        }
        Ok(())
    })
}

/// Prints `ldr`'s error against the same frame with forward-lit alpha entities, over the pixels
/// the entities cover (where that frame differs from one without them).
fn print_alpha_error(
    ctx: &Context,
    renderer: &mut Renderer,
    desc: &FrameDesc,
    ldr: &image::RgbaImage,
) -> Result<()> {
    let mode = desc.alpha;
    let reference = histencil_lab::AlphaReference::render(ctx, renderer, desc.shading)?;
    let e = reference.error(ldr);
    let whole = histencil_lab::image_error(ldr, &reference.forward);
    println!(
        "alpha error against forward ({mode:?}): mean {:.3}/255, max {}/255 over {} pixels; \
         whole frame mean {:.3}/255",
        e.mean, e.max, e.pixels, whole.mean
    );
    Ok(())
}

/// Prints each alpha entity's lightmap parameters and the estimate behind them, then the GPU's
/// hi-stencil statistics of one frame next to the simulator's prediction.
fn print_stats(renderer: &mut Renderer, desc: &FrameDesc) -> Result<()> {
    let parameters = renderer.lightmap_parameters()?;
    let names = renderer.scene().alpha_entity_names();
    for (p, name) in parameters.iter().zip(names) {
        let forced = |yes: bool| if yes { " (forced)" } else { "" };
        let estimated = format!(
            "estimated error mean {:.2}/255, max {:.0}/255",
            p.estimate.mean, p.estimate.max
        );
        let what = match p.kind {
            ParameterKind::Surface => format!(
                "mesh lightmap {0}x{0} texels{1} (coverage allows {2}); {estimated}",
                p.side,
                forced(p.forced_side),
                p.coverage_side
            ),
            ParameterKind::Slices => format!(
                "{} slice(s){} of {2}x{2} texels{3} (coverage allows {4}); {estimated}",
                p.slices,
                forced(p.forced_slices),
                p.side,
                forced(p.forced_side),
                p.coverage_side
            ),
            ParameterKind::Dust => "one texel per mote".to_owned(),
            ParameterKind::Ribbon => "texels along it from its length on screen".to_owned(),
        };
        println!("alpha entity {name}: {what}");
    }
    if desc.shading == Shading::Forward {
        bail!("--stats needs a deferred technique: the forward reference has no lighting passes");
    }
    let inputs = renderer.simulator_inputs(*desc)?;
    let depth_id = matches!(desc.shading, Shading::Deferred(Technique::DepthId { .. }));
    let (predicted, depth_bounds_rejected) = match desc.shading.technique() {
        _ if depth_id => (inputs.predict_depth_id(), 0),
        Some(technique) => {
            let sim = inputs.predict_on(&inputs.plan, technique.backend()).0;
            (sim.stats, sim.depth_bounds_rejected)
        }
        None => {
            let sim = inputs.predict().0;
            (sim.stats, sim.depth_bounds_rejected)
        }
    };
    let counted = FrameDesc {
        tile_stats: true,
        readback: Readback::NONE,
        ..*desc
    };
    let frame = renderer.render_frame(&counted)?;
    let Some(gpu) = frame.tile_stats else {
        bail!("--stats: the tiled technique has no stencil or depth tests to count");
    };
    let agrees = |gpu: TileStats| {
        if gpu == predicted {
            "agrees".to_owned()
        } else {
            format!("predicts {predicted:?}")
        }
    };
    if depth_id {
        // llvmpipe has no hierarchical depth: the rejections are the model's, on the GPU's ids.
        println!(
            "depth-id, hierarchical depth modelled on the GPU's id image ({0}x{0}-pixel tiles): \
             {1} tile tests, {2} rejected, {3} fragments shaded; the model from the G-buffer {4}",
            inputs.tile_size,
            gpu.tiles_tested,
            gpu.tiles_culled,
            gpu.fragments_shaded,
            agrees(gpu)
        );
        return Ok(());
    }
    println!(
        "hi-stencil ({}x{}-pixel tiles): {} tiles tested, {} culled, {} fragments shaded, {} flushes; \
         simulator {}",
        inputs.tile_size,
        inputs.tile_size,
        gpu.tiles_tested,
        gpu.tiles_culled,
        gpu.fragments_shaded,
        gpu.flushes,
        agrees(gpu)
    );
    // The test rejects fragments before any shader runs, so the GPU cannot count them: the
    // simulator does, on the frame's own depth and the plan's ranges.
    if inputs.plan.uses_depth_bounds() {
        println!(
            "depth bounds test: {depth_bounds_rejected} fragments of shade passes outside their \
             light's depth range rejected before stencil and shading (simulator, on the frame's \
             own depth)"
        );
    } else {
        let why = if renderer.context().depth_bounds() {
            "no light of this plan has a range that cuts"
        } else {
            "not used: the device has no depthBounds, or --no-depth-bounds"
        };
        println!("depth bounds test: {why}");
    }
    Ok(())
}

/// How a command opens its device.
#[derive(Clone, Copy, Debug, Default)]
pub struct DeviceArgs {
    /// Run under the validation layer; any message fails the run.
    pub validate: bool,
    /// Leave the device's depth bounds test unused where it has one.
    pub no_depth_bounds: bool,
    /// Apply no driver quirk.
    pub general_path: bool,
    /// Cap the device's limits at the spec's minimums.
    pub spec_minimum_limits: bool,
}

impl From<bool> for DeviceArgs {
    /// Validation as asked, the depth bounds test where the device has it.
    fn from(validate: bool) -> Self {
        Self {
            validate,
            no_depth_bounds: false,
            general_path: false,
            spec_minimum_limits: false,
        }
    }
}

/// Runs `body` on a device, then drops the context and fails on any validation message (with
/// `validate`): leaked objects are only reported when the device goes away.
fn on_device<T>(
    device: impl Into<DeviceArgs>,
    body: impl FnOnce(&Context) -> Result<T>,
) -> Result<T> {
    let device = device.into();
    let ctx = Context::new(ContextDesc {
        validation: device.validate,
        without_depth_bounds: device.no_depth_bounds,
        general_path: device.general_path,
        spec_minimum_limits: device.spec_minimum_limits,
        ..ContextDesc::default()
    })?;
    let log = ctx.validation_log();
    let value = body(&ctx)?;
    drop(ctx);
    let problems = log.problems();
    if !problems.is_empty() {
        for p in &problems {
            eprintln!("{p}");
        }
        bail!("{} validation message(s)", problems.len());
    }
    Ok(value)
}

fn shaders(args: &ShadersArgs) -> Result<()> {
    histencil_vk::check_output_file(&args.out)?;
    let modules =
        histencil_vk::write_shader_file(args.brdfs.as_deref(), args.hooks.as_deref(), &args.out)
            .map_err(anyhow::Error::msg)?;
    if let Some(folder) = &args.includes {
        let set = match &args.brdfs {
            Some(dir) => histencil_brdf::BrdfSet::load(dir)?,
            None => histencil_brdf::BrdfSet::default(),
        };
        histencil_build::stage_brdf_set(&set, folder).map_err(|e| anyhow::anyhow!("{e}"))?;
    }
    println!("{}: {modules} modules", args.out.display());
    Ok(())
}

fn brdf_eval(args: &BrdfEvalArgs) -> Result<()> {
    histencil_vk::check_output_file(&args.out)?;
    let input = std::fs::File::open(&args.cases)
        .with_context(|| format!("cannot read {}", args.cases.display()))?;
    let (rows, errors) = histencil_brdf::eval_csv::parse_cases(input)
        .with_context(|| format!("in {}", args.cases.display()))?;
    for e in &errors {
        eprintln!("histencil: {}: {e}", args.cases.display());
    }
    let (values, as_f32) = match args.device {
        Device::Cpu => (histencil_brdf::eval_csv::evaluate_cpu(&rows), false),
        Device::Gpu => (
            on_device(args.validate, |ctx| brdf_eval::evaluate_gpu(ctx, &rows))?,
            true,
        ),
    };
    let mut out = Vec::new();
    histencil_brdf::eval_csv::write_results(&mut out, &rows, &values, as_f32)?;
    histencil_vk::write_atomically(&args.out, &out)?;
    println!("wrote {} ({} rows)", args.out.display(), rows.len());
    if !errors.is_empty() {
        bail!("{} row(s) could not be evaluated", errors.len());
    }
    Ok(())
}

fn brdf_report(args: &BrdfReportArgs) -> Result<()> {
    if args.directions == 0 {
        bail!("--directions must be at least 1");
    }
    println!("## LUT error against resolution\n");
    println!(
        "Absolute error of `f_r cos` over {} fixed directions (f64 reference).\n",
        args.directions
    );
    println!(
        "{}",
        brdf_report::lut_table(&args.lut_res, args.directions)?
    );
    println!("## G-buffer encoding error\n");
    println!("{}", brdf_report::encoding_table(args.directions));
    Ok(())
}

fn scenes(args: &ScenesArgs, lights: DefaultLights) -> Result<()> {
    let row = |name: &str, scene: &histencil_scene::Scene, description: &str| {
        println!(
            "{name}\t{}\t{}\t{}\t{description}",
            scene.brdfs_in_use().len(),
            scene.lights.len(),
            scene.alpha_entity_count()
        );
    };
    for (name, description) in histencil_scene::EMBEDDED {
        let scene = histencil_scene::embedded(name).expect("embedded scenes exist");
        row(name, &scene, description);
    }
    for file in &args.files {
        let loaded = histencil_scene::load_scene(file)?;
        let (scene, rigged) = with_default_lights(loaded, lights);
        let description = match (rigged, scene.lights.is_empty()) {
            (true, _) => format!(
                "{}; no lights of its own: lit by the default rig",
                scene.description
            ),
            (false, true) => format!("{}; no lights: renders black", scene.description),
            (false, false) => scene.description.clone(),
        };
        row(&scene.name, &scene, &description);
    }
    Ok(())
}

fn main() -> ExitCode {
    // A closed stdout (`histencil check --list | head`) ends the process quietly, as it does
    // any Unix filter, instead of making every print a panic: Rust ignores SIGPIPE by default.
    // SAFETY: restoring a signal's default disposition before any thread starts.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    // Started as a googletest binary (a deqp-runner suite entry's `bin`): `check`'s gtest face,
    // its settings from the environment.
    let mut args: Vec<std::ffi::OsString> = std::env::args_os().collect();
    if suite::is_gtest_binary(&args) {
        args = match suite::check_args(&args, &|name| std::env::var(name).ok()) {
            Ok(args) => args,
            Err(e) => {
                eprintln!("histencil: {e}");
                return ExitCode::from(2);
            }
        };
    }
    let cli = match Cli::try_parse_from(args) {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => {
            // --help / --version
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
        Err(e) => {
            // One line: clap's first line names the problem; its "try --help" tail is noise.
            let text = e.to_string();
            eprintln!(
                "histencil: {}",
                text.lines()
                    .next()
                    .unwrap_or("bad arguments")
                    .trim_start_matches("error: ")
            );
            return ExitCode::from(2);
        }
    };
    let lights = if cli.no_default_lights {
        DefaultLights::Off
    } else {
        DefaultLights::IfNone
    };
    let result = match &cli.command {
        Command::Check(args) => return check::check(args, lights),
        Command::Render(args) => render(args, lights),
        Command::Scenes(args) => scenes(args, lights),
        Command::Compare(args) => lab::compare(args, lights),
        Command::Demo(args) => lab::demo(args, lights),
        Command::Scale(args) => lab::scale(args, lights),
        Command::TodaysGpus(args) => lab::todays_gpus(args, lights),
        Command::Sweep(args) => lab::sweep(args, lights),
        Command::Calibrate(args) => lab::calibrate(args),
        Command::BrdfEval(args) => brdf_eval(args),
        Command::BrdfReport(args) => brdf_report(args),
        Command::Shaders(args) => shaders(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("histencil: {e:#}");
            ExitCode::FAILURE
        }
    }
}
