#version 460
// Hi-stencil write, second half: one invocation per tile the draw touched (listed by
// hi_stencil_touch.frag, dispatched indirectly over that list), or per tile of the frame after
// a full-screen write, which rasterises every pixel and so touches every tile without a
// fragment shader to say so (`all_tiles`). The tile may pass when any of
// its pixels passes the hi-stencil compare on the stencil the draw left:
// `(stencil & read_mask) OP reference`, as histencil_model::HiStencilState says. No shared
// memory and no barriers: a CPU rasteriser runs a workgroup with barriers one invocation at a
// time, switching between them at each barrier.
#extension GL_EXT_samplerless_texture_functions : require
#include "generated.glsl"

layout(local_size_x = HI_STENCIL_UPDATE_GROUP) in;

// The stencil the draw left, read in place through a stencil-aspect view.
layout(set = 0, binding = 2) uniform utexture2D stencil_image;
layout(set = 0, binding = 0, std430) readonly buffer TouchedList {
    uint groups;
    uint group_y;
    uint group_z;
    uint count;
    uint tiles[];
} touched_list;
layout(set = 0, binding = 1, std430) writeonly buffer Pending {
    uint pending[];
};

layout(push_constant) uniform Update {
    uint compare;   // VkCompareOp
    uint reference;
    uint read_mask; // 0xFF without a read mask (360-like)
    uint width;
    uint height;
    uint tiles_x;
    uint all_tiles; // 1: every tile of the frame, in order; 0: the touched list's
} update;

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
    uint i = gl_GlobalInvocationID.x;
    uint tiles_y = (update.height + HI_STENCIL_TILE - 1u) / HI_STENCIL_TILE;
    uint count = update.all_tiles != 0u ? update.tiles_x * tiles_y : touched_list.count;
    if (i >= count) {
        return;
    }
    uint tile = update.all_tiles != 0u ? i : touched_list.tiles[i];
    uvec2 origin = uvec2(tile % update.tiles_x, tile / update.tiles_x) * HI_STENCIL_TILE;
    uvec2 end = min(origin + HI_STENCIL_TILE, uvec2(update.width, update.height));
    uint passes = 0u;
    for (uint y = origin.y; y < end.y && passes == 0u; ++y) {
        for (uint x = origin.x; x < end.x; ++x) {
            uint stencil = texelFetch(stencil_image, ivec2(x, y), 0).r;
            if (compare_passes(update.compare, stencil & update.read_mask, update.reference)) {
                passes = 1u;
                break;
            }
        }
    }
    pending[tile] = passes;
}
