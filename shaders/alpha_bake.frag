#version 460
// Writes one light probe per texel: object-space position (w = 1: covered) and normal.
layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;

layout(location = 0) out vec4 out_position;
layout(location = 1) out vec4 out_normal;

void main() {
    out_position = vec4(in_position, 1.0);
    out_normal = vec4(in_normal, 0.0);
}
