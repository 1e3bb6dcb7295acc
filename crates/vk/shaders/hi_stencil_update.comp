#version 460
// Hi-stencil write, second half: one workgroup per tile. A tile the draw covered (its stamp is
// this draw's) may pass when any of its pixels passes the hi-stencil compare on the stencil the
// draw left: `(stencil & read_mask) OP reference`, as histencil_model::HiStencilState says.
#include "generated.glsl"
#include "stencil_bytes.glsl"

layout(local_size_x = HI_STENCIL_TILE, local_size_y = HI_STENCIL_TILE) in;

// The stencil after the draw, copied out as tightly packed bytes.
layout(set = 0, binding = 0, std430) readonly buffer StencilCopy {
    uint stencil_copy[];
};
layout(set = 0, binding = 1, std430) readonly buffer Touched {
    uint touched[];
};
layout(set = 0, binding = 2, std430) writeonly buffer Pending {
    uint pending[];
};

layout(push_constant) uniform Update {
    uint stamp;
    uint compare;   // VkCompareOp
    uint reference;
    uint read_mask; // 0xFF without a read mask (360-like)
    uint width;
    uint height;
    uint tiles_x;
} update;

shared uint any_pixel_passes;

bool compare_passes(uint op, uint a, uint b) {
    switch (op) {
    case 0u: return false;
    case 1u: return a < b;
    case 2u: return a == b;
    case 3u: return a <= b;
    case 4u: return a > b;
    case 5u: return a != b;
    case 6u: return a >= b;
    default: return true;
    }
}

void main() {
    uint tile = gl_WorkGroupID.y * update.tiles_x + gl_WorkGroupID.x;
    // The whole workgroup takes the same branch, so the barriers below stay uniform.
    if (touched[tile] != update.stamp) {
        return;
    }
    if (gl_LocalInvocationIndex == 0u) {
        any_pixel_passes = 0u;
    }
    barrier();
    uvec2 px = gl_GlobalInvocationID.xy;
    if (px.x < update.width && px.y < update.height) {
        uint index = px.y * update.width + px.x;
        uint stencil = stencil_byte(stencil_copy[index >> 2], index);
        if (compare_passes(update.compare, stencil & update.read_mask, update.reference)) {
            atomicOr(any_pixel_passes, 1u);
        }
    }
    barrier();
    if (gl_LocalInvocationIndex == 0u) {
        pending[tile] = any_pixel_passes;
    }
}
