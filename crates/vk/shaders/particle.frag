#version 460
// A particle's fragment: a soft round sprite (coverage falls to zero at its rim), lit from its
// system's lightmap, forward per pixel, or by the single probe, premultiplied by coverage.
#include "alpha_lightmap.glsl"

layout(location = 0) in vec3 in_world_position;
layout(location = 1) in vec2 in_corner;
layout(location = 2) flat in uint in_entity;
layout(location = 3) in float in_param;
layout(location = 4) flat in float in_mote;
layout(location = 5) in vec3 in_located;

layout(location = 0) out vec4 out_color;

// How the fragment is lit: forward per pixel, by the single probe, through the direction map, or
// (none) from the lightmap. A pipeline per mode, so the lightmap pipeline carries none of the per-pixel
// reference's code (on a CPU rasteriser the unused branch and its inputs cost as much as the
// lookup). Booleans, as naga reads no specialisation-constant arithmetic.
layout(constant_id = 0) const bool LIT_FORWARD = false;
layout(constant_id = 1) const bool LIT_BY_PROBE = false;
// From the atlas's incident light and the direction map, with the fragment's own BRDF.
layout(constant_id = 2) const bool LIT_DIRECTIONAL = false;

void main() {
    AlphaEntity e = entities[in_entity];
    float coverage = e.tint_opacity.w * max(1.0 - dot(in_corner, in_corner), 0.0);
    if (coverage <= 0.0) {
        discard;
    }
    vec3 P = in_world_position;
    Surface s = alpha_surface(e, P, facing_normal(P));
    vec3 lit;
    if (LIT_FORWARD) {
        lit = forward_lighting(e, s);
    } else if (LIT_BY_PROBE) {
        lit = probe_lighting(e, s);
    } else {
        // Dust reads its mote's texel (flat: the interpolated copy may round off the index).
        float param = e.shape.x == ALPHA_DUST ? in_mote : in_param;
        lit = lightmap_particle_at(lightmap, lightmap_sampler, e, in_located, param);
        if (LIT_DIRECTIONAL) {
            vec4 direction =
                lightmap_particle_at_rgba(direction_map, lightmap_sampler, e, in_located, param);
            lit = directional_lighting(s, normalize(frame.eye.xyz - P), lit, direction);
        }
    }
    out_color = vec4(lit * coverage, coverage);
}
