//! The demo: a short tour of the talk on one scene. The talk's stencil technique on the 360-like
//! backend (zeroing, with engine bits in the preserved stencil bits), on the PS3-like backend and
//! on plain Vulkan, next to branching and the forward reference: each with its lighting time, its
//! error against forward, its hi-stencil statistics and what happened to the engine's bits; and a
//! contact sheet that shows the frame, its difference from forward, the stencil byte, and the
//! talk's two failures next to their fixes.

use crate::contact_sheet::{contact_sheet, stencil_colours};
use crate::image_error::{image_error, ImageError};
use crate::measure::{frame, time_technique, Timing};
use crate::Result;
use histencil_scene::Scene;
use histencil_vk::{
    Backend, Context, FlushPolicy, FrameDesc, MixedTiles, Readback, Renderer, Shading, Technique,
    TileSide, TileStats,
};
use image::{RgbImage, RgbaImage};
use std::fmt::Write as _;

/// The engine's bits in the preserved stencil bits, as in the talk's 360 story.
pub const DEMO_PATTERN: u8 = 0xA0;

/// What the demo renders.
pub struct DemoSettings {
    pub scene: Scene,
    pub width: u32,
    pub height: u32,
    /// Timed frames per row (after one warm-up frame).
    pub frames: usize,
    /// The BRDFs the scene is shaded with: histencil's own, or an engine's set
    /// (`demo --brdfs`), which every object's BRDF must belong to.
    pub brdfs: &'static histencil_vk::BrdfModules,
}

/// One row of the demo's table.
pub struct DemoRow {
    pub label: &'static str,
    pub shading: Shading,
    /// Lighting (or, for forward, the forward pass) over the timed frames: the platform's
    /// technique, without the hi-stencil emulator's bookkeeping.
    pub time: Timing,
    /// The emulator's bookkeeping in the same frames, on the emulated backends only.
    pub bookkeeping: Option<Timing>,
    /// `None` for the reference itself.
    pub error: Option<ImageError>,
    /// Emulated hi-stencil backends only.
    pub tiles: Option<TileStats>,
    /// Surface pixels whose engine bits survived lighting, and those zeroed.
    pub preserved: Option<(usize, usize)>,
}

pub struct DemoReport {
    pub device: String,
    /// The driver as Vulkan names it (name, build, conformance) and the validation layer: two
    /// builds of one driver share a device name.
    pub driver: String,
    pub width: u32,
    pub height: u32,
    pub frames: usize,
    pub rows: Vec<DemoRow>,
    /// The contact sheet (`out/demo.png`).
    pub sheet: RgbImage,
    /// The forward reference, full size.
    pub forward: RgbaImage,
    /// The talk's failures beside their fixes, full size, as the sheet's second row shows them.
    pub failures: Vec<FailureAndFix>,
}

/// One of the talk's failures and the frame its fix gives, each with its caption on the sheet.
/// The failure must be visible (it differs from the fix) and the fix must match forward: the
/// demo is only a tour of the talk while both hold, so a test holds them.
pub struct FailureAndFix {
    pub failure: (String, RgbaImage),
    pub fix: (String, RgbaImage),
}

/// A frame's stencil after lighting and which of its pixels hold a surface.
type StencilView = (image::GrayImage, Vec<bool>);

const X360: Backend = Backend::X360 {
    zero_preserved: true,
    save_restore: false,
};
const X360_NO_ZEROING: Backend = Backend::X360 {
    zero_preserved: false,
    save_restore: false,
};

fn stencil(backend: Backend, flush: FlushPolicy) -> Technique {
    Technique::Stencil { backend, flush }
}

/// The rows, in the table's order; tiled and depth-id with tiles of `side`.
fn configurations(side: TileSide) -> [(&'static str, Shading); 10] {
    let auto = FlushPolicy::Auto;
    [
        ("forward (reference)", Shading::Forward),
        ("branching, native", Technique::DEFERRED.into()),
        ("stencil, native", stencil(Backend::Native, auto).into()),
        ("stencil, PS3-like", stencil(Backend::Ps3, auto).into()),
        ("stencil, 360-like (zeroing)", stencil(X360, auto).into()),
        (
            "stencil, 360-like (save/restore)",
            stencil(
                Backend::X360 {
                    zero_preserved: true,
                    save_restore: true,
                },
                auto,
            )
            .into(),
        ),
        (
            "stencil, AMD GFX9-11 pretests (modelled)",
            stencil(Backend::AmdPretest, auto).into(),
        ),
        (
            "stencil, AMD GFX12 AND/OR (modelled)",
            stencil(Backend::AmdAndOr, auto).into(),
        ),
        (
            "tiled, native",
            Technique::Tiled {
                mixed: MixedTiles::PerBrdf,
                side,
            }
            .into(),
        ),
        (
            "depth-id (Bevy's), native",
            Technique::DepthId { side }.into(),
        ),
    ]
}

/// Runs the tour. `step` is told what is being rendered.
pub fn run_demo(
    ctx: &Context,
    settings: DemoSettings,
    step: &mut dyn FnMut(&str),
) -> Result<DemoReport> {
    let desc = histencil_vk::RendererDesc {
        brdfs: settings.brdfs,
        ..histencil_vk::RendererDesc::new(settings.width, settings.height)
    };
    let mut renderer = Renderer::with_desc(ctx, settings.scene, &desc)?;
    let layout = *renderer.stencil_layout();
    let preserved_mask = layout.preserved_mask();
    let all = Readback {
        hdr: false,
        ..Readback::ALL
    };
    let mut frames: Vec<(RgbaImage, Option<StencilView>)> = Vec::new();
    let mut rows = Vec::new();
    for (label, shading) in configurations(TileSide::for_context(ctx)) {
        step(label);
        let passes = shading.lighting_passes();
        let desc = FrameDesc {
            preserved_pattern: DEMO_PATTERN,
            ..FrameDesc::new(shading, all)
        };
        let (time, bookkeeping) = time_technique(&mut renderer, desc, passes, settings.frames)?;
        let images = renderer.render_frame(&desc)?.images;
        let ldr = images.ldr.expect("asked for");
        let error = frames
            .first()
            .map(|(forward, _)| image_error(&ldr, forward));
        let preserved = images
            .stencil
            .as_ref()
            .zip(images.brdf_ids.as_ref())
            .map(|(s, ids)| {
                let surfaces = s.as_raw().iter().zip(ids).filter(|(_, id)| id.is_some());
                let kept = surfaces
                    .clone()
                    .filter(|(v, _)| *v & preserved_mask == DEMO_PATTERN & preserved_mask)
                    .count();
                (kept, surfaces.count() - kept)
            });
        // Hierarchical stencil emulated (consoles, AMD), or the depth ids' hierarchical depth
        // modelled on the GPU's ids.
        let counts = match shading {
            Shading::Deferred(Technique::Stencil { backend, .. }) => backend != Backend::Native,
            Shading::Deferred(Technique::DepthId { .. }) => true,
            _ => false,
        };
        let tiles = if counts {
            let counted = FrameDesc {
                tile_stats: true,
                readback: Readback::NONE,
                ..desc
            };
            renderer.render_frame(&counted)?.tile_stats
        } else {
            None
        };
        rows.push(DemoRow {
            label,
            shading,
            time,
            bookkeeping,
            error,
            tiles,
            preserved: preserved.filter(|_| shading != Shading::Forward),
        });
        let surfaces = images
            .brdf_ids
            .map(|ids| ids.iter().map(Option::is_some).collect::<Vec<_>>());
        frames.push((ldr, images.stencil.zip(surfaces)));
    }
    step("the talk's failures");
    // The failures are rendered with the engine's bits that the table's rows carry: without
    // them the 360-like backend has nothing in the preserved bits to mis-test, and its failure
    // frame equals its fix.
    let failure = |renderer: &mut Renderer, technique: Technique| {
        let desc = FrameDesc {
            preserved_pattern: DEMO_PATTERN,
            ..FrameDesc::from(Shading::from(technique))
        };
        frame(renderer, desc)
    };
    let no_zeroing = failure(&mut renderer, stencil(X360_NO_ZEROING, FlushPolicy::Auto))?;
    let never = failure(&mut renderer, stencil(Backend::Ps3, FlushPolicy::Never))?;
    let unmasked = failure(
        &mut renderer,
        stencil(Backend::AmdAndOrUnmasked, FlushPolicy::Auto),
    )?;
    // Rows by technique, not by their place in the table.
    let row = |shading: Shading| {
        rows.iter()
            .position(|r| r.shading == shading)
            .expect("every technique shown is a row")
    };
    let (x360_row, ps3_row, andor_row) = (
        row(stencil(X360, FlushPolicy::Auto).into()),
        row(stencil(Backend::Ps3, FlushPolicy::Auto).into()),
        row(stencil(Backend::AmdAndOr, FlushPolicy::Auto).into()),
    );
    let forward = frames[row(Shading::Forward)].0.clone();
    let x360 = frames[x360_row].0.clone();
    let (ps3, ps3_stencil) = frames[ps3_row].clone();
    let (ps3_stencil, surfaces) = ps3_stencil.expect("asked for");
    let max_difference = rows[x360_row].error.map_or(0.0, |e| e.max);
    let failures = vec![
        FailureAndFix {
            failure: ("FAIL 360-like without zeroing".to_owned(), no_zeroing),
            fix: ("fix: zeroing as lights draw".to_owned(), x360.clone()),
        },
        FailureAndFix {
            failure: ("FAIL PS3-like, no hi-stencil flush".to_owned(), never),
            fix: ("fix: flush before each test".to_owned(), ps3),
        },
        FailureAndFix {
            failure: ("FAIL AMD AND/OR without read mask".to_owned(), unmasked),
            fix: (
                "fix: the test's read mask".to_owned(),
                frames[andor_row].0.clone(),
            ),
        },
    ];
    let mut tiles = vec![
        ("forward (reference)".to_owned(), forward.clone()),
        ("stencil technique, 360-like".to_owned(), x360.clone()),
        (
            format!("difference x16 (max {max_difference}/255)"),
            histencil_vk::difference_image(&x360, &forward, 16),
        ),
        (
            "PS3-like stencil: G BRDF id, B engine bits, R culling".to_owned(),
            stencil_colours(&ps3_stencil, &layout, &surfaces),
        ),
    ];
    for pair in &failures {
        tiles.push(pair.failure.clone());
        tiles.push(pair.fix.clone());
    }
    Ok(DemoReport {
        device: ctx.device_name().to_owned(),
        driver: ctx.driver().to_string(),
        width: settings.width,
        height: settings.height,
        frames: settings.frames,
        rows,
        sheet: contact_sheet(&halved(tiles), 4),
        forward,
        failures,
    })
}

/// The tiles at half size, so that four frames fit a screen side by side.
fn halved(tiles: Vec<(String, RgbaImage)>) -> Vec<(String, RgbaImage)> {
    tiles
        .into_iter()
        .map(|(caption, t)| {
            let (w, h) = ((t.width() / 2).max(1), (t.height() / 2).max(1));
            let small = image::imageops::resize(&t, w, h, image::imageops::FilterType::Triangle);
            (caption, small)
        })
        .collect()
}

impl DemoReport {
    /// The table, in plain text.
    pub fn table(&self) -> String {
        let mut out = format!(
            "{}x{}, device {} ({}); lighting time: median (spread) of {} frames, on the emulated \
             backends the platform's technique and then the emulator's bookkeeping (hi-stencil \
             resets, splits, touch draws, tile updates, flush copies; on AMD's, each tested \
             draw's tile evaluation); error against forward: 8-bit max / mean, mean FLIP; the \
             AMD rows are modelled from AMD's driver sources, not measured on AMD hardware, and \
             depth-id's culled tiles are a GPU's hierarchical depth modelled on the ids this \
             device wrote; engine bits 0x{DEMO_PATTERN:02X}\n\n",
            self.width, self.height, self.device, self.driver, self.frames
        );
        let _ = writeln!(
            out,
            "{:<42} {:>18} {:>18} {:>22} {:>28} {:>22}",
            "technique, backend",
            "lighting ms",
            "emulator ms",
            "error (max/mean/FLIP)",
            "hierarchy: tiles culled",
            "engine bits kept"
        );
        for row in &self.rows {
            let ms = |t: &Timing| format!("{:.1} ({:.1})", t.median_ms, t.spread_ms());
            let time = ms(&row.time);
            let bookkeeping = row.bookkeeping.as_ref().map_or("-".to_owned(), ms);
            let error = row.error.map_or("reference".to_owned(), |e| {
                format!("{:.0} / {:.3} / {:.4}", e.max, e.mean, e.flip)
            });
            let tiles = row.tiles.map_or("-".to_owned(), |t| {
                format!(
                    "{} of {}, {} flushes",
                    t.tiles_culled, t.tiles_tested, t.flushes
                )
            });
            let preserved = row.preserved.map_or("-".to_owned(), |(kept, zeroed)| {
                if zeroed == 0 {
                    format!("all {kept} px")
                } else {
                    format!("{kept} px, {zeroed} zeroed")
                }
            });
            let _ = writeln!(
                out,
                "{:<42} {:>18} {:>18} {:>22} {:>28} {:>22}",
                row.label, time, bookkeeping, error, tiles, preserved
            );
        }
        out
    }
}
