#version 460
// Mesh vertex stage of the G-buffer and forward passes.
#include "frame.glsl"
#include "draw.glsl"

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;

layout(location = 0) out vec3 out_world_position;
layout(location = 1) out vec3 out_world_normal;
layout(location = 2) out float out_linear_depth;

void main() {
    vec4 world = draw.model * vec4(in_position, 1.0);
    vec4 view = frame.view * world;
    out_world_position = world.xyz;
    out_world_normal = transpose(inverse(mat3(draw.model))) * in_normal;
    out_linear_depth = -view.z;
    gl_Position = frame.proj * view;
}
