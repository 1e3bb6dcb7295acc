#version 460
// A particle's fragment: a soft round sprite (coverage falls to zero at its rim), lit from its
// system's lightmap, forward per pixel, or by the single probe, premultiplied by coverage.
#include "alpha_lightmap.glsl"

layout(location = 0) in vec3 in_world_position;
layout(location = 1) in vec2 in_corner;
layout(location = 2) flat in uint in_entity;
layout(location = 3) in float in_param;
layout(location = 4) flat in float in_mote;

layout(location = 0) out vec4 out_color;

void main() {
    AlphaEntity e = entities[in_entity];
    float coverage = e.tint_opacity.w * max(1.0 - dot(in_corner, in_corner), 0.0);
    if (coverage <= 0.0) {
        discard;
    }
    vec3 P = in_world_position;
    Surface s = alpha_surface(e, P, facing_normal(P));
    vec3 lit;
    if (alpha_draw.mode == ALPHA_MODE_FORWARD) {
        lit = forward_lighting(e, s);
    } else if (alpha_draw.mode == ALPHA_MODE_PROBE) {
        lit = probe_lighting(e, s);
    } else {
        // Dust reads its mote's texel (flat: the interpolated copy may round off the index).
        lit = lightmap_particle(lightmap, e, P, e.shape.x == ALPHA_DUST ? in_mote : in_param);
    }
    out_color = vec4(lit * coverage, coverage);
}
