//! The AMD platforms' own hierarchical stencil changes the work and nothing else: on the native
//! plan, the simulator with either model shades exactly the pixels, with exactly the BRDFs, and
//! leaves exactly the stencil it does without one, while rejecting tiles; with the engine's bits
//! 0xA0 scattered through every tile (the 360's problem), on frames whose BRDFs vary per pixel
//! and in 16-pixel blocks.

use histencil_model::amd::{choose_pretests, slot_tile_counts, AndOrTiles, PretestTiles};
use histencil_model::{
    FlushPolicy, FramePlan, Native, SimResult, Simulator, SoftTarget, StencilLayout, SyntheticDesc,
    SyntheticFrame, TileSurface,
};

const TILE: u32 = 8;

/// A frame with engine bits 0xA0 in a third of the pixels, BRDFs per pixel (`blocks` false)
/// or per 16x16 block.
fn frame(blocks: bool) -> (StencilLayout, SyntheticFrame) {
    let layout = StencilLayout::new(4, 3).unwrap();
    assert_eq!(
        layout.preserved_mask() & 0xA0,
        0xA0,
        "room for the engine's bits"
    );
    let mut frame = SyntheticFrame::generate(&SyntheticDesc {
        size: 96,
        lights: 40,
        layout,
        preserved: 0,
        radius_px: (3.0, 30.0),
        seed: 0x9E37_79B9_7F4A_7C15,
    });
    let size = frame.target.width;
    for (i, s) in frame.target.stencil.iter_mut().enumerate() {
        let (x, y) = (i as u32 % size, i as u32 / size);
        if blocks {
            *s = layout.brdf_reference((x / 16 + y / 16) % 4);
        }
        if (x + 2 * y) % 3 == 0 {
            *s |= 0xA0;
        }
    }
    (layout, frame)
}

fn run(
    layout: StencilLayout,
    frame: &SyntheticFrame,
    hierarchy: Option<&mut dyn histencil_model::amd::TileHierarchy>,
) -> (SimResult, SoftTarget) {
    let plan =
        FramePlan::from_requests(&layout, &Native, &frame.requests, FlushPolicy::Auto).unwrap();
    let sim = Simulator {
        layout,
        tile_size: TILE,
    };
    let mut target = frame.target.clone();
    let result = match hierarchy {
        None => sim.run(&mut target, &plan, &frame.footprints),
        Some(h) => sim.run_with(&mut target, &plan, &frame.footprints, h),
    };
    (result, target)
}

#[test]
fn each_amd_model_rejects_tiles_and_shades_exactly_what_native_shades() {
    for blocks in [false, true] {
        let (layout, frame) = frame(blocks);
        let (native, native_target) = run(layout, &frame, None);
        assert_eq!(native.stats.tiles_tested, 0, "native has no hierarchy");
        let target = &frame.target;
        let tiles = TileSurface::new(target.width, target.height, TILE);
        let counts = slot_tile_counts(&layout, &target.stencil, target.width, &tiles);
        let mut pretest = PretestTiles::new(choose_pretests(&layout, &counts));
        let mut andor = AndOrTiles::new();
        for (name, h) in [
            (
                "amd-pretest",
                &mut pretest as &mut dyn histencil_model::amd::TileHierarchy,
            ),
            ("amd-andor", &mut andor),
        ] {
            let (result, left) = run(layout, &frame, Some(h));
            assert_eq!(
                result.lights, native.lights,
                "{name} (blocks {blocks}): shading"
            );
            assert_eq!(left.stencil, native_target.stencil, "{name}: stencil left");
            assert_eq!(result.stats.fragments_shaded, native.stats.fragments_shaded);
            // Neither culls where every tile holds every BRDF (BRDFs per pixel) and no tile is
            // marked wholly (depths per pixel): nothing is known there.
            let culls = blocks;
            assert!(
                result.stats.tiles_culled < result.stats.tiles_tested
                    && (result.stats.tiles_culled > 0) == culls,
                "{name} (blocks {blocks}): {:?}",
                result.stats
            );
            println!("{name}, BRDF blocks {blocks}: {:?}", result.stats);
        }
    }
}

#[test]
fn and_or_culls_more_where_brdfs_come_in_blocks_and_engine_bits_do_not_stop_it() {
    let culled = |blocks: bool, engine_bits: bool| {
        let (layout, mut frame) = frame(blocks);
        if !engine_bits {
            for s in frame.target.stencil.iter_mut() {
                *s &= !0xA0;
            }
        }
        let (result, _) = run(layout, &frame, Some(&mut AndOrTiles::new()));
        result.stats.tiles_culled as f64 / result.stats.tiles_tested as f64
    };
    let (mixed, blocked) = (culled(false, true), culled(true, true));
    assert!(
        blocked > mixed,
        "blocks {blocked} vs per-pixel BRDFs {mixed}"
    );
    // The engine's bits sit outside every test's mask: the same tiles are culled without them.
    assert_eq!(culled(true, false), blocked);
    assert_eq!(culled(false, false), mixed);
}
