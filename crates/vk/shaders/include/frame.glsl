// Set 0, shared by every pass: per-frame uniforms and the scene's lights. Rust mirror:
// crates/vk/src/gpu/frame/gpu_types.rs (FrameUniforms, GpuLight); layout:
// gpu/device/descriptors.rs.
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
    vec4 direction;       // xyz normalized direction the light travels (spot, directional),
                          // w: LIGHT_FALLOFF_* (histencil_scene::Falloff)
    vec4 spot;            // x cos(outer), y cos(inner), z tan(outer)
};

layout(set = 0, binding = 1, std430) readonly buffer Lights {
    Light lights[];
};

// The world-space point at `linear_depth` (-z in view space) on the view ray through
// `frag_coord` (gl_FragCoord.xy). The deferred passes rebuild every surface position this way
// from the G-buffer's depth, and the forward reference rebuilds its own the same way from the
// same interpolated depth instead of interpolating the world position: a rasteriser snaps
// vertices to its sub-pixel grid (the spec's minimum is 4 bits), so an interpolated position is
// a point on the snapped triangle, off the pixel's true view ray by up to 1/16 of a pixel's
// footprint, while the rebuilt one lies on the ray. Lit from two different points, forward and
// deferred differed by up to 21/255 on SwiftShader (4 bits); sharing the computation leaves
// them the same point on every rasteriser.
vec3 world_position_on_ray(vec2 frag_coord, float linear_depth) {
    vec2 ndc = frag_coord * frame.viewport.zw * 2.0 - 1.0;
    vec3 view_position = vec3((ndc + frame.projection.zw) * frame.projection.xy, -1.0) * linear_depth;
    return (frame.inv_view * vec4(view_position, 1.0)).xyz;
}

#endif
