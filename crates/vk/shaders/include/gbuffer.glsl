// The G-buffer read back by the deferred light shaders (set 1). Its layout is the contract in
// gbuffer_write.glsl, which histencil's G-buffer pass and an engine's write through.
// Float formats keep the deferred path within 1/255 of the forward reference: parameters are
// stored exactly as the forward pass reads them. What compact encodings would add is measured by
// `histencil brdf-report` (histencil_brdf::encoding).
#ifndef GBUFFER_GLSL
#define GBUFFER_GLSL

#include "frame.glsl"
#include "surface.glsl"

#extension GL_EXT_samplerless_texture_functions : require

// Sampled images read with texelFetch: no sampler, no filtering, exactly one texel.
layout(set = 1, binding = 0) uniform texture2D gbuffer_albedo;
layout(set = 1, binding = 1) uniform texture2D gbuffer_normal_depth;
layout(set = 1, binding = 2) uniform texture2D gbuffer_material;

// Reads the surface under pixel `frag_coord` (gl_FragCoord.xy: the pixel centre). Returns false
// where no geometry was drawn.
bool gbuffer_load(vec2 frag_coord, out Surface s) {
    ivec2 px = ivec2(frag_coord);
    vec4 normal_depth = texelFetch(gbuffer_normal_depth, px, 0);
    float linear_depth = normal_depth.w;
    vec4 albedo = texelFetch(gbuffer_albedo, px, 0);
    vec4 material = texelFetch(gbuffer_material, px, 0);
    s.position = world_position_on_ray(frag_coord, linear_depth);
    s.normal = normal_depth.xyz;
    s.tint = albedo.rgb;
    s.params = vec4(material.xyz, 0.0);
    s.brdf = uint(material.w);
    return linear_depth > 0.0;
}

// The material index of the surface under pixel `frag_coord`.
uint gbuffer_material_index(vec2 frag_coord) {
    return uint(texelFetch(gbuffer_albedo, ivec2(frag_coord), 0).a);
}

#endif
