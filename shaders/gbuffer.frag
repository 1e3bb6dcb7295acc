#version 460
// G-buffer pass: stores the surface for the deferred light shaders (layout: include/gbuffer.glsl).
// The BRDF id also goes into the stencil BRDF bits, through the draw's dynamic stencil reference.
#include "draw.glsl"

layout(location = 0) in vec3 in_world_position;
layout(location = 1) in vec3 in_world_normal;
layout(location = 2) in float in_linear_depth;

layout(location = 0) out vec4 out_albedo;
layout(location = 1) out vec4 out_normal_depth;
layout(location = 2) out vec4 out_material;

void main() {
    Surface s = surface_from_draw(in_world_position, in_world_normal);
    out_albedo = vec4(s.tint, draw.tint.w);
    out_normal_depth = vec4(s.normal, in_linear_depth);
    out_material = vec4(s.params.xyz, float(s.brdf));
}
