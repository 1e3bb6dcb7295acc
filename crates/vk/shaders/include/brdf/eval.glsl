// Every BRDF model by id (BRDF_*, generated from histencil_brdf::BrdfId::ALL) with its
// packed parameters (histencil_brdf::Brdf::packed_params). Scalar models fill all channels.
// A BRDF set (histencil_brdf::BrdfSet) reaches here through the four brdf_set/ files it
// generates: its engine BRDFs' ids and GLSL, their cases, and the BRDF_OMIT_* of the built-ins it
// leaves out. histencil's own set generates them empty, so its shaders are as they always were.
#ifndef BRDF_EVAL_GLSL
#define BRDF_EVAL_GLSL

#include "brdf/surface.glsl"
#include "brdf/fibre.glsl"
#include "brdf/skin.glsl"
#include "brdf/gltf.glsl"
#include "brdf_set/functions.glsl"

// A BRDF's value in two parts, f * N.L = tint * tinted + white (histencil_brdf::Parts): the
// talk's models scale with the tint and have no white part; glTF's metallic-roughness BRDF is
// affine in its base colour.
struct BrdfParts {
    vec3 tinted;
    float white;
};

// The value of a white surface (tint 1): for the talk's models, the value per unit tint.
vec3 brdf_eval(uint model, vec4 p, vec3 N, vec3 T, vec3 V, vec3 L) {
    switch (model) {
#ifndef BRDF_OMIT_LAMBERT
    case BRDF_LAMBERT:
        return vec3(brdf_lambert(p.x, N, L));
#endif
#ifndef BRDF_OMIT_BLINN_PHONG
    case BRDF_BLINN_PHONG:
        return vec3(brdf_blinn_phong(p.x, N, V, L));
#endif
#ifndef BRDF_OMIT_OREN_NAYAR_FULL
    case BRDF_OREN_NAYAR_FULL:
        return vec3(brdf_oren_nayar_full(p.x, p.y, N, V, L));
#endif
#ifndef BRDF_OMIT_OREN_NAYAR_QUALITATIVE
    case BRDF_OREN_NAYAR_QUALITATIVE:
        return vec3(brdf_oren_nayar_qualitative(p.x, p.y, N, V, L));
#endif
#ifndef BRDF_OMIT_GGX
    case BRDF_GGX:
        return vec3(brdf_ggx(p.x, p.y, p.z, N, V, L));
#endif
#ifndef BRDF_OMIT_KAJIYA_KAY
    case BRDF_KAJIYA_KAY:
        return vec3(brdf_kajiya_kay(p.x, p.y, p.z, T, V, L));
#endif
#ifndef BRDF_OMIT_PENNER_SKIN
    case BRDF_PENNER_SKIN:
        return brdf_penner_skin(p.x, p.y, N, L);
#endif
#ifndef BRDF_OMIT_GLTF_METAL_ROUGH
    case BRDF_GLTF_METAL_ROUGH: {
        vec2 g = brdf_gltf_metal_rough(p.x, p.y, N, V, L);
        return vec3(g.x + g.y);
    }
#endif
#include "brdf_set/eval_cases.glsl"
    }
    return vec3(0.0);
}

BrdfParts brdf_eval_parts(uint model, vec4 p, vec3 N, vec3 T, vec3 V, vec3 L) {
#include "brdf_set/parts.glsl"
    if (model == BRDF_GLTF_METAL_ROUGH) {
        vec2 g = brdf_gltf_metal_rough(p.x, p.y, N, V, L);
        return BrdfParts(vec3(g.x), g.y);
    }
    return BrdfParts(brdf_eval(model, p, N, T, V, L), 0.0);
}

// The value for a surface of colour `tint`: what a light's radiance is multiplied by. For the
// talk's models exactly tint * brdf_eval, as it always was.
vec3 brdf_eval_tinted(uint model, vec4 p, vec3 tint, vec3 N, vec3 T, vec3 V, vec3 L) {
#include "brdf_set/tinted.glsl"
    if (model == BRDF_GLTF_METAL_ROUGH) {
        vec2 g = brdf_gltf_metal_rough(p.x, p.y, N, V, L);
        return tint * g.x + g.y;
    }
    return tint * brdf_eval(model, p, N, T, V, L);
}

#endif
