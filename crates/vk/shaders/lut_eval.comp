#version 460
// Looks BRDF tables up with the GLSL spelling, for the comparison against Rust's Lut::lookup
// (crates/vk/src/lighting/lut.rs, LutEvaluator). A case is a table and four directions; a result
// is the tinted factor in rgb and the white one in a.

#define LUT_SET 0
#define LUT_BINDING 2
#include "lut.glsl"

layout(local_size_x = 64) in;

struct LutCase {
    uvec4 table;
    vec4 unused;
    vec4 n;
    vec4 t;
    vec4 v;
    vec4 l;
};

layout(set = 0, binding = 0, std430) readonly buffer Cases {
    LutCase cases[];
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
    LutCase c = cases[i];
    results[i] = lut_lookup(c.table.x, c.n.xyz, c.t.xyz, c.v.xyz, c.l.xyz);
}
