#version 460
// Deferred light shader for one light. SHADED_BRDF picks the BRDF at pipeline creation: a
// BRDF_* id gives the talk's per-BRDF shader (the stencil test guarantees the pixel's BRDF), and
// BRANCH_ON_GBUFFER gives the uber shader that branches on the G-buffer's id.
//
// Depth and stencil are tested before the shader runs (light passes write neither), so the
// hi-stencil emulation's tile rejection and the fragment count below see only fragments that
// passed every per-pixel test, as a shader behind real hi-stencil would.
#include "light.glsl"
#include "gbuffer.glsl"
#include "light_draw.glsl"
#include "hi_stencil.glsl"

layout(early_fragment_tests) in;

const uint BRANCH_ON_GBUFFER = 0xFFFFFFFFu;
layout(constant_id = 0) const uint SHADED_BRDF = BRANCH_ON_GBUFFER;
// The hi-stencil emulation's tile test and fragment count; specialised away when off, so the
// shader has no memory writes (which cost llvmpipe about 20 %).
layout(constant_id = 1) const bool TILE_WORK = false;

layout(location = 0) out vec4 out_color;

void main() {
    if (TILE_WORK) {
        if ((light_draw.flags & LIGHT_DRAW_HI_STENCIL_TEST) != 0u && active_tiles[hi_stencil_tile()] == 0u) {
            discard;
        }
        if ((light_draw.flags & LIGHT_DRAW_COUNT) != 0u) {
            atomicAdd(hi_stats.fragments_shaded, 1u);
        }
    }
    Surface s;
    if (!gbuffer_load(gl_FragCoord.xy, s)) {
        out_color = vec4(0.0);
        return;
    }
    // A switch on the constant itself: a comparison would become OpSpecConstantOp, which naga
    // cannot read. The driver folds the switch when it specialises the pipeline.
    uint model;
    switch (SHADED_BRDF) {
    case BRANCH_ON_GBUFFER:
        model = s.brdf;
        break;
    default:
        model = SHADED_BRDF;
        break;
    }
    out_color = vec4(shade_light_with(lights[light_draw.light_index], s, model), 0.0);
}
