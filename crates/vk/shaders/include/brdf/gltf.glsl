// glTF 2.0's metallic-roughness BRDF (the specification's Appendix B); the GLSL spelling of
// crates/brdf/src/models/gltf.rs. Its value is affine in the base colour, so it is returned in
// two parts: f * N.L = base * tinted + white (BrdfParts, eval.glsl).
#ifndef BRDF_GLTF_GLSL
#define BRDF_GLTF_GLSL

#include "brdf/surface.glsl"

// x: tinted, y: white, both times N.L.
vec2 brdf_gltf_metal_rough(float alpha, float metallic, vec3 N, vec3 V, vec3 L) {
    BrdfLit s;
    vec3 h;
    if (!brdf_lit(N, V, L, s) || !brdf_normalize(s.l + s.v, h)) {
        return vec2(0.0);
    }
    float a2;
    float d = brdf_ggx_d(alpha, s.n, h, a2);
    float nl = s.n_dot_l;
    float nv = s.n_dot_v;
    // The specification's separable Smith-GGX visibility.
    float masking_l = nl + sqrt(a2 + (1.0 - a2) * nl * nl);
    float masking_v = nv + sqrt(a2 + (1.0 - a2) * nv * nv);
    float vis = 1.0 / (masking_l * masking_v);
    float specular = d * vis * nl;
    float v_dot_h = clamp(dot(s.v, h), 0.0, 1.0);
    float w = 1.0 - v_dot_h;
    float schlick = w * w * w * w * w;
    float f_dielectric = 0.04 + 0.96 * schlick;
    float m = clamp(metallic, 0.0, 1.0);
    float dielectric = 1.0 - m;
    float diffuse = (1.0 - f_dielectric) * INV_PI * nl;
    float tinted = dielectric * diffuse + m * specular * (1.0 - schlick);
    float white = dielectric * f_dielectric * specular + m * specular * schlick;
    return vec2(tinted, white);
}

#endif
