#version 460
// A translucent object's fragment, lit as its pipeline's mode says (its lightmap, forward per
// pixel, or the single probe), premultiplied by its opacity for blending over what lies behind.
#include "alpha_lightmap.glsl"

layout(location = 0) in vec3 in_world_position;
layout(location = 1) in vec3 in_world_normal;
layout(location = 2) in vec2 in_uv;

layout(location = 0) out vec4 out_color;

// How the fragment is lit: forward per pixel, by the single probe, through the direction map, or
// (none) from the lightmap. A pipeline per mode, so the lightmap pipeline carries none of the per-pixel
// reference's code (on a CPU rasteriser the unused branch and its inputs cost as much as the
// lookup). Booleans, as naga reads no specialisation-constant arithmetic.
layout(constant_id = 0) const bool LIT_FORWARD = false;
layout(constant_id = 1) const bool LIT_BY_PROBE = false;
// From the atlas's incident light and the direction map, with the fragment's own BRDF.
layout(constant_id = 2) const bool LIT_DIRECTIONAL = false;

void main() {
    AlphaEntity e = entities[alpha_draw.entity];
    Surface s = alpha_surface(e, in_world_position, normalize(in_world_normal));
    vec3 lit;
    if (LIT_FORWARD) {
        lit = forward_lighting(e, s);
    } else if (LIT_BY_PROBE) {
        lit = probe_lighting(e, s);
    } else if (LIT_DIRECTIONAL) {
        vec3 irradiance = lightmap_object(lightmap, lightmap_sampler, e, in_uv);
        vec4 direction = lightmap_object_rgba(direction_map, lightmap_sampler, e, in_uv);
        lit = directional_lighting(s, normalize(frame.eye.xyz - s.position), irradiance, direction);
    } else {
        lit = lightmap_object(lightmap, lightmap_sampler, e, in_uv);
    }
    float a = e.tint_opacity.w;
    out_color = vec4(lit * a, a);
}
