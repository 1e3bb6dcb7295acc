#version 460
// Camera-facing sprites (histencil_alpha::SpriteVertex, built on the CPU each frame).
#include "alpha.glsl"

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec2 in_corner;
layout(location = 2) in uint in_entity;
layout(location = 3) in float in_param;

layout(location = 1) out vec2 out_corner;
layout(location = 2) flat out uint out_entity;
layout(location = 3) out float out_param;
layout(location = 4) out vec3 out_located;

void main() {
    out_corner = in_corner;
    out_entity = in_entity;
    out_param = in_param;
    // Where the fragment sits in the lightmap, per vertex: the sprite is flat, so it
    // interpolates exactly.
    out_located = lightmap_locate(entities[in_entity], in_position);
    gl_Position = camera.proj * camera.view * vec4(in_position, 1.0);
}
