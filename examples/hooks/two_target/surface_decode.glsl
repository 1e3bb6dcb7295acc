// The decode hook of a two-target G-buffer, as the book's engine chapter builds it
// (docs/src/engine/hooks.md). histencil_build::compile_light_shaders compiles histencil's light
// shaders with this folder's files in place of histencil's own hooks; the light shaders call
// decode_surface for every lit pixel and decode_lut_material for the LUT technique.
//
// Reads, all in set 1 (the engine's decode layout, each binding visible to FRAGMENT and COMPUTE):
//   binding 0  texture2D  G-buffer target 0, R16G16_UNORM: the world-space unit normal,
//                         octahedral, unfolded to [0, 1]^2 (with R16G16_SNORM, drop the
//                         `* 2.0 - 1.0` in two_target_octahedral_decode)
//   binding 1  texture2D  G-buffer target 1, R8G8B8A8_UNORM (or _SRGB: alpha stays linear):
//                         rgb the tint, a the BRDF id / 255 (histencil_brdf::BrdfId::index)
//   binding 2  texture2D  the depth-stencil image's depth aspect, through a depth-only view,
//                         in DEPTH_READ_ONLY_STENCIL_ATTACHMENT_OPTIMAL
//   binding 3  uniform    the packed parameters of each BRDF id (histencil_brdf::Brdf::
//                         packed_params): every surface of a BRDF shares them, its tint varies
// The surface formats given to EngineHooks::new, in LightingTargets::gbuffer order:
// [R16G16_UNORM, R8G8B8A8_UNORM]. The depth-stencil is LightingTargets::depth_stencil, not one.
// No geometry where depth still holds its clear value, the far plane's (frame.settings.y).
#ifndef SURFACE_DECODE_GLSL
#define SURFACE_DECODE_GLSL

// texelFetch on a texture2D with no sampler.
#extension GL_EXT_samplerless_texture_functions : require

#include "frame.glsl"   // set 0: the camera (frame.proj, frame.settings, world_position_on_ray)
#include "surface.glsl" // struct Surface

layout(set = 1, binding = 0) uniform texture2D two_target_normal;
layout(set = 1, binding = 1) uniform texture2D two_target_tint_brdf;
layout(set = 1, binding = 2) uniform texture2D two_target_depth;
// One row per BRDF id (BrdfId::index), each Brdf::packed_params as four floats: BRDF_ID_COUNT
// rows, every id of the set the light shaders are compiled for (8 for histencil's own, more
// with engine BRDFs), said to histencil as BrdfParams::Rows(BRDF_ID_COUNT).
#include "brdf_set/ids.glsl"
#define TWO_TARGET_BRDF_ROWS BRDF_ID_COUNT
layout(set = 1, binding = 3, std140) uniform TwoTargetBrdfs {
    vec4 packed_params[TWO_TARGET_BRDF_ROWS];
} two_target_brdfs;

// The unit vector whose octahedral encoding, unfolded to [0, 1]^2, is `f`.
vec3 two_target_octahedral_decode(vec2 f) {
    f = f * 2.0 - 1.0;
    vec3 n = vec3(f, 1.0 - abs(f.x) - abs(f.y));
    float t = clamp(-n.z, 0.0, 1.0);
    n.xy += vec2(n.x >= 0.0 ? -t : t, n.y >= 0.0 ? -t : t);
    return normalize(n);
}

bool decode_surface(vec2 frag_coord, out Surface s) {
    ivec2 px = ivec2(frag_coord);
    float depth = texelFetch(two_target_depth, px, 0).r;
    if (depth == frame.settings.y) {
        return false; // nothing drawn here: s is not read
    }
    vec4 tint_brdf = texelFetch(two_target_tint_brdf, px, 0);
    // Device depth to linear depth (-z in view space) for any perspective projection, standard
    // or reversed Z, finite or infinite far plane: depth = -P22 + P32 / linear_depth.
    float linear_depth = frame.proj[3][2] / (depth + frame.proj[2][2]);
    s.position = world_position_on_ray(frag_coord, linear_depth);
    s.normal = two_target_octahedral_decode(texelFetch(two_target_normal, px, 0).rg);
    s.tint = tint_brdf.rgb;
    s.brdf = uint(round(tint_brdf.a * 255.0));
    s.params = two_target_brdfs.packed_params[min(s.brdf, TWO_TARGET_BRDF_ROWS - 1u)];
    return true;
}

// This engine makes no BRDF tables (the LUT technique): every pixel is table 0.
uint decode_lut_material(vec2 frag_coord) {
    return 0u;
}

#endif
