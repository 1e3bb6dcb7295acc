// Metallic-roughness as many engines spell it (Karis 2013, "Real Shading in Unreal Engine 4"):
// GGX with alpha = roughness^2, Schlick's Fresnel from F0 = mix(0.04, base, metallic), Smith's
// visibility with k = alpha / 2, and a Lambert diffuse weighted by 1 - F. F holds the base
// colour and weighs the diffuse, which holds it again: the value goes with the base colour
// squared, so it takes the colour itself and returns f * N.L of that surface, per channel.
// p.x: perceptual roughness; p.y: metallic.
#ifndef TESTS_METAL_ROUGH_GLSL
#define TESTS_METAL_ROUGH_GLSL

vec3 metal_rough_rgb(vec4 p, vec3 tint, vec3 N, vec3 T, vec3 V, vec3 L) {
    float n_dot_l = min(dot(N, L), 1.0);
    vec3 v = V;
    float n_dot_v;
    vec3 h;
    if (n_dot_l <= 0.0 || !brdf_above_horizon(N, v, n_dot_v) || !brdf_normalize(v + L, h)) {
        return vec3(0.0);
    }
    float alpha = p.x * p.x;
    float a2 = alpha * alpha;
    float n_dot_h = clamp(dot(N, h), 0.0, 1.0);
    float q = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0;
    float d = a2 / (PI * q * q);
    // k >= 0.00125 keeps the denominator above 0 at the horizon, where n_dot_v is 0.
    float k = 0.5 * alpha;
    float vis = 1.0 / (4.0 * (n_dot_l * (1.0 - k) + k) * (n_dot_v * (1.0 - k) + k));
    float schlick = brdf_pow(1.0 - clamp(dot(v, h), 0.0, 1.0), 5.0);
    vec3 f0 = mix(vec3(0.04), tint, p.y);
    vec3 fresnel = f0 + (1.0 - f0) * schlick;
    vec3 diffuse = (1.0 - fresnel) * (1.0 - p.y) * tint * INV_PI;
    return (diffuse + fresnel * d * vis) * n_dot_l;
}

#endif
