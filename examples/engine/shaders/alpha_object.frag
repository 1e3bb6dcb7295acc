#version 460
// A translucent mesh lit from its lightmap, premultiplied by its opacity.
#include "alpha.glsl"

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_color;

void main() {
    AlphaEntity e = entities[draw.entity];
    float a = e.tint_opacity.w;
    out_color = vec4(lightmap_object(lightmap_atlas, lightmap_linear, e, in_uv) * a, a);
}
