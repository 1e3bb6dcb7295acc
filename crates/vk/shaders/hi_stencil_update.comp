#version 460
// Hi-stencil write, second half: one invocation per tile of the rectangle that holds the
// write's volume on screen. A tile the volume rasterised (one of its pixels holds the write's
// marker in the touch image, which hi_stencil.rs drew the volume into) is re-evaluated into
// the pending surface; the others keep their state. After a full-screen write, which rasterises
// every pixel without a touch draw to say so, `marker` is 0 and every tile of the rectangle
// (the frame) is re-evaluated. The tile may pass when any of its pixels passes the hi-stencil
// compare on the stencil the write left: `(stencil & read_mask) OP reference`, as
// histencil_model::HiStencilState says. No shared memory and no barriers: a CPU rasteriser
// runs a workgroup with barriers one invocation at a time, switching between them at each
// barrier.
#extension GL_EXT_samplerless_texture_functions : require
#include "generated.glsl"

layout(local_size_x = HI_STENCIL_UPDATE_GROUP) in;

layout(set = 0, binding = 0, std430) writeonly buffer Pending {
    uint pending[];
};
// Where the write's volume rasterised: its marker's depth (16-bit codes, read back as floats).
layout(set = 0, binding = 1) uniform texture2D touch_depth;
// The stencil the write left, read in place through a stencil-aspect view.
layout(set = 0, binding = 2) uniform utexture2D stencil_image;

layout(push_constant) uniform Update {
    uint compare;   // VkCompareOp
    uint reference;
    uint read_mask; // 0xFF without a read mask (360-like)
    uint width;
    uint height;
    uint tiles_x;
    uint rect_x;    // the rectangle's first tile, in tiles
    uint rect_y;
    uint rect_width;
    uint rect_tiles;
    uint marker;    // the write's 16-bit code; 0: every tile of the rectangle was touched
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

// Whether a pixel of the tile holds the marker: a code within one of it (Vulkan lets a device
// store a depth as either neighbouring code; markers are four apart, hi_stencil.rs).
bool touched(uvec2 origin, uvec2 end) {
    for (uint y = origin.y; y < end.y; ++y) {
        for (uint x = origin.x; x < end.x; ++x) {
            float code = texelFetch(touch_depth, ivec2(x, y), 0).r * 65535.0;
            if (abs(code - float(update.marker)) < 1.5) {
                return true;
            }
        }
    }
    return false;
}

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= update.rect_tiles) {
        return;
    }
    uvec2 at = uvec2(update.rect_x + i % update.rect_width, update.rect_y + i / update.rect_width);
    uvec2 origin = at * HI_STENCIL_TILE;
    uvec2 end = min(origin + HI_STENCIL_TILE, uvec2(update.width, update.height));
    if (update.marker != 0u && !touched(origin, end)) {
        return;
    }
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
    pending[at.y * update.tiles_x + at.x] = passes;
}
