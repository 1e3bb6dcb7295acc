#version 460
// Forward reference: every fragment evaluates its own BRDF for every light, with the same light
// code as the deferred pass and the same textured surface as the G-buffer pass. Ground truth for
// every error figure. Emitted light is added once, before the lights.
#include "light.glsl"
#include "material.glsl"

layout(location = 0) in vec3 in_world_position;
layout(location = 1) in vec3 in_world_normal;
layout(location = 2) in float in_linear_depth;
layout(location = 3) in vec4 in_uv;
layout(location = 4) in vec4 in_world_tangent;
layout(location = 5) in vec4 in_color;

layout(location = 0) out vec4 out_color;

void main() {
    if (material_masked(in_uv, in_color)) {
        discard;
    }
    // Lit at the point the deferred passes rebuild from the G-buffer's depth (frame.glsl).
    vec3 position = world_position_on_ray(gl_FragCoord.xy, in_linear_depth);
    Surface s = surface_from_material(position, in_world_normal, in_uv, in_world_tangent,
                                      in_color, gl_FrontFacing);
    vec3 sum = material_emissive(in_uv);
    for (uint i = 0; i < frame.counts.x; ++i) {
        sum += shade_light(lights[i], s);
    }
    out_color = vec4(sum, 0.0);
}
