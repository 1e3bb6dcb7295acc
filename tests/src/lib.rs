//! Helpers for histencil's end-to-end GPU tests: a validated context, rendering, and image
//! comparison that writes `-actual`, `-expected` and `-difference` PNGs when a check fails.

pub mod engine;
pub mod gltf_builder;

use histencil_scene::Scene;
use histencil_vk::{Context, ContextDesc, Frame, Readback, Renderer, Shading};
use image::RgbaImage;
use std::path::PathBuf;
use std::sync::{Mutex, MutexGuard, PoisonError};

/// Where failing comparisons write their images.
pub fn output_dir() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/test-output");
    std::fs::create_dir_all(&dir).expect("create target/test-output");
    dir
}

/// This test process's turn to hold a Vulkan instance with the validation layer: one at a time.
///
/// The test harness runs a file's tests on parallel threads, each with its own instance. The
/// validation layer of Debian 12 (1.3.239) now and then crashed in that case, inside the layer
/// (a SIGSEGV in `libVkLayer_khronos_validation.so`, once through a null function pointer)
/// with no message before, in tests that pass alone every time: the layer's own global state
/// is not safe against instances made and destroyed concurrently (as in Vulkan-Profiles #414).
/// lavapipe already spreads one frame over every core, so taking turns costs little. A test
/// that panics gives its turn back (a poisoned lock is still a turn).
pub fn instance_turn() -> MutexGuard<'static, ()> {
    static TURN: Mutex<()> = Mutex::new(());
    TURN.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Runs `body` with a validated context, then drops the context (the validation layer reports
/// leaked objects at device destruction) and fails on any validation message. Holds
/// [`instance_turn`] throughout.
pub fn with_validated_context<T>(body: impl FnOnce(&Context) -> T) -> T {
    let _turn = instance_turn();
    let ctx = Context::new(ContextDesc::validated()).expect("a Vulkan 1.3 device with validation");
    let log = ctx.validation_log();
    let result = body(&ctx);
    drop(ctx);
    log.assert_clean();
    result
}

/// Renders one frame of `scene`.
pub fn render(
    ctx: &Context,
    scene: &Scene,
    shading: impl Into<Shading>,
    size: u32,
    readback: Readback,
) -> Frame {
    let mut renderer = Renderer::new(ctx, scene.clone(), size, size).expect("renderer");
    renderer.render(shading, readback).expect("frame")
}

/// Per-channel absolute differences of two 8-bit images.
#[derive(Debug, Clone, Copy)]
pub struct ImageDiff {
    pub max: u8,
    pub mean: f64,
    pub pixels_differing: usize,
}

/// The whole frame's differences, as `histencil check` judges them
/// ([`histencil_check::judge::image_error`]): a pixel differs when any channel does.
pub fn diff(a: &RgbaImage, b: &RgbaImage) -> ImageDiff {
    let e = histencil_check::judge::image_error(a, b, 0, |_| true);
    ImageDiff {
        max: e.max,
        mean: e.mean,
        pixels_differing: e.over,
    }
}

/// Asserts `actual` is within `tolerance` (per channel, 8-bit steps) of `expected`; on failure
/// writes `name-actual.png`, `name-expected.png` and `name-difference.png` (differences x 32).
pub fn assert_close(
    name: &str,
    actual: &RgbaImage,
    expected: &RgbaImage,
    tolerance: u8,
) -> ImageDiff {
    let d = diff(actual, expected);
    if d.max > tolerance {
        let dir = output_dir();
        actual.save(dir.join(format!("{name}-actual.png"))).unwrap();
        expected
            .save(dir.join(format!("{name}-expected.png")))
            .unwrap();
        histencil_vk::difference_image(actual, expected, 32)
            .save(dir.join(format!("{name}-difference.png")))
            .unwrap();
        panic!(
            "{name}: max difference {} > {tolerance} (mean {:.4}, {} pixels differ); images in {}",
            d.max,
            d.mean,
            d.pixels_differing,
            dir.display()
        );
    }
    d
}

/// Fraction of pixels with any non-zero colour channel: guards against "both images black".
pub fn lit_fraction(image: &RgbaImage) -> f64 {
    let lit = image
        .pixels()
        .filter(|p| p.0[..3].iter().any(|c| *c > 0))
        .count();
    lit as f64 / (image.width() * image.height()) as f64
}

/// Every device limit the work done on `ctx` needed lies within [`histencil_vk::NEEDS`] (or
/// the spec's minimum for a limit the table leaves out), so the table every driver line reports
/// cannot fall behind the code; where `reached`, each need the table puts above the spec's
/// minimum was met exactly by this work (the table is no larger than the code needs).
pub fn assert_needs_hold(ctx: &Context, reached: &[histencil_vk::Limit]) {
    for limit in histencil_vk::Limit::ALL {
        let most = histencil_vk::NEEDS
            .iter()
            .find(|n| n.limit == limit)
            .map_or(limit.spec_minimum(), |n| n.most);
        let used = ctx.limit_used(limit);
        println!("{}: used {used}, need at most {most}", limit.vk_name());
        assert!(
            used <= most,
            "{} used {used}, more than histencil::NEEDS says ({most})",
            limit.vk_name()
        );
        if reached.contains(&limit) {
            assert_eq!(
                used,
                most,
                "{}: the table's need not reached",
                limit.vk_name()
            );
        }
    }
}
