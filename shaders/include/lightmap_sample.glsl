// Sampling an alpha entity's light from the lightmap atlas, for any alpha shader: histencil's
// own alpha pass and an engine's. The atlas is the colour image AlphaLightmaps::record lit (bound
// as a sampled image in SHADER_READ_ONLY_OPTIMAL); the entity is its AlphaEntity record. The
// result is the radiance towards the viewer that the entity's own BRDF reflects at the probe
// (the talk's lightmap): multiply by coverage and blend.
//
// Reads are bilinear inside one tile of the entity's region, clamped to the tile, so no texel
// of a neighbour (or of the guard band) ever leaks in.
#ifndef LIGHTMAP_SAMPLE_GLSL
#define LIGHTMAP_SAMPLE_GLSL

#extension GL_EXT_samplerless_texture_functions : require

#include "alpha_entity.glsl"

// Tile `tile` of the entity's region at uv in [0, 1]^2 (texel centres at (i + 0.5) / size).
vec3 lightmap_tile(texture2D atlas, AlphaEntity e, uint tile, vec2 uv) {
    vec2 size = vec2(e.region.zw);
    vec2 t = clamp(uv * size - 0.5, vec2(0.0), size - 1.0);
    ivec2 i0 = ivec2(floor(t));
    vec2 f = t - vec2(i0);
    ivec2 i1 = min(i0 + 1, ivec2(e.region.zw) - 1);
    ivec2 origin = ivec2(e.region.xy) + ivec2(int(tile * e.region.z), 0);
    vec3 a = texelFetch(atlas, origin + ivec2(i0.x, i0.y), 0).rgb;
    vec3 b = texelFetch(atlas, origin + ivec2(i1.x, i0.y), 0).rgb;
    vec3 c = texelFetch(atlas, origin + ivec2(i0.x, i1.y), 0).rgb;
    vec3 d = texelFetch(atlas, origin + ivec2(i1.x, i1.y), 0).rgb;
    return mix(mix(a, b, f.x), mix(c, d, f.x), f.y);
}

// A translucent object's light at `uv`, its mesh's lightmap UV (the layout it was baked in).
vec3 lightmap_object(texture2D atlas, AlphaEntity e, vec2 uv) {
    return lightmap_tile(atlas, e, 0u, uv);
}

// A particle's light from its system's lightmap. P: the fragment's world position; param: the
// dust mote's index (flat: an interpolated copy may round off) or the position along a ribbon
// in [0, 1]; unused for billboards and slices.
vec3 lightmap_particle(texture2D atlas, AlphaEntity e, vec3 P, float param) {
    uint kind = e.shape.x;
    if (kind == ALPHA_DUST) {
        uint i = uint(param);
        ivec2 texel = ivec2(e.region.xy) + ivec2(int(i % e.region.z), int(i / e.region.z));
        return texelFetch(atlas, texel, 0).rgb;
    }
    if (kind == ALPHA_RIBBON) {
        return lightmap_tile(atlas, e, 0u, vec2(param, 0.5));
    }
    vec3 located = frame_locate(e, P);
    uint k0 = uint(floor(located.z));
    uint k1 = min(k0 + 1u, e.shape.y - 1u);
    vec3 a = lightmap_tile(atlas, e, k0, located.xy);
    vec3 b = lightmap_tile(atlas, e, k1, located.xy);
    return mix(a, b, located.z - float(k0));
}

#endif
