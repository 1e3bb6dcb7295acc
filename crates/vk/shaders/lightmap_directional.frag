#version 460
// The lightmap pass with a direction map (the talk's "second texture with light direction
// information"): per texel, the irradiance the lights deliver at the probe through its normal
// (atlas, rgb: the sum of incident * N.L), and the sum of their directions weighted by that
// irradiance's luminance (direction map: xyz the sum of w L, w the sum of w). Additive like
// lightmap.frag, so the sums build up one light per draw; the alpha shaders evaluate their own
// BRDF with their own normal and view along the dominant direction (directional_lighting).
#include "alpha.glsl"

layout(location = 0) out vec4 out_irradiance;
layout(location = 1) out vec4 out_direction;

void main() {
    out_irradiance = vec4(0.0);
    out_direction = vec4(0.0);
    AlphaEntity e = entities[alpha_draw.entity];
    vec3 P, N;
    if (!lightmap_probe(e, ivec2(gl_FragCoord.xy) - ivec2(e.region.xy), P, N)) {
        return;
    }
    vec3 L;
    vec3 incident = light_incident(lights[alpha_draw.light], P, L);
    float n_dot_l = dot(N, L);
    if (n_dot_l <= 0.0) {
        return;
    }
    vec3 irradiance = incident * n_dot_l;
    // Weighted by the irradiance's luminance (Rec. 709).
    float w = dot(irradiance, vec3(0.2126, 0.7152, 0.0722));
    out_irradiance = vec4(irradiance, 0.0);
    out_direction = vec4(L * w, w);
}
