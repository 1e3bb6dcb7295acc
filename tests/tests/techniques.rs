//! Every lighting technique (the talk's, and the tiled one of today's engines) matches the
//! forward reference within 1/255 per channel, on scenes
//! with 1, 2, 3 and 6 BRDFs in use and on the camera-inside and near/far-crossing scenes; the
//! stencil technique runs under every platform backend. The LUT technique, approximate, is held
//! to its own stated tolerance on the same scenes.
//!
//! Stencil and branching are bit-identical: each pixel is shaded by exactly one draw per light
//! in both (the stencil test passes a pixel for its own BRDF's pass only), the shader of that
//! draw computes the same expression (the per-BRDF pipeline's model is a specialisation constant,
//! the branching one reads the same id from the G-buffer), and lights are blended in the same
//! order. So the sums round identically. The test asserts it.

use histencil_brdf::BrdfId;
use histencil_tests::{
    assert_close, assert_needs_hold, diff, lit_fraction, with_validated_context,
};
use histencil_vk::{
    Backend, CostModel, DepthIdCosts, FlushPolicy, Limit, MixedTiles, Readback, Renderer,
    RendererDesc, Shading, Technique, TileSide, TiledCosts,
};

const SIZE: u32 = 160;
const TOLERANCE: u8 = 1;
/// The LUT technique at `DEFAULT_LUT_RESOLUTION` (32), per channel: `tests/tests/lut.rs` holds
/// it to its tables' predicted error per pixel; in these scenes that is at most 23/255 where a
/// point light's highlight on Blinn-Phong 256 falls between grid points (measured 2026-11), and
/// a mean below 0.03/255.
const LUT_TOLERANCE: u8 = 32;
const LUT_MEAN_TOLERANCE: f64 = 0.05;

fn techniques() -> Vec<(&'static str, Technique)> {
    let flush = FlushPolicy::Auto;
    let stencil = |backend| Technique::Stencil { backend, flush };
    vec![
        ("branching", Technique::DEFERRED),
        ("stencil-native", stencil(Backend::Native)),
        ("stencil-ps3", stencil(Backend::Ps3)),
        // AMD's hierarchies reject only tiles where no pixel passes: as exact as native.
        ("stencil-amd-pretest", stencil(Backend::AmdPretest)),
        ("stencil-amd-andor", stencil(Backend::AmdAndOr)),
        (
            "stencil-x360",
            stencil(Backend::X360 {
                zero_preserved: true,
                save_restore: false,
            }),
        ),
        (
            "adaptive-ps3",
            Technique::Adaptive {
                backend: Backend::Ps3,
                flush,
            },
        ),
        (
            "branching-x360",
            Technique::Branching {
                backend: Backend::X360 {
                    zero_preserved: true,
                    save_restore: false,
                },
                flush,
            },
        ),
    ]
}

fn check(scene_name: &str) {
    let scene = histencil_scene::embedded(scene_name).unwrap();
    with_validated_context(|ctx| {
        let mut renderer = Renderer::new(ctx, scene, SIZE, SIZE).expect("renderer");
        let scene_brdfs = renderer.brdfs().to_vec();
        let forward = renderer
            .render(Shading::Forward, Readback::ALL)
            .expect("forward")
            .images
            .ldr
            .unwrap();
        assert!(
            lit_fraction(&forward) > 0.5,
            "{scene_name}: reference frame is mostly black"
        );
        let mut against_forward = |label: &str, technique, tolerance| {
            let image = renderer
                .render(technique, Readback::ALL)
                .expect("frame")
                .images
                .ldr
                .unwrap();
            let d = assert_close(
                &format!("technique-{scene_name}-{label}"),
                &image,
                &forward,
                tolerance,
            );
            println!(
                "{scene_name} {label}: max {} / 255, mean {:.5} / 255, {} pixels differ",
                d.max, d.mean, d.pixels_differing
            );
            (image, d)
        };
        let mut images = vec![];
        for (label, technique) in techniques() {
            images.push((label, against_forward(label, technique, TOLERANCE).0));
        }
        // The tiled technique, either way with mixed tiles: exact like the others, the same
        // twice (its tile lists are appended in whatever order the GPU runs the tiles; each
        // pixel is shaded once), and the same both ways (a pixel's sum does not depend on which
        // kernel computes it).
        let tiled_with = |mixed, side| Technique::Tiled { mixed, side };
        let per_brdf = tiled_with(MixedTiles::PerBrdf, TileSide::Sixteen);
        let branching_mixed = tiled_with(MixedTiles::Branching, TileSide::Sixteen);
        let (tiled, _) = against_forward("tiled", per_brdf, TOLERANCE);
        let (again, _) = against_forward("tiled", per_brdf, TOLERANCE);
        assert_eq!(
            diff(&tiled, &again).pixels_differing,
            0,
            "{scene_name}: tiled twice"
        );
        let (mixed, _) = against_forward("tiled-mixed-branching", branching_mixed, TOLERANCE);
        assert_eq!(
            diff(&tiled, &mixed).pixels_differing,
            0,
            "{scene_name}: tiled both ways"
        );
        // 8x8 tiles, either way: the same pixels again.
        for mixed in [MixedTiles::PerBrdf, MixedTiles::Branching] {
            let small = tiled_with(mixed, TileSide::Eight);
            let (image, _) = against_forward("tiled-8x8", small, TOLERANCE);
            assert_eq!(
                diff(&tiled, &image).pixels_differing,
                0,
                "{scene_name}: 8x8 tiles"
            );
        }
        // The depth-id technique finds each BRDF's pixels by a depth test instead of tile
        // lists, and adds the same lights the same way: the tiled image, with either tile.
        for side in [TileSide::Sixteen, TileSide::Eight] {
            let (image, _) = against_forward("depth-id", Technique::DepthId { side }, TOLERANCE);
            assert_eq!(
                diff(&tiled, &image).pixels_differing,
                0,
                "{scene_name}: depth-id with {side:?} tiles"
            );
        }
        // The LUT technique is approximate: its own tolerance, at the default resolution, with
        // hi-stencil (ps3) and without (native). glTF's metallic-roughness BRDF is held as its
        // two factors per entry, the tinted and the white part.
        let luts =
            [("lut-native", Backend::Native), ("lut-ps3", Backend::Ps3)].map(|(label, backend)| {
                (
                    label,
                    Technique::Lut {
                        backend,
                        flush: FlushPolicy::Auto,
                    },
                )
            });
        // A white specular's table error grows as its roughness falls, past this bound at the
        // default resolution: a scene with one is held to its tables' predicted error in
        // tests/tests/lut.rs, and here only lit, validation-clean.
        let white = scene_brdfs.contains(&BrdfId::GltfMetalRough);
        for (label, technique) in &luts {
            let tolerance = if white { u8::MAX } else { LUT_TOLERANCE };
            let (image, d) = against_forward(label, *technique, tolerance);
            assert!(lit_fraction(&image) > 0.2, "{scene_name} {label}: too dark");
            assert!(
                white || d.mean <= LUT_MEAN_TOLERANCE,
                "{scene_name} {label}: {d:?}"
            );
        }
        let (_, branching) = &images[0];
        for (label, image) in &images[1..] {
            let d = diff(image, branching);
            assert_eq!(
                d.pixels_differing, 0,
                "{scene_name}: {label} is not bit-identical to branching"
            );
        }
        // Only the BRDFs in use get shaders: per BRDF and geometry (volume, and full screen for
        // the directional light) one pipeline with and one without the hi-stencil emulation's
        // tile work, plus branching, LUT, stencil-only and hi-stencil touch ones.
        let brdfs = renderer.brdfs().len();
        assert!(
            renderer.light_pipeline_count() <= 2 * (2 * brdfs + 5),
            "{scene_name}: {} light pipelines for {brdfs} BRDFs",
            renderer.light_pipeline_count()
        );
        drop(renderer);
        // Every technique on one context: the device limits they needed are the table's.
        let reached = [
            Limit::PerStageStorageBuffers,
            Limit::ComputeWorkGroupInvocations,
            Limit::ComputeWorkGroupSize,
        ];
        assert_needs_hold(ctx, &reached);
    });
}

#[test]
fn one_brdf() {
    check("brdfs-1");
}

#[test]
fn two_brdfs() {
    check("default");
}

#[test]
fn three_brdfs() {
    check("brdfs-3");
}

#[test]
fn six_brdfs() {
    check("brdfs-6");
}

/// glTF's metallic-roughness BRDF beside skin, hair and cloth: the talk's multi-BRDF case.
#[test]
fn gltf_metal_rough_beside_the_talks_brdfs() {
    check("pbr-mixed");
}

#[test]
fn camera_inside_a_light_volume() {
    check("inside");
}

#[test]
fn volumes_crossing_near_and_far_planes() {
    check("near-far");
}

/// Adaptive follows its cost model: costs that make stencil free plan exactly the stencil
/// technique, costs that make branching free plan exactly branching.
#[test]
fn adaptive_chooses_what_the_cost_model_says() {
    let scene = histencil_scene::embedded("brdfs-3").unwrap();
    with_validated_context(|ctx| {
        let (backend, flush) = (Backend::Ps3, FlushPolicy::Auto);
        let with_costs = |costs| {
            let desc = RendererDesc {
                cost_model: Some(costs),
                ..RendererDesc::new(SIZE, SIZE)
            };
            Renderer::with_desc(ctx, scene.clone(), &desc).expect("renderer")
        };
        let plan = |renderer: &Renderer, technique| renderer.plan(technique).expect("plan");
        let adaptive = Technique::Adaptive { backend, flush };
        let free_stencil = CostModel {
            pass_overhead_ms: 0.0,
            stencil_per_brdf_ms: 0.0,
            branch_tax_per_brdf_ms: 1.0,
            shade_ms: 1.0,
            interval: None,
            tiled: None,
            slot_weights: None,
        };
        let renderer = with_costs(free_stencil);
        assert_eq!(
            plan(&renderer, adaptive),
            plan(&renderer, Technique::Stencil { backend, flush })
        );
        let free_branching = CostModel {
            pass_overhead_ms: 1.0,
            stencil_per_brdf_ms: 1.0,
            branch_tax_per_brdf_ms: 0.0,
            shade_ms: 1.0,
            interval: None,
            tiled: None,
            slot_weights: None,
        };
        let renderer = with_costs(free_branching);
        assert_eq!(
            plan(&renderer, adaptive),
            plan(&renderer, Technique::Branching { backend, flush })
        );
        assert_eq!(renderer.resolve(adaptive).unwrap(), adaptive);

        // A stencil pass costs what a whole screen of branching's tax does: with every BRDF of
        // the same cost branching is never dearer; with the scene's BRDFs weighed heavy
        // (`calibrate`'s `brdf_weights`) their tax outweighs the passes on every light.
        let balanced = CostModel {
            pass_overhead_ms: 0.5,
            stencil_per_brdf_ms: 0.0,
            ..free_stencil
        };
        let renderer = with_costs(balanced);
        assert_eq!(
            plan(&renderer, adaptive),
            plan(&renderer, Technique::Branching { backend, flush })
        );
        let set = &histencil_vk::BrdfModules::builtin().set;
        let heavy: Vec<(String, f64)> = set.ids().iter().map(|b| (b.name().into(), 1e6)).collect();
        let desc = RendererDesc {
            cost_model: Some(balanced),
            brdf_weights: Some(histencil_brdf::BrdfWeights::by_name(set, &heavy).unwrap()),
            ..RendererDesc::new(SIZE, SIZE)
        };
        let renderer = Renderer::with_desc(ctx, scene.clone(), &desc).expect("renderer");
        assert_eq!(
            plan(&renderer, adaptive),
            plan(&renderer, Technique::Stencil { backend, flush })
        );

        // Costs with free tiles light the frame tiled (with the device's tiles, 8x8 on
        // lavapipe): the same image as the tiled technique, classification timed; costs with
        // dear tiles keep the plan.
        let tiled = Technique::Tiled {
            mixed: MixedTiles::PerBrdf,
            side: TileSide::for_context(ctx),
        };
        let tiles = |classify_ms| {
            Some(TiledCosts {
                classify_ms,
                shade_ms: 0.0,
                interval: None,
                depth_id: None,
            })
        };
        let mut renderer = with_costs(CostModel {
            tiled: tiles(0.0),
            ..free_branching
        });
        // An emulated console keeps its plan: tiles are not what it shows.
        assert_eq!(renderer.resolve(adaptive).unwrap(), adaptive);
        let native = Technique::Adaptive {
            backend: Backend::Native,
            flush,
        };
        assert_eq!(renderer.resolve(native).unwrap(), tiled);
        let ldr = Readback {
            ldr: true,
            ..Readback::NONE
        };
        let frame = renderer.render(native, ldr).unwrap();
        assert!(frame.timings.pass_ms("tile-classify").is_some());
        assert!(frame.timings.pass_ms("tile-lights").is_some());
        let expected = renderer.render(tiled, ldr).unwrap().images.ldr.unwrap();
        assert_eq!(frame.images.ldr.unwrap(), expected);
        let renderer = with_costs(CostModel {
            tiled: tiles(1e9),
            ..free_branching
        });
        assert_eq!(renderer.resolve(native).unwrap(), native);
        // Costs whose depth-id figures undercut the tiled kernels light the frame by depth ids:
        // the tiled image again, bit for bit.
        let mut renderer = with_costs(CostModel {
            tiled: Some(TiledCosts {
                shade_ms: 1.0,
                depth_id: Some(DepthIdCosts {
                    per_brdf_ms: 0.0,
                    shade_ms: 0.0,
                    interval: None,
                }),
                ..tiles(0.0).unwrap()
            }),
            ..free_branching
        });
        let side = TileSide::for_context(ctx);
        assert_eq!(
            renderer.resolve(native).unwrap(),
            Technique::DepthId { side }
        );
        let frame = renderer.render(native, ldr).unwrap();
        assert_eq!(frame.images.ldr.unwrap(), expected);
    });
}

/// A device that offers only the spec's minimum of every limit (capped here, on any device):
/// the driver line lists what histencil needs above it and what is unmet, the tiles shrink to
/// 8x8, and the lighting, whose layouts bind 7 storage buffers per stage against the minimum's
/// 4, is refused with an error that names the limit before Vulkan sees the layout (so no
/// validation message).
#[test]
fn a_device_at_the_spec_minimum_is_refused_by_name() {
    let _turn = histencil_tests::instance_turn();
    let ctx = histencil_vk::Context::new(histencil_vk::ContextDesc {
        spec_minimum_limits: true,
        ..histencil_vk::ContextDesc::validated()
    })
    .expect("a device");
    let log = ctx.validation_log();
    let line = ctx.driver().to_string();
    assert!(
        line.contains("unmet: maxPerStageDescriptorStorageBuffers 4 < 7")
            && line.contains("maxComputeWorkGroupInvocations 128 < 256"),
        "{line}"
    );
    assert_eq!(TileSide::for_context(&ctx), TileSide::Eight);
    let scene = histencil_scene::embedded("default").unwrap();
    // The renderer makes its lighting's layouts as it is made.
    let refused = Renderer::new(&ctx, scene, 16, 16).err();
    match refused {
        Some(histencil_vk::Error::DeviceLimit(why)) => {
            assert!(why.contains("maxPerStageDescriptorStorageBuffers"), "{why}")
        }
        other => panic!("expected a device-limit error, got {other:?}"),
    }
    drop(ctx);
    log.assert_clean();
}
