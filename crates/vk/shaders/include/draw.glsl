// Per-draw push constants of the mesh passes (G-buffer, forward).
// Rust mirror: crates/vk/src/passes/geometry.rs (DrawPush).
#ifndef DRAW_GLSL
#define DRAW_GLSL

#include "surface.glsl"

layout(push_constant) uniform Draw {
    mat4 model;
    vec4 tint;   // rgb tint, w material index (the LUT technique's table)
    vec4 params; // xyz the BRDF's packed parameters (histencil_brdf::Brdf::packed_params), w id
} draw;

Surface surface_from_draw(vec3 world_position, vec3 world_normal) {
    Surface s;
    s.position = world_position;
    s.normal = normalize(world_normal);
    s.tint = draw.tint.rgb;
    s.params = vec4(draw.params.xyz, 0.0);
    s.brdf = uint(draw.params.w);
    return s;
}

#endif
