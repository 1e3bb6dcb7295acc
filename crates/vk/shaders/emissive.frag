#version 460
// Emissive pass of the deferred frame: after the G-buffer pass, each emitting object is drawn
// again (depth at or in front of the stored one) and writes the radiance it emits into the cleared HDR target,
// once per pixel; the light passes then add onto it. The forward reference adds the same
// `material_emissive` before its lights.
#include "material.glsl"

// Every varying of mesh.vert is declared, used or not, so the interfaces match.
layout(location = 0) in vec3 in_world_position;
layout(location = 1) in vec3 in_world_normal;
layout(location = 2) in float in_linear_depth;
layout(location = 3) in vec4 in_uv;
layout(location = 4) in vec4 in_world_tangent;
layout(location = 5) in vec4 in_color;

layout(location = 0) out vec4 out_color;

void main() {
    if (material_masked(in_uv, in_color)) {
        discard;
    }
    out_color = vec4(material_emissive(in_uv), 0.0);
}
