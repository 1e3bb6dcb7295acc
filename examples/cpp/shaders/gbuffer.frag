#version 460
// The engine's G-buffer fragment stage: histencil's G-buffer contract, written through its
// gbuffer_encode (share/histencil/shaders/include/gbuffer_write.glsl). The stencil (each BRDF's
// slot) is the pipeline's, set per draw from histencil_lighting_stencil_reference.
#extension GL_GOOGLE_include_directive : require
#include "gbuffer_write.glsl"

layout(push_constant) uniform Draw {
    mat4 model;
    vec4 tint_material;
    vec4 brdf;
} draw;

layout(location = 0) in vec3 in_normal;
layout(location = 1) in float in_linear_depth;

layout(location = 0) out vec4 out_albedo;
layout(location = 1) out vec4 out_normal_depth;
layout(location = 2) out vec4 out_material;

void main() {
    GBufferTexel t = gbuffer_encode(draw.tint_material.rgb, normalize(in_normal), in_linear_depth,
                                    draw.brdf.xyz, uint(draw.brdf.w), uint(draw.tint_material.w));
    out_albedo = t.albedo;
    out_normal_depth = t.normal_depth;
    out_material = t.material;
}
