#version 460
// The per-frame lightmap pass: one draw per (entity, light that reaches it) over the entity's
// region, additive. Each texel is a light probe (lightmap_probe); it is lit by the same light and
// BRDF code as the deferred pass (include/light.glsl), with the entity's own BRDF, towards the
// camera. lightmap_directional.frag is the twin that records a direction map instead.
#include "alpha.glsl"

layout(location = 0) out vec4 out_color;

void main() {
    AlphaEntity e = entities[alpha_draw.entity];
    vec3 P, N;
    if (!lightmap_probe(e, ivec2(gl_FragCoord.xy) - ivec2(e.region.xy), P, N)) {
        out_color = vec4(0.0);
        return;
    }
    out_color = vec4(shade_light(lights[alpha_draw.light], alpha_surface(e, P, N)), 0.0);
}
