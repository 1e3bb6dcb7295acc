// The tiled technique's light lists (tile_lights.comp): the light's screen rectangle of tiles,
// each tile's view-space box, and the test of a light against it. Needs TILED_TILE, the tile
// side, defined before it is included.
#ifndef TILE_LIGHTS_GLSL
#define TILE_LIGHTS_GLSL
#include "frame.glsl"
#include "tiled.glsl"

// The view-space position at linear depth `d` on the ray through framebuffer point `p`.
vec3 view_point(vec2 p, float d) {
    vec2 ndc = p * frame.viewport.zw * 2.0 - 1.0;
    return vec3((ndc + frame.projection.zw) * frame.projection.xy, -1.0) * d;
}

// Whether `light` can light anything in the view-space box [lo, hi]: directional lights reach
// everything; point and spot lights are zero beyond their range sphere.
bool reaches(Light light, vec3 lo, vec3 hi) {
    if (uint(light.color_kind.w) == LIGHT_DIRECTIONAL) {
        return true;
    }
    vec3 centre = (frame.view * vec4(light.position_radius.xyz, 1.0)).xyz;
    vec3 nearest = clamp(centre, lo, hi);
    vec3 d = centre - nearest;
    // A margin against rounding: a light that misses by less is kept (it adds zero).
    float r = light.position_radius.w * (1.0 + 1e-4) + 1e-4;
    return dot(d, d) <= r * r;
}

// The view-space box of the pixel footprints of tile `t` between linear depths `near_bits` and
// `far_bits` (float bits).
void tile_box(uvec2 t, uint near_bits, uint far_bits, out vec3 lo, out vec3 hi) {
    float near = uintBitsToFloat(near_bits);
    float far = uintBitsToFloat(far_bits);
    vec2 p0 = vec2(t * TILED_TILE);
    vec2 p1 = min(p0 + vec2(TILED_TILE), frame.viewport.xy);
    lo = vec3(3.0e38);
    hi = vec3(-3.0e38);
    for (uint c = 0u; c < 8u; ++c) {
        vec2 p = vec2((c & 1u) != 0u ? p1.x : p0.x, (c & 2u) != 0u ? p1.y : p0.y);
        vec3 v = view_point(p, (c & 4u) != 0u ? far : near);
        lo = min(lo, v);
        hi = max(hi, v);
    }
}

// The framebuffer point that view-space point `v` (in front of the eye) projects to: the
// inverse of `view_point`.
vec2 framebuffer_point(vec3 v) {
    vec2 ndc = v.xy / (-v.z * frame.projection.xy) - frame.projection.zw;
    return (ndc + 1.0) * 0.5 * frame.viewport.xy;
}

// The tiles [t0, t1) that can hold a pixel whose surface `light` reaches: every tile for a
// directional light and for one whose range box reaches the eye's plane, none for one wholly
// behind it (every visible surface is in front); else the rectangle round the projected
// corners of the box round its range sphere (the sphere's projection lies inside), a pixel
// wider on each side. Outside it a light adds exactly zero.
void light_tiles(Light light, out uvec2 t0, out uvec2 t1) {
    t0 = uvec2(0u);
    t1 = uvec2(tiled.tiles_x, tiled.tiles / tiled.tiles_x);
    if (uint(light.color_kind.w) == LIGHT_DIRECTIONAL) {
        return;
    }
    vec3 centre = (frame.view * vec4(light.position_radius.xyz, 1.0)).xyz;
    float r = light.position_radius.w * (1.0 + 1e-4) + 1e-4;
    if (centre.z - r > 0.0) {
        t1 = t0;
        return;
    }
    if (centre.z + r >= -1e-6) {
        return;
    }
    vec2 lo = vec2(3.0e38);
    vec2 hi = vec2(-3.0e38);
    for (uint c = 0u; c < 8u; ++c) {
        vec3 corner = centre + r * vec3((c & 1u) != 0u ? 1.0 : -1.0, (c & 2u) != 0u ? 1.0 : -1.0,
                                        (c & 4u) != 0u ? 1.0 : -1.0);
        vec2 p = framebuffer_point(corner);
        lo = min(lo, p);
        hi = max(hi, p);
    }
    // Clamped in floats first: a box just in front of the eye projects far off screen.
    vec2 size = frame.viewport.xy;
    lo = clamp(floor(lo) - 1.0, vec2(0.0), size);
    hi = clamp(ceil(hi) + 1.0, vec2(0.0), size);
    t0 = min(uvec2(lo) / TILED_TILE, t1);
    t1 = min(uvec2(hi) / TILED_TILE + 1u, t1);
}

#endif
