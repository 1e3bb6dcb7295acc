#version 460
// The engine's G-buffer vertex stage: its own camera block and per-draw push constants.

layout(set = 0, binding = 0, std140) uniform Camera {
    mat4 view;
    mat4 proj; // reversed Z, infinite far plane
} camera;

layout(push_constant) uniform Draw {
    mat4 model;
    vec4 tint_material; // rgb tint, w material index
    vec4 brdf;          // xyz packed BRDF parameters, w BRDF model id
} draw;

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;

layout(location = 0) out vec3 out_normal;
#ifndef COMPACT
// histencil's layout stores linear depth; the compact one reads the depth attachment instead.
layout(location = 1) out float out_linear_depth;
#endif

void main() {
    vec4 world = draw.model * vec4(in_position, 1.0);
    vec4 view = camera.view * world;
    out_normal = transpose(inverse(mat3(draw.model))) * in_normal;
#ifndef COMPACT
    out_linear_depth = -view.z;
#endif
    gl_Position = camera.proj * view;
}
