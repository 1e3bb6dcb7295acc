#version 460
// The position atlas bake: an alpha mesh drawn in its lightmap UV layout (the viewport is the
// entity's region), carrying object-space positions and normals to every texel it covers.
layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;

layout(location = 0) out vec3 out_position;
layout(location = 1) out vec3 out_normal;

void main() {
    out_position = in_position;
    out_normal = in_normal;
    gl_Position = vec4(in_uv * 2.0 - 1.0, 0.0, 1.0);
}
