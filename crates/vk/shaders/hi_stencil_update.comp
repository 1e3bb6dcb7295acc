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
//
// The same pass evaluates AMD's hierarchies (histencil_model::amd) before a draw that tests
// stencil, from the stencil as it is then (each tile's state there is exact for its current
// values: made from the G-buffer's stencil and updated in every tile a draw writes): `mode` 1,
// GFX9-11's pretests (the tile may pass unless one of the `tests` pretests implied by the draw's
// test, each an EQUAL of `(stencil & mask)` against its value, has no passing pixel); `mode` 2,
// GFX12's AND and OR of the tile's values (the tile may pass unless a known bit contradicts the
// draw's test). Either writes `pending` over the whole rectangle, made active at once.
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
    uint mode;      // 0: console hi-stencil; 1: AMD pretests; 2: AMD AND/OR (see above)
    uint tests;     // mode 1: pretests to hold (0 to 2): (read_mask, reference), (mask2, value2)
    uint mask2;
    uint value2;
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

// Whether some pixel of the tile passes `(stencil & mask) OP reference`.
bool some_pixel_passes(uvec2 origin, uvec2 end, uint op, uint mask, uint reference) {
    for (uint y = origin.y; y < end.y; ++y) {
        for (uint x = origin.x; x < end.x; ++x) {
            uint stencil = texelFetch(stencil_image, ivec2(x, y), 0).r;
            if (compare_passes(op, stencil & mask, reference)) {
                return true;
            }
        }
    }
    return false;
}

// GFX12: whether a stencil test `(reference & mask) OP (stencil & mask)` may pass somewhere in a
// tile whose values have this AND and OR (histencil_model::AndOrTiles::may_pass).
bool and_or_may_pass(uint and_bits, uint or_bits, uint op, uint mask, uint reference) {
    uint known_one = and_bits & mask;
    uint known_zero = ~or_bits & mask;
    uint r = reference & mask;
    if (op == 2u) { // EQUAL: every masked bit as the reference has it
        return (r & known_zero) == 0u && (~r & mask & known_one) == 0u;
    }
    if (op == 5u) { // NOT_EQUAL: fails only where every masked bit is known and equal
        return (known_one | known_zero) != mask || known_one != r;
    }
    // The ordered compares: the masked value lies between the known ones and the complement of
    // the known zeros.
    uint hi = mask & ~known_zero;
    for (uint v = known_one; v <= hi; ++v) {
        if (compare_passes(op, r, v)) {
            return true;
        }
    }
    return false;
}

// The tile's AND and OR of its stencil values, evaluated against the draw's test.
bool tile_and_or_may_pass(uvec2 origin, uvec2 end) {
    uint and_bits = 0xFFu;
    uint or_bits = 0u;
    for (uint y = origin.y; y < end.y; ++y) {
        for (uint x = origin.x; x < end.x; ++x) {
            uint stencil = texelFetch(stencil_image, ivec2(x, y), 0).r;
            and_bits &= stencil;
            or_bits |= stencil;
        }
    }
    return and_or_may_pass(and_bits, or_bits, update.compare, update.read_mask, update.reference);
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
    bool passes;
    switch (update.mode) {
    case HI_STENCIL_MODE_PRETESTS:
        passes = (update.tests < 1u
                  || some_pixel_passes(origin, end, 2u, update.read_mask, update.reference))
              && (update.tests < 2u
                  || some_pixel_passes(origin, end, 2u, update.mask2, update.value2));
        break;
    case HI_STENCIL_MODE_AND_OR:
        passes = tile_and_or_may_pass(origin, end);
        break;
    default:
        passes = some_pixel_passes(
            origin, end, update.compare, update.read_mask, update.reference);
        break;
    }
    pending[at.y * update.tiles_x + at.x] = passes ? 1u : 0u;
}
