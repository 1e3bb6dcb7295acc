// The engine's decode hook: histencil's light shaders read each pixel's surface from the
// engine's compact G-buffer (compact_gbuffer.glsl) and its depth attachment, through the
// engine's own descriptor set (set 1). histencil_build compiles the light shaders with this file
// in place of histencil's own (build.rs).
#ifndef SURFACE_DECODE_GLSL
#define SURFACE_DECODE_GLSL

#include "frame.glsl"
#include "surface.glsl"
#include "compact_gbuffer.glsl"

#extension GL_EXT_samplerless_texture_functions : require

layout(set = 1, binding = 0) uniform texture2D compact_albedo;
layout(set = 1, binding = 1) uniform texture2D compact_normal_params;
// The depth aspect of the depth-stencil attachment, which histencil keeps read-only (depth) while
// its light passes test and write stencil.
layout(set = 1, binding = 2) uniform texture2D scene_depth;

bool decode_surface(vec2 frag_coord, out Surface s) {
    ivec2 px = ivec2(frag_coord);
    float depth = texelFetch(scene_depth, px, 0).r;
    vec4 albedo = texelFetch(compact_albedo, px, 0);
    vec4 normal_params = texelFetch(compact_normal_params, px, 0);
    // Device depth to -z in view space, for any perspective projection: depth = P22 + P32 / -z
    // with -z = linear depth (reversed or not, finite or infinite far plane).
    float linear_depth = frame.proj[3][2] / (depth + frame.proj[2][2]);
    s.position = world_position_on_ray(frag_coord, linear_depth);
    s.normal = octahedral_decode(normal_params.xy);
    s.tint = albedo.rgb;
    s.brdf = uint(round(albedo.a * 255.0));
    float scale = compact_param_scale(s.brdf);
    s.params = vec4(normal_params.zw * scale, 1.0, 0.0);
    return depth != frame.settings.y;
}

// This engine uses no BRDF tables.
uint decode_lut_material(vec2 frag_coord) {
    return 0u;
}

#endif
