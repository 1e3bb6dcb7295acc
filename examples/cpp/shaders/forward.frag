#version 460
// The engine's forward reference: every light at every pixel of every draw, shaded by
// histencil's own light code (light.glsl, reading set 0 as histencil_shading_inputs wrote it).
// It builds the Surface exactly as histencil's deferred passes rebuild it from the G-buffer
// (gbuffer.glsl's gbuffer_load), so the two differ only by the HDR target's additive rounding:
//   position  on this pixel's view ray at the linear depth the G-buffer stores (the same
//             interpolated value: scene.vert is shared), not the interpolated world position;
//   normal    normalize(in_normal), stored in f32 by the G-buffer pass;
//   tint      through f16, as the albedo target (R16G16B16A16_SFLOAT) stores it;
//   params    the packed BRDF parameters, stored in f32, w = 0 as gbuffer_load sets it.
#extension GL_GOOGLE_include_directive : require
#include "light.glsl"

layout(push_constant) uniform Draw {
    mat4 model;
    vec4 tint_material;
    vec4 brdf;
} draw;

layout(location = 0) in vec3 in_normal;
layout(location = 1) in float in_linear_depth;

layout(location = 0) out vec4 out_color;

vec3 through_f16(vec3 v) {
    return vec3(unpackHalf2x16(packHalf2x16(v.xy)), unpackHalf2x16(packHalf2x16(v.zz)).x);
}

void main() {
    Surface s;
    s.position = world_position_on_ray(gl_FragCoord.xy, in_linear_depth);
    s.normal = normalize(in_normal);
    s.tint = through_f16(draw.tint_material.rgb);
    s.params = vec4(draw.brdf.xyz, 0.0);
    s.brdf = uint(draw.brdf.w);
    vec3 sum = vec3(0.0);
    for (uint i = 0u; i < frame.counts.x; ++i) {
        sum += shade_light(lights[i], s);
    }
    out_color = vec4(sum, 0.0);
}
