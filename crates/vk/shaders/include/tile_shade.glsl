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

layout(local_size_x = TILED_TILE, local_size_y = TILED_TILE) in;

const uint BRANCH_ON_GBUFFER = 0xFFFFFFFFu;
layout(constant_id = 0) const uint SHADED_BRDF = 0u;
layout(constant_id = 1) const uint SHADED_SLOT = 0u;

// Advances `w` past empty mask words of the tile whose masks start at `base`, loading each into
// `bits`, and stops at the last word.
void skip_empty_words(uint base, inout uint w, inout uint bits) {
    while (bits == 0u && w + 1u < tiled.words) {
        bits = tile_lights[base + ++w];
    }
}

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
    // The tile's lights in the scene's order (word by word, low bit first), as forward adds
    // them. The loop tests for another light at its end, and skips empty words in a loop of
    // its own: llvmpipe runs a loop's body once more, every lane masked off, after the last
    // lane leaves it, so a light loop entered per mask word (or tested at its top) cost a whole
    // light evaluation per word. Here the wasted one is a word load, and a light evaluation
    // only where the tile has no light at all.
    uint base = tile * tiled.words;
    uint w = 0u;
    uint bits = tile_lights[base];
    skip_empty_words(base, w, bits);
    vec3 sum = vec3(0.0);
    if (bits != 0u) {
        do {
            uint index = w * 32u + uint(findLSB(bits));
            bits &= bits - 1u;
            Light light = lights[index];
            vec3 lit = shade_light_with(light, s, model);
            if (any(greaterThan(lit, vec3(0.0)))) {
                lit *= light_visibility(index, light, s);
            }
            sum += lit;
            skip_empty_words(base, w, bits);
        } while (bits != 0u);
    }
    // Each pixel is shaded by one kernel (its BRDF's, or the branching one's): over a cleared
    // target its light is the whole value, and the classification left the pixel unwritten.
    vec4 under = tiled.clear != 0u ? vec4(0.0) : imageLoad(tiled_hdr, px);
    imageStore(tiled_hdr, px, under + vec4(sum, 0.0));
}

#endif
