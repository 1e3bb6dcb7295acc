// The engine's own compact G-buffer: 12 bytes per pixel in two targets, depth from the depth
// attachment (histencil's own layout is 40 bytes plus depth). Written by gbuffer_compact.frag,
// read by the decode hook (histencil_hooks/surface_decode.glsl) that histencil's light shaders
// are compiled with.
//
//   target 0  R8G8B8A8_UNORM      rgb: tint (linear, in [0, 1]); a: BRDF model id / 255
//   target 1  R16G16B16A16_UNORM  xy: octahedral unit normal; zw: the BRDF's first two packed
//                                 parameters divided by compact_param_scale
//
// The third packed parameter (GGX's f90, the toon ramp's albedo, the sheen's strength) is 1 for
// every material of this engine, so it is not stored. Clear: all zeros (the depth attachment's far plane marks "no geometry").
#ifndef COMPACT_GBUFFER_GLSL
#define COMPACT_GBUFFER_GLSL

#include "generated.glsl"
// The engine's own BRDFs' ids (BRDF_ENGINE_*), from its BRDF set (build.rs).
#include "brdf_set/ids.glsl"

// Parameters are stored in [0, 1]: Blinn-Phong's exponent is divided by 2048 and the toon
// ramp's band count and edge by 8; the others are already there (Lambert rho, Oren-Nayar rho
// and sigma, GGX alpha and f0, the sheen's base albedo and roughness).
float compact_param_scale(uint model) {
    if (model == BRDF_ENGINE_TOON) {
        return 8.0;
    }
    return model == BRDF_BLINN_PHONG ? 2048.0 : 1.0;
}

float sign_not_zero(float v) {
    return v >= 0.0 ? 1.0 : -1.0;
}

// A unit vector on the octahedron, unfolded to [0, 1]^2.
vec2 octahedral_encode(vec3 n) {
    n /= abs(n.x) + abs(n.y) + abs(n.z);
    vec2 e = n.z >= 0.0 ? n.xy : (1.0 - abs(n.yx)) * vec2(sign_not_zero(n.x), sign_not_zero(n.y));
    return e * 0.5 + 0.5;
}

vec3 octahedral_decode(vec2 f) {
    f = f * 2.0 - 1.0;
    vec3 n = vec3(f, 1.0 - abs(f.x) - abs(f.y));
    float t = clamp(-n.z, 0.0, 1.0);
    n.xy += vec2(n.x >= 0.0 ? -t : t, n.y >= 0.0 ? -t : t);
    return normalize(n);
}

// What the deferred path reads back for a surface written with these values: each stored field
// rounded to its format's steps as a UNORM write rounds (to nearest; Vulkan lets a device pick
// either neighbour, a step of 1/255 in tint or 1/65535 elsewhere). For the forward reference.
#ifdef SURFACE_GLSL
Surface compact_round_trip(vec3 position, vec3 unit_normal, vec3 tint, vec2 params, uint model) {
    float scale = compact_param_scale(model);
    Surface s;
    s.position = position;
    s.normal = octahedral_decode(round(octahedral_encode(unit_normal) * 65535.0) / 65535.0);
    s.tint = round(clamp(tint, 0.0, 1.0) * 255.0) / 255.0;
    s.params = vec4(round(clamp(params / scale, 0.0, 1.0) * 65535.0) / 65535.0 * scale, 1.0, 0.0);
    s.brdf = model;
    return s;
}
#endif

#endif
