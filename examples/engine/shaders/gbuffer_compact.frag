#version 460
// The engine's G-buffer fragment stage for its own compact layout (compact_gbuffer.glsl).
#extension GL_GOOGLE_include_directive : require
#include "histencil_hooks/compact_gbuffer.glsl"

layout(push_constant) uniform Draw {
    mat4 model;
    vec4 tint_material;
    vec4 brdf;
} draw;

layout(location = 0) in vec3 in_normal;

layout(location = 0) out vec4 out_albedo;
layout(location = 1) out vec4 out_normal_params;

void main() {
    uint model = uint(draw.brdf.w);
    float scale = compact_param_scale(model);
    out_albedo = vec4(draw.tint_material.rgb, float(model) / 255.0);
    out_normal_params = vec4(octahedral_encode(normalize(in_normal)), draw.brdf.xy / scale);
}
