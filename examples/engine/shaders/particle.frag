#version 460
// A soft round sprite lit from its system's lightmap, premultiplied by its coverage.
#include "alpha.glsl"

layout(location = 0) in vec3 in_world_position;
layout(location = 1) in vec2 in_corner;
layout(location = 2) flat in uint in_entity;
layout(location = 3) in float in_param;

layout(location = 0) out vec4 out_color;

void main() {
    AlphaEntity e = entities[in_entity];
    float coverage = e.tint_opacity.w * max(1.0 - dot(in_corner, in_corner), 0.0);
    if (coverage <= 0.0) {
        discard;
    }
    vec3 lit = lightmap_particle(lightmap_atlas, e, in_world_position, in_param);
    out_color = vec4(lit * coverage, coverage);
}
