// The tiled technique's shade pass for one BRDF, dispatched indirectly over the tiles that
// contain it (tile_classify.comp): each of the tile's pixels of this BRDF adds every light of
// the tile's mask, in the scene's order, with the BRDF specialised in (SHADED_BRDF); pixels of
// other BRDFs are left to their own BRDF's pass. Specialised to BRANCH_ON_GBUFFER, it is the
// one pass over the mixed tiles (list TILED_MIXED_SLOT) that branches on each pixel's BRDF.
// The body of the stages tile_shade.comp (16x16 tiles) and tile_shade_8.comp (8x8): each defines
// TILED_TILE, the tile side, and includes this.
#ifndef TILE_SHADE_GLSL
#define TILE_SHADE_GLSL
#include "light.glsl"
#include "surface_decode.glsl"
#include "light_visibility.glsl"
#include "tiled.glsl"
#include "tile_light_sum.glsl"

layout(local_size_x = TILED_TILE, local_size_y = TILED_TILE) in;

const uint BRANCH_ON_GBUFFER = 0xFFFFFFFFu;
layout(constant_id = 0) const uint SHADED_BRDF = 0u;
layout(constant_id = 1) const uint SHADED_SLOT = 0u;

void main() {
    uint tile = tile_lists[SHADED_SLOT * tiled.tiles + gl_WorkGroupID.x];
    uvec2 origin = uvec2(tile % tiled.tiles_x, tile / tiled.tiles_x) * TILED_TILE;
    ivec2 px = ivec2(origin + gl_LocalInvocationID.xy);
    if (any(greaterThanEqual(px, ivec2(frame.viewport.xy)))) {
        return;
    }
    Surface s;
    if (!decode_surface(vec2(px) + 0.5, s)) {
        return;
    }
    // A switch on the constant itself: a comparison of two constants would become
    // OpSpecConstantOp, which naga cannot read (as in deferred_light.frag).
    uint model;
    switch (SHADED_BRDF) {
    case BRANCH_ON_GBUFFER:
        model = s.brdf;
        break;
    default:
        model = SHADED_BRDF;
        break;
    }
    if (s.brdf != model) {
        return;
    }
    vec3 sum = tile_light_sum(tile, s, model);
    // Each pixel is shaded by one kernel (its BRDF's, or the branching one's): over a cleared
    // target its light is the whole value, and the classification left the pixel unwritten.
    vec4 under = tiled.clear != 0u ? vec4(0.0) : imageLoad(tiled_hdr, px);
    imageStore(tiled_hdr, px, under + vec4(sum, 0.0));
}

#endif
