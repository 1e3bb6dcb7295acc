#version 460
// Particle sprites and ribbon strips in the alpha pass (histencil_alpha::SpriteVertex, world
// space, built facing the camera each frame).
#include "alpha_lightmap.glsl"

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec2 in_corner;
layout(location = 2) in uint in_entity;
layout(location = 3) in float in_param;

layout(location = 0) out vec3 out_world_position;
layout(location = 1) out vec2 out_corner;
layout(location = 2) flat out uint out_entity;
layout(location = 3) out float out_param;
layout(location = 4) flat out float out_mote;
layout(location = 5) out vec3 out_located;

void main() {
    out_world_position = in_position;
    out_corner = in_corner;
    out_entity = in_entity;
    out_param = in_param;
    out_mote = in_param;
    out_located = lightmap_locate(entities[in_entity], in_position);
    gl_Position = frame.view_proj * vec4(in_position, 1.0);
}
