//! The depth-id technique as engines ship it instead of stencil ids, as a GPU's hierarchical
//! depth would cull it. Bevy's deferred renderer copies each pixel's lighting-pass id into a
//! 16-bit depth target (`bevy_core_pipeline/src/deferred/copy_lighting_id.rs`) and draws each
//! lighting pass as a full-screen triangle at its id's depth with compare EQUAL
//! (`bevy_pbr/src/deferred/mod.rs`), so the hierarchical depth, which keeps each tile's depth
//! range, rejects the tiles whose range excludes the pass's id before any fragment runs. Here
//! the ids are what histencil-vk's depth-id technique writes into its 16-bit id image (BRDF
//! slot + 1, and the clear value [`NO_SURFACE`] where no surface was drawn) and the tiles 8x8;
//! llvmpipe has no hierarchical depth, so this is a model of what such a GPU would reject, not a
//! measurement. It runs on the GPU's own id image (`Frame::tile_stats` of a depth-id frame) and
//! on ids made from the G-buffer's stencil and depth ([`pixel_ids`]), which must agree.

use crate::tiles::{TileStats, TileSurface};

/// The id of a pixel with no surface: the id image's clear value, depth 1.
pub const NO_SURFACE: u16 = u16::MAX;

/// The id of BRDF slot `slot`: `slot + 1`, so that no slot is 0 or [`NO_SURFACE`].
pub fn slot_id(slot: u32) -> u16 {
    slot as u16 + 1
}

/// Each pixel's id: its BRDF slot's [`slot_id`], or [`NO_SURFACE`] where `depth` is `far`.
pub fn pixel_ids(slots: impl Iterator<Item = u32>, depth: &[f32], far: f32) -> Vec<u16> {
    slots
        .zip(depth)
        .map(|(slot, d)| if *d == far { NO_SURFACE } else { slot_id(slot) })
        .collect()
}

/// One full-screen EQUAL pass per id in `passes` over `ids` (a `width`-wide target): every
/// tile is tested by every pass, a tile whose id range excludes the pass's id is culled, and
/// each pixel of the pass's id is shaded once (it loops over its tile's lights itself).
pub fn depth_id_stats(ids: &[u16], width: u32, tiles: &TileSurface, passes: &[u16]) -> TileStats {
    let mut range = vec![(u16::MAX, 0u16); tiles.tile_count()];
    for (i, &id) in ids.iter().enumerate() {
        let r = &mut range[tiles.tile_of(i as u32 % width, i as u32 / width)];
        *r = (r.0.min(id), r.1.max(id));
    }
    let mut stats = TileStats::default();
    for &pass in passes {
        stats.tiles_tested += range.len() as u64;
        stats.tiles_culled += range
            .iter()
            .filter(|(lo, hi)| pass < *lo || pass > *hi)
            .count() as u64;
        stats.fragments_shaded += ids.iter().filter(|&&id| id == pass).count() as u64;
    }
    stats
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pass_culls_the_tiles_whose_id_range_excludes_it() {
        // Two 2x2 tiles side by side: ids {1, 1, 1, 1} and {none, 2, 3, 3}.
        let tiles = TileSurface::new(4, 2, 2);
        let none = NO_SURFACE;
        let ids = [1, 1, none, 2, 1, 1, 3, 3];
        let stats = depth_id_stats(&ids, 4, &tiles, &[1, 2, 3]);
        assert_eq!(stats.tiles_tested, 6);
        // Id 1: the second tile's range 2..=none excludes it: culled. Id 2 and 3: the first
        // tile (1..=1) is culled, the second's range holds them.
        assert_eq!(stats.tiles_culled, 3);
        assert_eq!(stats.fragments_shaded, 7, "every surface pixel once");
        // A range, not a set: ids 1 and 3 in a tile keep a pass of id 2 testing it.
        let stats = depth_id_stats(&[1, 3], 2, &TileSurface::new(2, 1, 2), &[2]);
        assert_eq!((stats.tiles_culled, stats.fragments_shaded), (0, 0));
        let far = 1.0;
        let depth = [0.5, far, 0.2];
        assert_eq!(
            pixel_ids([0, 0, 2].into_iter(), &depth, far),
            vec![1, none, 3]
        );
    }
}
