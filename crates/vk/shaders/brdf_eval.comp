#version 460
// Evaluates BRDF cases with the GLSL spelling, in parts (tinted RGB, white), for the comparison
// against the f64 reference; a case whose tint.w is 1 gets the value of a surface of colour
// tint.xyz instead (brdf_eval_tinted, as every technique shades: the one spelling of an engine
// BRDF whose function takes the tint)
// (histencil brdf-eval --device gpu, and crates/vk/tests/brdf_gpu.rs).
// Rust mirror of the structs: crates/vk/src/tools/brdf_eval.rs (GpuBrdfCase).

#include "brdf/eval.glsl"

layout(local_size_x = 64) in;

struct BrdfCase {
    uvec4 model;
    vec4 params;
    vec4 tint;
    vec4 n;
    vec4 t;
    vec4 v;
    vec4 l;
};

layout(set = 0, binding = 0, std430) readonly buffer Cases {
    BrdfCase cases[];
};

layout(set = 0, binding = 1, std430) writeonly buffer Results {
    vec4 results[];
};

layout(push_constant) uniform Push {
    uint count;
} push;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.count) {
        return;
    }
    BrdfCase c = cases[i];
    if (c.tint.w == 1.0) {
        vec3 value = brdf_eval_tinted(c.model.x, c.params, c.tint.xyz, c.n.xyz, c.t.xyz, c.v.xyz, c.l.xyz);
        results[i] = vec4(value, 0.0);
        return;
    }
    BrdfParts parts = brdf_eval_parts(c.model.x, c.params, c.n.xyz, c.t.xyz, c.v.xyz, c.l.xyz);
    results[i] = vec4(parts.tinted, parts.white);
}
