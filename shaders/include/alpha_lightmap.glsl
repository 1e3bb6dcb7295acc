// Sampling the lightmap atlas in the alpha pass: bilinear inside one tile of an entity's region,
// clamped to the tile so no texel of a neighbour (or of the guard band) ever leaks in.
#ifndef ALPHA_LIGHTMAP_GLSL
#define ALPHA_LIGHTMAP_GLSL

#include "alpha.glsl"

layout(set = 2, binding = 0) uniform texture2D lightmap;

// Tile `tile` of the entity's region at uv in [0, 1]^2 (texel centres at (i + 0.5) / size).
vec3 sample_tile(AlphaEntity e, uint tile, vec2 uv) {
    vec2 size = vec2(e.region.zw);
    vec2 t = clamp(uv * size - 0.5, vec2(0.0), size - 1.0);
    ivec2 i0 = ivec2(floor(t));
    vec2 f = t - vec2(i0);
    ivec2 i1 = min(i0 + 1, ivec2(e.region.zw) - 1);
    ivec2 origin = ivec2(e.region.xy) + ivec2(int(tile * e.region.z), 0);
    vec3 a = texelFetch(lightmap, origin + ivec2(i0.x, i0.y), 0).rgb;
    vec3 b = texelFetch(lightmap, origin + ivec2(i1.x, i0.y), 0).rgb;
    vec3 c = texelFetch(lightmap, origin + ivec2(i0.x, i1.y), 0).rgb;
    vec3 d = texelFetch(lightmap, origin + ivec2(i1.x, i1.y), 0).rgb;
    return mix(mix(a, b, f.x), mix(c, d, f.x), f.y);
}

// A particle's lighting from its system's lightmap. P: the fragment's world position; param:
// the dust mote's index or the ribbon position (histencil_alpha::SpriteVertex::param).
vec3 particle_lightmap(AlphaEntity e, vec3 P, float param) {
    uint kind = e.shape.x;
    if (kind == ALPHA_DUST) {
        uint i = uint(param);
        ivec2 texel = ivec2(e.region.xy) + ivec2(int(i % e.region.z), int(i / e.region.z));
        return texelFetch(lightmap, texel, 0).rgb;
    }
    if (kind == ALPHA_RIBBON) {
        return sample_tile(e, 0u, vec2(param, 0.5));
    }
    vec3 located = frame_locate(e, P);
    uint k0 = uint(floor(located.z));
    uint k1 = min(k0 + 1u, e.shape.y - 1u);
    vec3 a = sample_tile(e, k0, located.xy);
    vec3 b = sample_tile(e, k1, located.xy);
    return mix(a, b, located.z - float(k0));
}

#endif
