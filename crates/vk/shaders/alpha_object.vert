#version 460
// Translucent objects in the alpha pass.
#include "alpha.glsl"

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;

layout(location = 0) out vec3 out_world_position;
layout(location = 1) out vec3 out_world_normal;
layout(location = 2) out vec2 out_uv;

void main() {
    mat4 model = entities[alpha_draw.entity].model;
    vec4 world = model * vec4(in_position, 1.0);
    out_world_position = world.xyz;
    out_world_normal = transpose(inverse(mat3(model))) * in_normal;
    out_uv = in_uv;
    gl_Position = frame.view_proj * world;
}
