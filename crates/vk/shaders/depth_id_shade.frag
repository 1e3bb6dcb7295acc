#version 460
// The depth-id technique's shade pass for one BRDF (SHADED_BRDF): a
// full-screen triangle drawn at the slot's depth id with compare EQUAL against the id image
// (depth_id_copy.frag), so only this BRDF's pixels run it; each adds its tile's lights
// (tile_lights.comp) by the BRDF, in the scene's order, with the same sum as the tiled
// technique's kernels (tile_light_sum.glsl), and stores it into the HDR target as they do.
#include "light.glsl"
#include "surface_decode.glsl"
#include "light_visibility.glsl"
#include "tiled.glsl"
#include "tile_light_sum.glsl"

layout(constant_id = 0) const uint SHADED_BRDF = 0u;
// The tiles' side in pixels (8 or 16), as the light lists were built for.
layout(constant_id = 1) const uint TILE_SIDE = 16u;

// The depth test is the whole selection: no fragment of another BRDF runs.
layout(early_fragment_tests) in;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    Surface s;
    if (!decode_surface(gl_FragCoord.xy, s)) {
        return;
    }
    uvec2 t = uvec2(px) / TILE_SIDE;
    vec3 sum = tile_light_sum(t.y * tiled.tiles_x + t.x, s, SHADED_BRDF);
    // As in tile_shade.glsl: each pixel is shaded by one pass, over a target the classification
    // cleared where no pass writes.
    vec4 under = tiled.clear != 0u ? vec4(0.0) : imageLoad(tiled_hdr, px);
    imageStore(tiled_hdr, px, under + vec4(sum, 0.0));
}
