#version 460
// G-buffer pass: stores the surface for the deferred light shaders, through the same contract an
// engine's G-buffer shader writes (include/gbuffer_write.glsl). The BRDF slot also goes into the
// stencil BRDF bits, through the draw's dynamic stencil reference. Textures are read here, once
// per pixel (include/material.glsl); the light passes read the textured surface back.
#include "material.glsl"
#include "gbuffer_write.glsl"

layout(location = 0) in vec3 in_world_position;
layout(location = 1) in vec3 in_world_normal;
layout(location = 2) in float in_linear_depth;
layout(location = 3) in vec4 in_uv;
layout(location = 4) in vec4 in_world_tangent;
layout(location = 5) in vec4 in_color;

layout(location = 0) out vec4 out_albedo;
layout(location = 1) out vec4 out_normal_depth;
layout(location = 2) out vec4 out_material;

void main() {
    if (material_masked(in_uv, in_color)) {
        discard;
    }
    Surface s = surface_from_material(in_world_position, in_world_normal, in_uv,
                                      in_world_tangent, in_color, gl_FrontFacing);
    GBufferTexel t = gbuffer_encode(s.tint, s.normal, in_linear_depth, s.params.xyz, s.brdf,
                                    uint(draw.tint.w));
    out_albedo = t.albedo;
    out_normal_depth = t.normal_depth;
    out_material = t.material;
}
