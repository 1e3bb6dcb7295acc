#version 460
// A soft round sprite lit from its system's lightmap, premultiplied by its coverage.
#include "alpha.glsl"

layout(location = 1) in vec2 in_corner;
layout(location = 2) flat in uint in_entity;
layout(location = 3) in float in_param;
layout(location = 4) in vec3 in_located;

layout(location = 0) out vec4 out_color;

void main() {
    AlphaEntity e = entities[in_entity];
    float coverage = e.tint_opacity.w * max(1.0 - dot(in_corner, in_corner), 0.0);
    if (coverage <= 0.0) {
        discard;
    }
    vec3 lit = lightmap_particle_at(lightmap_atlas, lightmap_linear, e, in_located, in_param);
    out_color = vec4(lit * coverage, coverage);
}
