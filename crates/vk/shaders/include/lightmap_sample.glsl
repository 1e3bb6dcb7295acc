// Sampling an alpha entity's light from the lightmap atlas, for any alpha shader: histencil's
// own alpha pass and an engine's. The atlas is the colour image AlphaLightmaps::record lit (bound
// as a sampled image in SHADER_READ_ONLY_OPTIMAL) with a sampler of linear filtering, no mips and
// clamp-to-edge addressing; the entity is its AlphaEntity record. The result (.rgb) is the
// radiance towards the viewer that the entity's own BRDF reflects at the probe (the talk's
// lightmap): multiply by coverage and blend. With a direction map (record_directional), see
// lightmap_direction below.
//
// Reads are bilinear inside one tile of the entity's region, clamped to the tile, so no texel
// of a neighbour (or of the guard band) ever leaks in.
#ifndef LIGHTMAP_SAMPLE_GLSL
#define LIGHTMAP_SAMPLE_GLSL

#extension GL_EXT_samplerless_texture_functions : require

#include "alpha_entity.glsl"

// Tile `tile` of the entity's region at uv in [0, 1]^2 (texel centres at (i + 0.5) / size),
// filtered by `linear` (bilinear, clamp to edge): the coordinate is clamped to the tile's outer
// texel centres, so the filter never reaches past the tile.
vec4 lightmap_tile_rgba(texture2D atlas, sampler linear, AlphaEntity e, uint tile, vec2 uv) {
    vec2 size = vec2(e.region.zw);
    vec2 t = clamp(uv * size, vec2(0.5), size - 0.5);
    uint columns = tile_columns(e);
    uvec2 cell = uvec2(tile % columns, tile / columns);
    vec2 origin = vec2(e.region.xy + cell * e.region.zw);
    vec2 atlas_size = vec2(textureSize(sampler2D(atlas, linear), 0));
    return textureLod(sampler2D(atlas, linear), (origin + t) / atlas_size, 0.0);
}

vec3 lightmap_tile(texture2D atlas, sampler linear, AlphaEntity e, uint tile, vec2 uv) {
    return lightmap_tile_rgba(atlas, linear, e, tile, uv).rgb;
}

// A translucent object's light at `uv`, its mesh's lightmap UV (the layout it was baked in).
vec3 lightmap_object(texture2D atlas, sampler linear, AlphaEntity e, vec2 uv) {
    return lightmap_tile(atlas, linear, e, 0u, uv);
}

// The same read with all four channels: a direction map's texel at `uv` (bound as `atlas`).
vec4 lightmap_object_rgba(texture2D atlas, sampler linear, AlphaEntity e, vec2 uv) {
    return lightmap_tile_rgba(atlas, linear, e, 0u, uv);
}

// Where a particle system's fragment at world position P sits in its lightmap, before clamping:
// (u, v, slice), affine in P. Computed per vertex and interpolated, it saves the fragment stage
// the work (the alpha pass's sprites are flat, so the interpolation is exact).
vec3 lightmap_locate(AlphaEntity e, vec3 P) {
    vec3 d = P - e.centre_radius.xyz;
    float r = e.centre_radius.w;
    uint n = e.shape.y;
    float s = 0.0;
    if (n > 1u) {
        float half_depth = e.right_depth.w;
        s = (dot(d, e.forward.xyz) + half_depth) / (2.0 * half_depth) * float(n - 1u);
    }
    return vec3(0.5 + 0.5 * dot(d, e.right_depth.xyz) / r, 0.5 - 0.5 * dot(d, e.up.xyz) / r, s);
}

// A particle's light from its system's lightmap, at `located` (lightmap_locate of the
// fragment's world position). param: the dust mote's index (flat: an interpolated copy may round
// off) or the position along a ribbon in [0, 1]; unused for billboards and slices.
// lightmap_particle_at with all four channels: a direction map's texel (bound as `atlas`).
vec4 lightmap_particle_at_rgba(texture2D atlas, sampler linear, AlphaEntity e, vec3 located,
                               float param) {
    uint kind = e.shape.x;
    if (kind == ALPHA_DUST) {
        uint i = uint(param);
        ivec2 texel = ivec2(e.region.xy) + ivec2(int(i % e.region.z), int(i / e.region.z));
        return texelFetch(sampler2D(atlas, linear), texel, 0);
    }
    if (kind == ALPHA_RIBBON) {
        return lightmap_tile_rgba(atlas, linear, e, 0u, vec2(param, 0.5));
    }
    float last = float(e.shape.y - 1u);
    float s = clamp(located.z, 0.0, last);
    uint k0 = uint(floor(s));
    vec4 a = lightmap_tile_rgba(atlas, linear, e, k0, located.xy);
    float f = s - float(k0);
    if (f == 0.0) {
        return a;
    }
    return mix(a, lightmap_tile_rgba(atlas, linear, e, k0 + 1u, located.xy), f);
}

vec3 lightmap_particle_at(texture2D atlas, sampler linear, AlphaEntity e, vec3 located,
                          float param) {
    return lightmap_particle_at_rgba(atlas, linear, e, located, param).rgb;
}

// A particle's light at world position P (lightmap_locate here, in the fragment stage).
vec3 lightmap_particle(texture2D atlas, sampler linear, AlphaEntity e, vec3 P, float param) {
    return lightmap_particle_at(atlas, linear, e, lightmap_locate(e, P), param);
}

// A direction map's texel (read like the atlas, with the same calls) as the dominant direction
// towards the lights, L (unit), and its directionality in [0, 1]: 1 where every light arrives
// from L, towards 0 where lights on opposite sides cancel. False where no light arrives. With a
// direction map the atlas holds the irradiance at the probe (rgb: the sum of incident * N.L
// through the probe's normal), and the reflected light is `irradiance * f_r(N, V, L)` by the
// engine's own BRDF f_r (without its cosine) with its own normal N and view V: exact for one
// light, and for a Lambert surface under any number; histencil's alpha pass takes the undirected
// share as arriving along N (directional_lighting in alpha.glsl).
bool lightmap_direction(vec4 texel, out vec3 L, out float directionality) {
    float length_sum = length(texel.xyz);
    L = vec3(0.0, 0.0, 1.0);
    directionality = 0.0;
    if (texel.w <= 0.0 || length_sum <= 0.0) {
        return false;
    }
    L = texel.xyz / length_sum;
    directionality = clamp(length_sum / texel.w, 0.0, 1.0);
    return true;
}

#endif
