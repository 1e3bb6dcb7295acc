#version 460
// The tiled technique's light lists, between the classification (tile_classify.comp, which
// left each tile's depth range and zeroed masks) and the shade kernels (tile_shade.comp): one
// workgroup per light, its invocations over the tiles of the light's screen rectangle, each
// setting the light's bit in the mask of a tile whose view-space box (the pixel footprints
// between its nearest and farthest surface) the light's range sphere reaches. Battlefield 3's
// tiles test every light against every tile; binning each light into its own rectangle costs
// what the lights cover, so hundreds of small lights cost little. OR is order-free: the masks
// are the same whatever order the workgroups run in.
#include "frame.glsl"

// The tile side (8 or 16), as the classification and shade stages are built for.
layout(constant_id = 0) const uint TILE_SIDE = 16u;
#define TILED_TILE TILE_SIDE
#include "tile_lights.glsl"

const uint GROUP = 64u;
layout(local_size_x = GROUP) in;

void main() {
    uint l = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
    if (l >= frame.counts.x) {
        return;
    }
    Light light = lights[l];
    uvec2 t0;
    uvec2 t1;
    light_tiles(light, t0, t1);
    uvec2 extent = t1 - t0;
    uint count = extent.x * extent.y;
    for (uint i = gl_LocalInvocationID.x; i < count; i += GROUP) {
        uvec2 t = t0 + uvec2(i % extent.x, i / extent.x);
        uint tile = t.y * tiled.tiles_x + t.x;
        uvec2 range = tile_depths[tile];
        if (range.x > range.y) {
            continue; // no surface the frame lights
        }
        vec3 lo;
        vec3 hi;
        tile_box(t, range.x, range.y, lo, hi);
        if (reaches(light, lo, hi)) {
            atomicOr(tile_lights[tile * tiled.words + l / 32u], 1u << (l % 32u));
        }
    }
}
