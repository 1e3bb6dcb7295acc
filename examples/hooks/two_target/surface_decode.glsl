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
//                         rgb the tint, a the material index / 255 (0 to 255)
//   binding 2  texture2D  the depth-stencil image's depth aspect, through a depth-only view,
//                         in DEPTH_READ_ONLY_STENCIL_ATTACHMENT_OPTIMAL
//   binding 3  uniform    one row per material (histencil_brdf::MaterialRows::bytes): its BRDF
//                         id and parameters, so two materials of one BRDF keep their own
//                         roughness; TWO_TARGET_MATERIALS rows, 8 KiB
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
layout(set = 1, binding = 1) uniform texture2D two_target_tint_material;
layout(set = 1, binding = 2) uniform texture2D two_target_depth;
// One row per material, indexed by the material index target 1 carries: said to histencil as
// BrdfParams::Materials. A row is 32 bytes in std140 as in histencil_brdf::MaterialRows::bytes;
// an 8-bit index names at most 256, so every index the G-buffer can hold has a row (8 KiB, within
// the 16 KiB uniform range every device binds). Rows past the engine's materials are zeros.
#define TWO_TARGET_MATERIALS 256
struct TwoTargetMaterial {
    vec4 params; // Brdf::packed_params
    uvec4 brdf;  // x: BrdfId::index
};
layout(set = 1, binding = 3, std140) uniform TwoTargetMaterials {
    TwoTargetMaterial rows[TWO_TARGET_MATERIALS];
} two_target_materials;

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
    vec4 tint_material = texelFetch(two_target_tint_material, px, 0);
    // Device depth to linear depth (-z in view space) for any perspective projection, standard
    // or reversed Z, finite or infinite far plane: depth = -P22 + P32 / linear_depth.
    float linear_depth = frame.proj[3][2] / (depth + frame.proj[2][2]);
    s.position = world_position_on_ray(frag_coord, linear_depth);
    s.normal = two_target_octahedral_decode(texelFetch(two_target_normal, px, 0).rg);
    s.tint = tint_material.rgb;
    TwoTargetMaterial row = two_target_materials.rows[uint(round(tint_material.a * 255.0))];
    s.brdf = row.brdf.x;
    s.params = row.params;
    return true;
}

// The LUT technique's table: one per material, so the material index names it (an engine that
// makes tables makes them from MaterialRows::materials, in that order: LutTables).
uint decode_lut_material(vec2 frag_coord) {
    return uint(round(texelFetch(two_target_tint_material, ivec2(frag_coord), 0).a * 255.0));
}

#endif
