// Every BRDF model by id (BRDF_*, generated from histencil_brdf::BrdfId::ALL) with its
// packed parameters (histencil_brdf::Brdf::packed_params). Scalar models fill all channels.
#ifndef BRDF_EVAL_GLSL
#define BRDF_EVAL_GLSL

#include "brdf/surface.glsl"
#include "brdf/fibre.glsl"
#include "brdf/skin.glsl"

vec3 brdf_eval(uint model, vec4 p, vec3 N, vec3 T, vec3 V, vec3 L) {
    switch (model) {
    case BRDF_LAMBERT:
        return vec3(brdf_lambert(p.x, N, L));
    case BRDF_BLINN_PHONG:
        return vec3(brdf_blinn_phong(p.x, N, V, L));
    case BRDF_OREN_NAYAR_FULL:
        return vec3(brdf_oren_nayar_full(p.x, p.y, N, V, L));
    case BRDF_OREN_NAYAR_QUALITATIVE:
        return vec3(brdf_oren_nayar_qualitative(p.x, p.y, N, V, L));
    case BRDF_GGX:
        return vec3(brdf_ggx(p.x, p.y, p.z, N, V, L));
    case BRDF_KAJIYA_KAY:
        return vec3(brdf_kajiya_kay(p.x, p.y, p.z, T, V, L));
    case BRDF_PENNER_SKIN:
        return brdf_penner_skin(p.x, p.y, N, L);
    }
    return vec3(0.0);
}

#endif
