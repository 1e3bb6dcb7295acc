// Set 0, shared by every pass: per-frame uniforms and the scene's lights.
// Rust mirror: crates/vk/src/gpu/gpu_types.rs (FrameUniforms, GpuLight); layout: descriptors.rs.
#ifndef FRAME_GLSL
#define FRAME_GLSL

#include "generated.glsl"
#include "brdf/common.glsl"

layout(set = 0, binding = 0, std140) uniform Frame {
    mat4 view;
    mat4 proj;
    mat4 view_proj;
    mat4 inv_view;
    vec4 eye;        // xyz: camera position
    vec4 viewport;   // width, height, 1/width, 1/height
    vec4 projection; // (1/P00, 1/P11, P20, P21): view.xy / -view.z = (ndc.xy + zw) * xy
    vec4 settings;   // x: exposure, y: the far plane's depth (1, or 0 with reversed Z)
    uvec4 counts;    // x: number of lights
} frame;

struct Light {
    vec4 position_radius; // xyz position, w range (contribution is zero at and beyond it)
    vec4 color_kind;      // rgb radiance scale, w: LIGHT_* kind
    vec4 direction;       // xyz normalized direction the light travels (spot, directional)
    vec4 spot;            // x cos(outer), y cos(inner), z tan(outer)
};

layout(set = 0, binding = 1, std430) readonly buffer Lights {
    Light lights[];
};

#endif
