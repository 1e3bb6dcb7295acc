#version 460
// Restores one preserved stencil bit: the draw writes stencil bit `light_draw.bit` (reference
// and write mask) wherever the copy saved before lighting had it set, and nowhere else.
#include "light_draw.glsl"
#include "hi_stencil.glsl"

void main() {
    uvec2 px = uvec2(gl_FragCoord.xy);
    // A quad on the frame's right or bottom edge of an odd size runs texels past it as helper
    // invocations; their index would read past the saved bytes (see lightmap_probe).
    if (any(greaterThanEqual(px, uvec2(frame.viewport.xy)))) {
        discard;
    }
    uint index = px.y * uint(frame.viewport.x) + px.x;
    if ((stencil_byte(saved_stencil[index >> 2], index) & light_draw.bit) == 0u) {
        discard;
    }
}
