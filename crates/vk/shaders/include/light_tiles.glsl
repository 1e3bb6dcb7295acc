// The hi-stencil emulation's work in a light shader (deferred_light.frag, lut_light.frag):
// rejecting fragments of failing tiles (TILE_TEST) and counting shaded fragments (TILE_COUNT).
// Each is specialised away where the pass has no use for it: only the statistics runs count, so
// the shaders of timed passes carry no memory writes (llvmpipe pays for an atomic compiled in
// even where it never runs: about 5 of the 14 % a testing pass cost over native's, README).
//
// The shaders declare early_fragment_tests (light passes write neither depth nor stencil), so
// what arrives here passed every per-pixel test, as behind real hi-stencil.
#ifndef LIGHT_TILES_GLSL
#define LIGHT_TILES_GLSL

#include "light_draw.glsl"
#include "hi_stencil.glsl"

layout(constant_id = 1) const bool TILE_TEST = false;
layout(constant_id = 2) const bool TILE_COUNT = false;

// True when the active hi-stencil surface culls this fragment's tile; counts the fragment
// otherwise, when the draw asks for it.
// (Tested as `if (TILE_TEST)`: `!TILE_TEST` would be an OpSpecConstantOp, which naga cannot read.)
bool light_tile_culled() {
    if (TILE_TEST) {
        if ((light_draw.flags & LIGHT_DRAW_HI_STENCIL_TEST) != 0u && active_tiles[hi_stencil_tile()] == 0u) {
            return true;
        }
    }
    if (TILE_COUNT) {
        if ((light_draw.flags & LIGHT_DRAW_COUNT) != 0u) {
            atomicAdd(hi_stats.fragments_shaded, 1u);
        }
    }
    return false;
}

#endif
