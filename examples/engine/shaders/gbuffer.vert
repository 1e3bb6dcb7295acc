#version 460
// The engine's G-buffer vertex stage: its own camera block and per-draw push constants. Built
// three ways (build.rs): for histencil's G-buffer, for the compact one (-DCOMPACT), and for the
// forward reference (-DFORWARD), which rebuilds its position from depth as the decode hook does.

#ifdef FORWARD
// The forward reference binds histencil's frame layout at set 0 (its fragment stage shades
// through light.glsl); its view and proj are the camera.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
#define camera frame
#else
layout(set = 0, binding = 0, std140) uniform Camera {
    mat4 view;
    mat4 proj; // reversed Z, infinite far plane
} camera;
#endif

layout(push_constant) uniform Draw {
    mat4 model;
    vec4 tint_material; // rgb tint, w material index
    vec4 brdf;          // xyz packed BRDF parameters, w BRDF model id
} draw;

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;

layout(location = 0) out vec3 out_normal;
#if !defined(FORWARD) && !defined(COMPACT)
// histencil's layout stores linear depth; the compact one reads the depth attachment instead.
layout(location = 1) out float out_linear_depth;
#endif

void main() {
    vec4 world = draw.model * vec4(in_position, 1.0);
    vec4 view = camera.view * world;
    out_normal = transpose(inverse(mat3(draw.model))) * in_normal;
#if !defined(FORWARD) && !defined(COMPACT)
    out_linear_depth = -view.z;
#endif
    gl_Position = camera.proj * view;
}
