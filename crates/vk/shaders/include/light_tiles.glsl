// The hi-stencil emulation's work in a light shader (deferred_light.frag, lut_light.frag):
// rejecting fragments of failing tiles and counting shaded fragments. TILE_WORK specialises it
// away when the pass has neither, so those shaders have no memory writes (which cost llvmpipe
// about 20 %).
//
// The shaders declare early_fragment_tests (light passes write neither depth nor stencil), so
// what arrives here passed every per-pixel test, as behind real hi-stencil.
#ifndef LIGHT_TILES_GLSL
#define LIGHT_TILES_GLSL

#include "light_draw.glsl"
#include "hi_stencil.glsl"

layout(constant_id = 1) const bool TILE_WORK = false;

// True when the active hi-stencil surface culls this fragment's tile; counts the fragment
// otherwise, when the draw asks for it.
// (Tested as `if (TILE_WORK)`: `!TILE_WORK` would be an OpSpecConstantOp, which naga cannot read.)
bool light_tile_culled() {
    if (TILE_WORK) {
        if ((light_draw.flags & LIGHT_DRAW_HI_STENCIL_TEST) != 0u && active_tiles[hi_stencil_tile()] == 0u) {
            return true;
        }
        if ((light_draw.flags & LIGHT_DRAW_COUNT) != 0u) {
            atomicAdd(hi_stats.fragments_shaded, 1u);
        }
    }
    return false;
}

#endif
