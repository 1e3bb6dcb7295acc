#version 460
// Mesh vertex stage of the G-buffer and forward passes: both read the same varyings, so the
// surface a G-buffer texel holds is the surface forward lights at that pixel.
#include "frame.glsl"
#include "draw.glsl"

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv0;
layout(location = 3) in vec2 in_uv1;
layout(location = 4) in vec4 in_tangent;
layout(location = 5) in vec4 in_color;

layout(location = 0) out vec3 out_world_position;
layout(location = 1) out vec3 out_world_normal;
layout(location = 2) out float out_linear_depth;
layout(location = 3) out vec4 out_uv;
layout(location = 4) out vec4 out_world_tangent;
layout(location = 5) out vec4 out_color;

void main() {
    vec4 world = draw.model * vec4(in_position, 1.0);
    vec4 view = frame.view * world;
    mat3 linear = mat3(draw.model);
    out_world_position = world.xyz;
    out_world_normal = transpose(inverse(linear)) * in_normal;
    out_linear_depth = -view.z;
    out_uv = vec4(in_uv0, in_uv1);
    // The bitangent is cross(N, T) * w in object space; a mirroring transform turns the
    // world-space cross product around, so w takes the transform's orientation too.
    float orientation = determinant(linear) < 0.0 ? -1.0 : 1.0;
    out_world_tangent = vec4(linear * in_tangent.xyz, in_tangent.w * orientation);
    out_color = in_color;
    gl_Position = frame.proj * view;
}
