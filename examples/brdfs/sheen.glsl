// glTF's KHR_materials_sheen over a Lambert base. p.x: the base's albedo (tinted by the surface's
// colour); p.y: the sheen roughness (perceptual; alpha = p.y^2); p.z: the sheen's strength (a
// white sheen colour). The lobe is Estevez and Kulla's Charlie distribution with Neubelt and
// Pettineo's visibility, 1 / (4 (N.L + N.V - N.L N.V)).
#ifndef EXAMPLE_SHEEN_GLSL
#define EXAMPLE_SHEEN_GLSL

vec3 sheen_base(vec4 p, vec3 N, vec3 T, vec3 V, vec3 L) {
    float c = dot(N, L);
    return vec3(c > 0.0 ? p.x * INV_PI * c : 0.0);
}

float sheen_lobe(vec4 p, vec3 N, vec3 T, vec3 V, vec3 L) {
    float n_dot_l = min(dot(N, L), 1.0);
    vec3 v = V;
    float n_dot_v;
    vec3 h;
    if (n_dot_l <= 0.0 || !brdf_above_horizon(N, v, n_dot_v) || !brdf_normalize(v + L, h)) {
        return 0.0;
    }
    float n_dot_h = clamp(dot(N, h), 0.0, 1.0);
    float inv_alpha = 1.0 / max(p.y * p.y, 1e-3);
    float sin2 = max(1.0 - n_dot_h * n_dot_h, 0.0);
    float d = (2.0 + inv_alpha) * brdf_pow(sin2, 0.5 * inv_alpha) * (0.5 * INV_PI);
    float visibility = 1.0 / (4.0 * (n_dot_l + n_dot_v - n_dot_l * n_dot_v));
    return p.z * d * visibility * n_dot_l;
}

#endif
