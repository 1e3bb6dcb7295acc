//! The GPU hi-stencil emulation reproduces the talk's failures, and its fixes repair them:
//! - 360-like hardware compares all 8 stencil bits in hi-stencil, so engine data in the preserved
//!   bits makes tiles fail that should pass: lights go missing unless the bits are zeroed (or
//!   saved, zeroed and restored);
//! - hi-stencil written by a mask pass is stale until flushed: without flushes, shade passes
//!   reject tiles by another pass's state, with any backend.
//!
//! "Exact" below means within 1/255 of the forward reference, like every deferred technique.

use histencil_model::DepthConvention;
use histencil_tests::{assert_close, diff, lit_fraction, with_validated_context};
use histencil_vk::{
    Backend, FlushPolicy, FrameDesc, Readback, Renderer, Shading, Technique, TileSide,
};
use image::RgbaImage;

const SIZE: u32 = 160;
const TOLERANCE: u8 = 1;
const PATTERN: u8 = 0xA0;

fn x360(zero_preserved: bool, save_restore: bool) -> Backend {
    Backend::X360 {
        zero_preserved,
        save_restore,
    }
}

/// The LDR frame of `shading` with `pattern` in the engine's stencil bits.
fn image(renderer: &mut Renderer, shading: impl Into<Shading>, pattern: u8) -> RgbaImage {
    let desc = FrameDesc {
        preserved_pattern: pattern,
        ..FrameDesc::new(shading, Readback::ALL)
    };
    renderer
        .render_frame(&desc)
        .expect("frame")
        .images
        .ldr
        .unwrap()
}

fn stencil(backend: Backend, flush: FlushPolicy) -> Technique {
    Technique::Stencil { backend, flush }
}

/// Asserts the failure is visible: a large part of the lit image is wrong.
fn assert_broken(label: &str, actual: &RgbaImage, forward: &RgbaImage) {
    let d = diff(actual, forward);
    let broken = d.pixels_differing as f64 / (SIZE * SIZE) as f64;
    println!("{label}: max {} / 255, {broken:.3} of pixels differ", d.max);
    assert!(
        d.max > 32 && broken > 0.05,
        "{label}: the failure did not appear (max {}, {broken:.3} of pixels)",
        d.max
    );
}

#[test]
fn x360_without_zeroing_loses_lights_on_preserved_bits_and_the_fixes_restore_them() {
    for name in ["default", "brdfs-6", "near-far"] {
        let scene = histencil_scene::embedded(name).unwrap();
        with_validated_context(|ctx| {
            let mut renderer = Renderer::new(ctx, scene.clone(), SIZE, SIZE).expect("renderer");
            let forward = image(&mut renderer, Shading::Forward, 0);
            assert!(
                lit_fraction(&forward) > 0.5,
                "{name}: reference mostly black"
            );
            let auto = FlushPolicy::Auto;
            // Without engine data the missing read mask is harmless.
            let clean = image(&mut renderer, stencil(x360(false, false), auto), 0);
            assert_close(
                &format!("hi-{name}-no-pattern"),
                &clean,
                &forward,
                TOLERANCE,
            );

            let broken = image(&mut renderer, stencil(x360(false, false), auto), PATTERN);
            assert_broken(&format!("{name} x360 without zeroing"), &broken, &forward);
            for (label, backend) in [
                ("zeroing", x360(true, false)),
                ("save-restore", x360(true, true)),
                ("ps3", Backend::Ps3),
            ] {
                let fixed = image(&mut renderer, stencil(backend, auto), PATTERN);
                assert_close(&format!("hi-{name}-{label}"), &fixed, &forward, TOLERANCE);
            }
        });
    }
}

/// The 360's failure asked of AMD's GFX12 tiles: with the tests' read mask they cull around
/// the engine's bits and stay exact; compared on every bit (the rule broken on purpose), the
/// engine's bits reject whole tiles of light. Pretests mask the BRDF field: exact either way.
#[test]
fn amd_hierarchies_keep_engine_bits_out_of_culling_and_breaking_the_read_mask_loses_lights() {
    for name in ["default", "brdfs-6"] {
        let scene = histencil_scene::embedded(name).unwrap();
        with_validated_context(|ctx| {
            let mut renderer = Renderer::new(ctx, scene.clone(), SIZE, SIZE).expect("renderer");
            let forward = image(&mut renderer, Shading::Forward, 0);
            let auto = FlushPolicy::Auto;
            let unmasked = stencil(Backend::AmdAndOrUnmasked, auto);
            let clean = image(&mut renderer, unmasked, 0);
            assert_close(
                &format!("amd-{name}-no-pattern"),
                &clean,
                &forward,
                TOLERANCE,
            );
            let broken = image(&mut renderer, unmasked, PATTERN);
            assert_broken(&format!("{name} amd-andor unmasked"), &broken, &forward);
            for (label, backend) in [
                ("andor", Backend::AmdAndOr),
                ("pretest", Backend::AmdPretest),
            ] {
                let fixed = image(&mut renderer, stencil(backend, auto), PATTERN);
                assert_close(&format!("amd-{name}-{label}"), &fixed, &forward, TOLERANCE);
            }
        });
    }
}

#[test]
fn without_flushes_stale_tiles_are_culled_and_auto_flushing_is_exact() {
    for name in ["default", "brdfs-3"] {
        let scene = histencil_scene::embedded(name).unwrap();
        with_validated_context(|ctx| {
            let mut renderer = Renderer::new(ctx, scene.clone(), SIZE, SIZE).expect("renderer");
            let forward = image(&mut renderer, Shading::Forward, 0);
            for backend in [Backend::Ps3, x360(true, false)] {
                let label = format!("{name} {backend:?}");
                let never = image(&mut renderer, stencil(backend, FlushPolicy::Never), 0);
                assert_broken(&format!("{label} flush never"), &never, &forward);
                // Timed frames test tiles in a shader without the statistics' count: the same
                // failure, pixel for pixel, as the counting shader's.
                let counted = FrameDesc {
                    tile_stats: true,
                    ..FrameDesc::new(stencil(backend, FlushPolicy::Never), Readback::ALL)
                };
                let counted = renderer.render_frame(&counted).expect("frame");
                assert_eq!(
                    diff(&counted.images.ldr.unwrap(), &never).pixels_differing,
                    0,
                    "{label}: the counting shader culls other tiles"
                );
                let auto = image(&mut renderer, stencil(backend, FlushPolicy::Auto), 0);
                assert_close(&format!("hi-{name}-auto"), &auto, &forward, TOLERANCE);
                // Extra flushes change nothing once every test sees its own mask.
                let always = image(&mut renderer, stencil(backend, FlushPolicy::Always), 0);
                assert_eq!(
                    diff(&always, &auto).pixels_differing,
                    0,
                    "{label}: flush always differs from auto"
                );
            }
        });
    }
}

/// The GPU frame does what the CPU simulator predicts from the GPU's own inputs (G-buffer depth
/// and stencil, rasterised light footprints, the plan): the same stencil after lighting, so the
/// 360-like backend zeroes preserved bits exactly where the model says, and the same tile
/// statistics, so tiles are marked, flushed and culled exactly as the model says. A forward
/// frame has nothing to simulate and is refused.
#[test]
fn gpu_stencil_and_tile_statistics_equal_the_simulators() {
    let auto = FlushPolicy::Auto;
    let cases = [
        ("ps3", stencil(Backend::Ps3, auto)),
        ("x360", stencil(x360(true, false), auto)),
        ("x360-no-zeroing", stencil(x360(false, false), auto)),
        ("x360-save-restore", stencil(x360(true, true), auto)),
        ("ps3-flush-never", stencil(Backend::Ps3, FlushPolicy::Never)),
        (
            "x360-flush-always",
            stencil(x360(true, false), FlushPolicy::Always),
        ),
        (
            "branching-ps3",
            Technique::Branching {
                backend: Backend::Ps3,
                flush: auto,
            },
        ),
        (
            "lut-ps3",
            Technique::Lut {
                backend: Backend::Ps3,
                flush: auto,
            },
        ),
        // AMD's own hierarchies, no plan step driving them: the GPU's tiles evaluated before
        // each stencil-testing draw, the model's run beside the native plan (`run_with`).
        ("amd-pretest", stencil(Backend::AmdPretest, auto)),
        ("amd-andor", stencil(Backend::AmdAndOr, auto)),
        // The rule broken on purpose: the engine's bits reject whole tiles of light, on the
        // GPU as in the model.
        (
            "amd-andor-unmasked",
            stencil(Backend::AmdAndOrUnmasked, auto),
        ),
        (
            "branching-amd-andor",
            Technique::Branching {
                backend: Backend::AmdAndOr,
                flush: auto,
            },
        ),
    ];
    for name in ["default", "brdfs-3", "near-far", "inside"] {
        let scene = histencil_scene::embedded(name).unwrap();
        with_validated_context(|ctx| {
            let mut renderer = Renderer::new(ctx, scene.clone(), SIZE, SIZE).expect("renderer");
            // The forward reference has no stencil plan to simulate: refused, not guessed.
            assert!(matches!(
                renderer.simulator_inputs(Shading::Forward),
                Err(histencil_vk::Error::Unsupported(_))
            ));
            for (label, technique) in cases {
                let desc = FrameDesc {
                    preserved_pattern: PATTERN,
                    tile_stats: true,
                    ..FrameDesc::new(technique, Readback::ALL)
                };
                assert_simulated(&mut renderer, &desc, &format!("{name} {label}"));
            }
        });
    }
}

/// Reversed Z and an infinite far plane are simulated as the GPU renders them: the capture
/// projects depths and light volumes in the frame's convention.
#[test]
fn reversed_and_infinite_far_frames_equal_the_simulators() {
    let auto = FlushPolicy::Auto;
    let cases = [
        ("ps3", stencil(Backend::Ps3, auto)),
        ("x360", stencil(x360(true, false), auto)),
        ("ps3-flush-never", stencil(Backend::Ps3, FlushPolicy::Never)),
        (
            "x360-flush-always",
            stencil(x360(true, false), FlushPolicy::Always),
        ),
        ("amd-pretest", stencil(Backend::AmdPretest, auto)),
        ("amd-andor", stencil(Backend::AmdAndOr, auto)),
    ];
    let conventions = [
        ("reversed", DepthConvention::Reversed, false),
        ("reversed-infinite", DepthConvention::Reversed, true),
        ("infinite", DepthConvention::Standard, true),
    ];
    for name in ["default", "near-far", "inside"] {
        let scene = histencil_scene::embedded(name).unwrap();
        with_validated_context(|ctx| {
            let mut renderer = Renderer::new(ctx, scene.clone(), SIZE, SIZE).expect("renderer");
            for (label, technique) in cases {
                for (depth_label, depth, infinite_far) in conventions {
                    let desc = FrameDesc {
                        preserved_pattern: PATTERN,
                        tile_stats: true,
                        depth,
                        infinite_far,
                        ..FrameDesc::new(technique, Readback::ALL)
                    };
                    let what = format!("{name} {label} {depth_label}");
                    assert_simulated(&mut renderer, &desc, &what);
                }
            }
        });
    }
}

/// Asserts that the GPU frame `desc` leaves the stencil and the tile statistics that the
/// simulator predicts from the GPU's own inputs (on the AMD platforms, with the model of the
/// GPU's hierarchy).
fn assert_simulated(renderer: &mut Renderer, desc: &FrameDesc, what: &str) {
    let inputs = renderer.simulator_inputs(*desc).expect("inputs");
    let backend = desc.shading.technique().expect("deferred").backend();
    let (sim, predicted) = inputs.predict_on(&inputs.plan, backend);
    let frame = renderer.render_frame(desc).expect("frame");
    let stats = frame.tile_stats.expect("statistics were asked for");
    println!("{what}: {stats:?}");
    assert!(stats.tiles_tested > 0, "{what}: nothing tested");
    assert_eq!(stats, sim.stats, "{what}: tile statistics");
    let stencil = frame.images.stencil.unwrap().into_raw();
    let wrong = stencil
        .iter()
        .zip(&predicted.stencil)
        .filter(|(a, b)| a != b)
        .count();
    assert_eq!(wrong, 0, "{what}: stencil differs at {wrong} pixels");
}

/// The depth-id technique's ids, as the GPU writes them into its id image, are the ones the
/// model makes from the G-buffer's stencil and depth, in every depth convention (the id image
/// has a convention of its own, the same in all): the hierarchical-depth statistics of the two
/// agree, and every surface pixel is shaded once.
#[test]
fn depth_id_statistics_from_the_gpus_ids_equal_the_models() {
    let conventions = [
        (DepthConvention::Standard, false),
        (DepthConvention::Reversed, false),
        (DepthConvention::Reversed, true),
        (DepthConvention::Standard, true),
    ];
    for name in ["default", "brdfs-3", "inside"] {
        let scene = histencil_scene::embedded(name).unwrap();
        with_validated_context(|ctx| {
            let mut renderer = Renderer::new(ctx, scene.clone(), SIZE, SIZE).expect("renderer");
            for (depth, infinite_far) in conventions {
                let what = format!("{name} {depth:?} infinite far {infinite_far}");
                let desc = FrameDesc {
                    tile_stats: true,
                    depth,
                    infinite_far,
                    ..FrameDesc::new(
                        Technique::DepthId {
                            side: TileSide::Eight,
                        },
                        Readback::NONE,
                    )
                };
                let inputs = renderer.simulator_inputs(desc).expect("inputs");
                let stats = renderer.render_frame(&desc).expect("frame").tile_stats;
                let stats = stats.expect("statistics were asked for");
                println!("{what}: {stats:?}");
                assert_eq!(stats, inputs.predict_depth_id(), "{what}");
                let far = inputs.plan.depth.far();
                let surface = inputs.target.depth.iter().filter(|d| **d != far).count();
                assert_eq!(
                    stats.fragments_shaded, surface as u64,
                    "{what}: shaded once"
                );
                assert!(stats.tiles_culled > 0, "{what}: nothing rejected");
            }
        });
    }
}
