#version 460
// A translucent object's fragment, lit as AlphaDraw.mode says (its lightmap, forward per pixel,
// or the single probe), premultiplied by its opacity for blending over what lies behind.
#include "alpha_lightmap.glsl"

layout(location = 0) in vec3 in_world_position;
layout(location = 1) in vec3 in_world_normal;
layout(location = 2) in vec2 in_uv;

layout(location = 0) out vec4 out_color;

void main() {
    AlphaEntity e = entities[alpha_draw.entity];
    Surface s = alpha_surface(e, in_world_position, normalize(in_world_normal));
    vec3 lit;
    if (alpha_draw.mode == ALPHA_MODE_FORWARD) {
        lit = forward_lighting(e, s);
    } else if (alpha_draw.mode == ALPHA_MODE_PROBE) {
        lit = probe_lighting(e, s);
    } else {
        lit = lightmap_object(lightmap, e, in_uv);
    }
    float a = e.tint_opacity.w;
    out_color = vec4(lit * a, a);
}
