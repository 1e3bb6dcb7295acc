#version 460
// G-buffer pass: stores the surface for the deferred light shaders, through the same contract an
// engine's G-buffer shader writes (include/gbuffer_write.glsl). The BRDF slot also goes into the
// stencil BRDF bits, through the draw's dynamic stencil reference.
#include "draw.glsl"
#include "gbuffer_write.glsl"

layout(location = 0) in vec3 in_world_position;
layout(location = 1) in vec3 in_world_normal;
layout(location = 2) in float in_linear_depth;

layout(location = 0) out vec4 out_albedo;
layout(location = 1) out vec4 out_normal_depth;
layout(location = 2) out vec4 out_material;

void main() {
    Surface s = surface_from_draw(in_world_position, in_world_normal);
    GBufferTexel t = gbuffer_encode(s.tint, s.normal, in_linear_depth, s.params.xyz, s.brdf,
                                    uint(draw.tint.w));
    out_albedo = t.albedo;
    out_normal_depth = t.normal_depth;
    out_material = t.material;
}
