#version 460
// A translucent mesh: its lightmap UV goes to the fragment stage.
#include "alpha.glsl"

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec2 in_uv;

layout(location = 0) out vec2 out_uv;

void main() {
    out_uv = in_uv;
    gl_Position = camera.proj * camera.view * draw.model * vec4(in_position, 1.0);
}
