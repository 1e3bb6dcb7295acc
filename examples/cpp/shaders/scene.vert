#version 460
// The engine's one vertex stage, shared by its G-buffer pass and its forward reference: both
// passes rasterise the very same triangles and interpolate the very same normal and linear
// depth, so the surface each pixel sees is the same point in both (the deferred path rebuilds
// it from the stored depth, the forward one from the interpolated depth: the same number).

// The camera. The engine binds histencil's frame block here (histencil_shading_inputs writes
// it), whose first two members are the view and projection matrices: one upload serves the
// G-buffer pass and the forward reference, and the matrices cannot differ between them.
layout(set = 0, binding = 0, std140) uniform Camera {
    mat4 view;
    mat4 proj;
} camera;

layout(push_constant) uniform Draw {
    mat4 model;
    vec4 tint_material; // rgb tint, w material index
    vec4 brdf;          // xyz packed BRDF parameters, w BRDF model id (histencil_brdf_encode)
} draw;

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;

layout(location = 0) out vec3 out_normal;
layout(location = 1) out float out_linear_depth;

void main() {
    vec4 world = draw.model * vec4(in_position, 1.0);
    vec4 view = camera.view * world;
    out_normal = transpose(inverse(mat3(draw.model))) * in_normal;
    out_linear_depth = -view.z;
    gl_Position = camera.proj * view;
}
