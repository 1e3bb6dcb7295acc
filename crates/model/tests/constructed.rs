//! Constructed cases with exact expectations: the talk's failure on the 360 without zeroing,
//! stale hi-stencil without flushes, hi-stencil culling that actually culls, and a full-size run.

use histencil_model::{
    FlushPolicy, Footprint, FramePlan, LightCase, LightRequest, LightTechnique, PlatformBackend,
    Ps3Like, Simulator, SoftTarget, StencilLayout, SyntheticDesc, SyntheticFrame, X360Like,
    NOT_SHADED,
};

const SIZE: u32 = 16;

/// A 16x16 frame at depth 0.5: BRDF slot 0 left of `split`, slot 1 right of it, `preserved`
/// in every pixel.
fn split_frame(split: u32, preserved: u8) -> (StencilLayout, SoftTarget) {
    let layout = StencilLayout::new(2, 0).unwrap();
    let stencil = (0..SIZE * SIZE)
        .map(|i| layout.brdf_reference(u32::from(i % SIZE >= split)) | preserved)
        .collect();
    let target = SoftTarget {
        width: SIZE,
        height: SIZE,
        depth: vec![0.5; (SIZE * SIZE) as usize],
        stencil,
    };
    (layout, target)
}

/// A light covering the whole frame, its volume from depth 0.1 to 0.9 at the centre.
fn covering_light() -> Footprint {
    Footprint::ellipsoid((SIZE, SIZE), (8.0, 8.0), 24.0, 0.5, 0.4)
}

fn lit_pixels(
    layout: StencilLayout,
    target: &SoftTarget,
    backend: &dyn PlatformBackend,
    policy: FlushPolicy,
    tile_size: u32,
) -> (usize, histencil_model::TileStats) {
    let footprint = covering_light();
    assert_eq!(footprint.case(), LightCase::Outside);
    let request = LightRequest {
        case: footprint.case(),
        affected: vec![0, 1],
        technique: LightTechnique::Stencil,
    };
    let plan = FramePlan::from_requests(&layout, backend, &[request], policy).unwrap();
    let mut target = target.clone();
    let result = Simulator { layout, tile_size }.run(&mut target, &plan, &[footprint]);
    let lit = result.lights[0]
        .brdf
        .iter()
        .filter(|&&b| b != NOT_SHADED)
        .count();
    (lit, result.stats)
}

#[test]
fn the_360_without_zeroing_loses_lit_pixels_to_preserved_bits() {
    let everything = (SIZE * SIZE) as usize;
    let (layout, garbage) = split_frame(8, 0x80);
    let naive = X360Like {
        zero_preserved: false,
        save_restore: false,
    };
    let (lit, stats) = lit_pixels(layout, &garbage, &naive, FlushPolicy::Auto, 8);
    assert_eq!(lit, 0, "the talk's failure: every tile culled");
    assert_eq!(stats.tiles_culled, stats.tiles_tested);

    let (lit, _) = lit_pixels(layout, &garbage, &X360Like::default(), FlushPolicy::Auto, 8);
    assert_eq!(lit, everything, "zeroing as we go fixes it");
    let (lit, _) = lit_pixels(layout, &garbage, &Ps3Like, FlushPolicy::Auto, 8);
    assert_eq!(lit, everything, "a read mask never needed it");

    let (clean_layout, clean) = split_frame(8, 0);
    let (lit, _) = lit_pixels(clean_layout, &clean, &naive, FlushPolicy::Auto, 8);
    assert_eq!(
        lit, everything,
        "without engine data the naive scheme works"
    );
}

#[test]
fn never_flushing_shades_with_a_stale_surface() {
    let (layout, target) = split_frame(8, 0);
    let (lit, _) = lit_pixels(layout, &target, &Ps3Like, FlushPolicy::Auto, 8);
    assert_eq!(lit, 256);
    // The BRDF 1 shade pass tests the mask of BRDF 0, which culls the right-hand tiles.
    let (lit, stats) = lit_pixels(layout, &target, &Ps3Like, FlushPolicy::Never, 8);
    assert_eq!(lit, 128, "only the BRDF 0 half is lit");
    assert_eq!(stats.flushes, 0);
}

#[test]
fn hi_stencil_culls_tiles_of_other_brdfs() {
    let (layout, target) = split_frame(8, 0);
    let (lit, stats) = lit_pixels(layout, &target, &Ps3Like, FlushPolicy::Auto, 8);
    assert_eq!(lit, 256);
    assert_eq!(stats.tiles_tested, 8, "two shade passes over four tiles");
    assert_eq!(
        stats.tiles_culled, 4,
        "each shade pass culls the other half"
    );
    assert_eq!(stats.fragments_shaded, 256);
    assert_eq!(stats.flushes, 2);
    // A tile straddling the split passes for both BRDFs: hi-stencil is conservative.
    let (straddle_layout, straddle) = split_frame(4, 0);
    let (lit, stats) = lit_pixels(straddle_layout, &straddle, &Ps3Like, FlushPolicy::Auto, 8);
    assert_eq!(lit, 256);
    assert_eq!(stats.tiles_culled, 2);
}

#[test]
fn the_360_plan_with_save_restore_reads_like_the_talk() {
    let layout = StencilLayout::new(8, 0).unwrap();
    let backend = X360Like {
        zero_preserved: true,
        save_restore: true,
    };
    let request = LightRequest {
        case: LightCase::Outside,
        affected: vec![0, 2],
        technique: LightTechnique::Stencil,
    };
    let plan = FramePlan::from_requests(&layout, &backend, &[request], FlushPolicy::Auto).unwrap();
    assert_eq!(
        plan.describe(),
        "depth Standard\n\
         light 0 (input 0): Outside, BRDF slots [0, 2], stencil\n\
         save preserved bits 0xf0\n\
         light 0: setup\n\
         light 0: mask-brdf-0\n\
         flush hi-stencil\n\
         light 0: shade-brdf-0\n\
         light 0: mask-brdf-2\n\
         flush hi-stencil\n\
         light 0: shade-brdf-2\n\
         light 0: cleanup\n\
         restore preserved bits 0xf0\n"
    );
    assert_eq!(
        plan.draw_count(),
        6 + 4,
        "restoring 4 bits costs 4 full-screen passes"
    );
}

/// The size the issue asks the simulator to handle quickly; speed itself is in the bench.
#[test]
fn a_256_square_frame_with_100_lights_is_lit_exactly() {
    let layout = StencilLayout::new(4, 2).unwrap();
    let frame = SyntheticFrame::generate(&SyntheticDesc {
        size: 256,
        lights: 100,
        layout,
        preserved: 0xC0,
        radius_px: (4.0, 64.0),
        seed: 0x2545_F491_4F6C_DD1D,
    });
    let plan =
        FramePlan::from_requests(&layout, &Ps3Like, &frame.requests, FlushPolicy::Auto).unwrap();
    let mut target = frame.target.clone();
    let result = Simulator {
        layout,
        tile_size: 8,
    }
    .run(&mut target, &plan, &frame.footprints);
    assert_eq!(target.stencil, frame.target.stencil);
    let mut expected = 0u64;
    for (l, fp) in frame.footprints.iter().enumerate() {
        for y in fp.y0..fp.y0 + fp.height {
            for x in fp.x0..fp.x0 + fp.width {
                let depth = frame.target.depth[target.index(x, y)];
                let local = ((y - fp.y0) * fp.width + (x - fp.x0)) as usize;
                let inside = fp.shades(x, y, depth);
                expected += u64::from(inside);
                assert_eq!(result.lights[l].count[local], u8::from(inside));
            }
        }
    }
    assert_eq!(result.stats.fragments_shaded, expected);
    assert!(result.stats.tiles_culled > 0);
}
