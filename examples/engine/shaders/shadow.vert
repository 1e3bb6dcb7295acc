#version 460
// The engine's shadow map pass: its world's depth seen from the shadowed spot light.

layout(push_constant) uniform Draw {
    mat4 model;
    mat4 light_view_proj;
} draw;

layout(location = 0) in vec3 in_position;

void main() {
    gl_Position = draw.light_view_proj * (draw.model * vec4(in_position, 1.0));
}
