// The tiled technique's own resources (set 2) and settings (push constants), shared by its two
// compute passes (tile_classify.comp, tile_shade.comp). Rust mirror: crates/vk/src/passes/tiled.rs.
#ifndef TILED_GLSL
#define TILED_GLSL

#include "generated.glsl"

// The list of mixed tiles, after every BRDF slot's.
const uint TILED_MIXED_SLOT = 32u;
// tiled.mixed: mixed tiles go to each of their BRDFs' lists.
const uint TILED_PER_BRDF = ~0u;

// Per BRDF slot s, the indirect dispatch of its shade pass at words 4s to 4s + 2: x tiles,
// y = z = 1 (word 4s + 3 unused). Words, not uvec4s: atomics act on whole words.
layout(set = 2, binding = 0, std430) buffer TiledDispatch {
    uint dispatch[];
};
// Per BRDF slot, the tiles that contain it: slot s's list starts at s * tiled.tiles. List
// TILED_MIXED_SLOT holds the tiles of several BRDFs when they are shaded once, branching.
layout(set = 2, binding = 1, std430) buffer TileLists {
    uint tile_lists[];
};
// Per tile, a bit per light that can reach it (tiled.words words, light i at bit i % 32 of word
// i / 32), so the shade pass adds the lights in the scene's order, as forward does. Zeroed
// before the classification, set by the light lists (tile_lights.comp).
layout(set = 2, binding = 2, std430) buffer TileLights {
    uint tile_lights[];
};
// Per tile, the bits of its surfaces' nearest and farthest linear depth (positive floats order
// as their bits do), or EMPTY_TILE where it has no surface of a BRDF the frame lights: written
// by the classification for the light lists.
layout(set = 2, binding = 3, std430) buffer TileDepths {
    uvec2 tile_depths[];
};
const uvec2 EMPTY_TILE = uvec2(0xFFFFFFFFu, 0u);
// The HDR target: with `clear`, the classification clears the pixels no kernel shades and each
// kernel writes its pixels once; without, the kernels add onto it.
layout(set = 2, binding = 4, rgba16f) uniform image2D tiled_hdr;

layout(push_constant) uniform Tiled {
    uint tiles_x; // tiles per row
    uint tiles;   // tiles in the frame
    uint words;   // light mask words per tile
    uint clear;   // 1: the HDR target is cleared first (its old contents are not read)
    uint mixed;   // the list mixed tiles go to: TILED_MIXED_SLOT (one branching pass), or
                  // TILED_PER_BRDF (each of their BRDFs' lists)
    uint slot_of_model[TILED_MODELS]; // BRDF model id -> stencil slot (or ~0u: not in the frame)
} tiled;

#endif
