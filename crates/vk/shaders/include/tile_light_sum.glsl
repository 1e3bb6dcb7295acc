// The light a surface of BRDF `model` gets from its tile's lights (the tile's mask,
// tile_lights.comp), added in the scene's order as forward adds them: the sum both tiled shade
// passes write, the compute kernels (tile_shade.glsl) and the depth-id technique's full-screen
// passes (depth_id_shade.frag), so the two agree bit for bit.
#ifndef TILE_LIGHT_SUM_GLSL
#define TILE_LIGHT_SUM_GLSL
#include "light.glsl"
#include "light_visibility.glsl"
#include "tiled.glsl"

// Advances `w` past empty mask words of the tile whose masks start at `base`, loading each into
// `bits`, and stops at the last word.
void skip_empty_words(uint base, inout uint w, inout uint bits) {
    while (bits == 0u && w + 1u < tiled.words) {
        bits = tile_lights[base + ++w];
    }
}

vec3 tile_light_sum(uint tile, Surface s, uint model) {
    // The tile's lights word by word, low bit first. The loop tests for another light at its
    // end, and skips empty words in a loop of its own: llvmpipe runs a loop's body once more,
    // every lane masked off, after the last lane leaves it, so a light loop entered per mask
    // word (or tested at its top) cost a whole light evaluation per word. Here the wasted one is
    // a word load, and a light evaluation only where the tile has no light at all.
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
    return sum;
}

#endif
