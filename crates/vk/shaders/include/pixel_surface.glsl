// What the tiled technique's classification (tile_classify.glsl) and the depth-id technique's
// id copy (depth_id_copy.frag) read of a pixel: its surface's BRDF and linear depth, and the
// BRDF's slot in the frame.
#ifndef PIXEL_SURFACE_GLSL
#define PIXEL_SURFACE_GLSL
#include "frame.glsl"
#include "surface_decode.glsl"
#include "tiled.glsl"

// The BRDF model id and linear depth of the surface under pixel `px`; false where none.
bool tile_surface(ivec2 px, out uint model, out float depth) {
#ifdef HISTENCIL_BUILTIN_DECODE
    depth = texelFetch(gbuffer_normal_depth, px, 0).w;
    model = uint(texelFetch(gbuffer_material, px, 0).w);
    return depth > 0.0;
#else
    Surface s;
    if (!decode_surface(vec2(px) + 0.5, s)) {
        return false;
    }
    model = s.brdf;
    depth = max(-(frame.view * vec4(s.position, 1.0)).z, 0.0);
    return true;
#endif
}

// The frame's BRDF slot of BRDF model `model`, or ~0u where the frame does not light it.
uint slot_of_model(uint model) {
    return model < TILED_MODELS ? tiled.slot_of_model[model] : ~0u;
}

#endif
