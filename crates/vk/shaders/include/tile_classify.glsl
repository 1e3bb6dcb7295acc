// The tiled technique's first pass, on the GPU with no readback: per TILED_TILE x TILED_TILE
// tile, the set of BRDFs its pixels use (from the decode hook, or straight from histencil's
// G-buffer, which holds both in two texels) and their depth range, which the light lists
// (tile_lights.comp, next) test lights against; each BRDF's list of the tiles that contain it
// and the count its shade pass dispatches (appended atomically: the order of a list does not
// matter, each pixel is shaded by one workgroup).
// Two shapes of the same work, by specialisation (PER_INVOCATION, `TileClassify` in tiled.rs),
// with the same results bit for bit: a workgroup per tile whose invocations each read a pixel
// and combine in shared memory (GPUs), or an invocation per tile that reads its tile's pixels
// in a loop, TILED_TILE x TILED_TILE tiles per workgroup (CPU rasterisers such as llvmpipe,
// which run a workgroup with barriers one invocation at a time, switching at each barrier).
// The body of the stages tile_classify.comp (16x16 tiles) and tile_classify_8.comp (8x8): each defines
// TILED_TILE, the tile side, and includes this.
#ifndef TILE_CLASSIFY_GLSL
#define TILE_CLASSIFY_GLSL
#include "frame.glsl"
#include "surface_decode.glsl"
#include "tiled.glsl"
#include "pixel_surface.glsl"

layout(local_size_x = TILED_TILE, local_size_y = TILED_TILE) in;

// True: an invocation per tile (`classify_alone`); false: a workgroup per tile.
layout(constant_id = 0) const bool PER_INVOCATION = false;

shared uint tile_brdfs;
// Linear depths as float bits: positive floats order as their bits do.
shared uint tile_near;
shared uint tile_far;

// Pixel `px`'s part in its tile's class: false where it has no surface; else its BRDF slot's
// bit (0 for a BRDF the frame does not light) and the bits of its linear depth (positive floats
// order as their bits do). Clears the pixel when asked, unless it is of a BRDF in the frame,
// which its kernel writes once without reading it. (The branching kernel of mixed tiles also
// writes a mixed tile's pixels of BRDFs not in the frame, after this clear, ordered after it.)
bool pixel_class(ivec2 px, out uint bit, out uint depth_bits) {
    uint model;
    float depth;
    bit = 0u;
    bool surface = tile_surface(px, model, depth);
    if (surface) {
        uint slot = slot_of_model(model);
        bit = slot < 32u ? 1u << slot : 0u;
        depth_bits = floatBitsToUint(depth);
    }
    if (tiled.clear != 0u && bit == 0u) {
        imageStore(tiled_hdr, px, vec4(0.0));
    }
    return surface;
}

// Appends `tile` to the list of each BRDF in `brdfs`, or to the mixed tiles' list when it has
// several and those are shaded once, branching.
void list_tile(uint tile, uint brdfs) {
    bool mixed = (brdfs & (brdfs - 1u)) != 0u; // more than one bit
    if (mixed && tiled.mixed != TILED_PER_BRDF) {
        uint i = atomicAdd(dispatch[4u * TILED_MIXED_SLOT], 1u);
        tile_lists[TILED_MIXED_SLOT * tiled.tiles + i] = tile;
        return;
    }
    while (brdfs != 0u) {
        uint slot = uint(findLSB(brdfs));
        brdfs &= brdfs - 1u;
        uint i = atomicAdd(dispatch[4u * slot], 1u);
        tile_lists[slot * tiled.tiles + i] = tile;
    }
}

// An invocation per tile: it reads the tile's pixels itself, in a loop. Depths are compared as
// float bits, as the workgroup's atomics do, so both give the same range.
void classify_alone() {
    uvec2 t = gl_GlobalInvocationID.xy;
    if (t.x >= tiled.tiles_x || t.y * tiled.tiles_x >= tiled.tiles) {
        return;
    }
    uint tile = t.y * tiled.tiles_x + t.x;
    ivec2 p0 = ivec2(t * TILED_TILE);
    ivec2 p1 = min(p0 + ivec2(TILED_TILE), ivec2(frame.viewport.xy));
    uint brdfs = 0u;
    uint near_bits = floatBitsToUint(3.0e38);
    uint far_bits = 0u;
    for (int y = p0.y; y < p1.y; ++y) {
        for (int x = p0.x; x < p1.x; ++x) {
            uint bit;
            uint depth;
            if (pixel_class(ivec2(x, y), bit, depth)) {
                brdfs |= bit;
                near_bits = min(near_bits, depth);
                far_bits = max(far_bits, depth);
            }
        }
    }
    list_tile(tile, brdfs);
    tile_depths[tile] = brdfs != 0u ? uvec2(near_bits, far_bits) : EMPTY_TILE;
}

// A workgroup per tile: each invocation reads one pixel.
void classify_together() {
    uint local = gl_LocalInvocationIndex;
    uint tile = gl_WorkGroupID.y * tiled.tiles_x + gl_WorkGroupID.x;
    if (local == 0u) {
        tile_brdfs = 0u;
        tile_near = floatBitsToUint(3.0e38);
        tile_far = 0u;
    }
    barrier();
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = ivec2(frame.viewport.xy);
    if (all(lessThan(px, size))) {
        uint bit;
        uint depth;
        if (pixel_class(px, bit, depth)) {
            if (bit != 0u) {
                atomicOr(tile_brdfs, bit);
            }
            atomicMin(tile_near, depth);
            atomicMax(tile_far, depth);
        }
    }
    barrier();
    uint brdfs = tile_brdfs;
    if (local == 0u) {
        list_tile(tile, brdfs);
        tile_depths[tile] = brdfs != 0u ? uvec2(tile_near, tile_far) : EMPTY_TILE;
    }
}

void main() {
    // Branches on the constant itself (`!PER_INVOCATION` would be an OpSpecConstantOp, which
    // naga cannot read); the barriers of the workgroup shape stay in uniform control flow.
    if (PER_INVOCATION) {
        classify_alone();
    } else {
        classify_together();
    }
}

#endif
