// Kajiya-Kay: the GLSL spelling of crates/brdf/src/models/fibre.rs. Ignores N, not gated; a zero
// tangent gives 0.
#ifndef BRDF_FIBRE_GLSL
#define BRDF_FIBRE_GLSL

#include "brdf/common.glsl"

float brdf_kajiya_kay(float kd, float ks, float p, vec3 T, vec3 V, vec3 L) {
    vec3 t, v, l;
    if (!brdf_normalize(T, t) || !brdf_normalize(V, v) || !brdf_normalize(L, l)) {
        return 0.0;
    }
    float t_dot_l = clamp(dot(t, l), -1.0, 1.0);
    float t_dot_v = clamp(dot(t, v), -1.0, 1.0);
    float sin_tl = brdf_sin_from_cos(t_dot_l);
    float sin_tv = brdf_sin_from_cos(t_dot_v);
    float specular = clamp(t_dot_l * t_dot_v + sin_tl * sin_tv, 0.0, 1.0);
    return kd * sin_tl + ks * brdf_pow(specular, p);
}

#endif
