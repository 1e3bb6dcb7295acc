#version 460
// Deferred light shader for one light. SHADED_BRDF picks the BRDF at pipeline creation: a
// BRDF_* id gives the talk's per-BRDF shader (the stencil test guarantees the pixel's BRDF), and
// BRANCH_ON_GBUFFER gives the uber shader that branches on the G-buffer's id.
// The hi-stencil emulation's work: include/light_tiles.glsl.
#include "light.glsl"
#include "gbuffer.glsl"
#include "light_tiles.glsl"

layout(early_fragment_tests) in;

const uint BRANCH_ON_GBUFFER = 0xFFFFFFFFu;
layout(constant_id = 0) const uint SHADED_BRDF = BRANCH_ON_GBUFFER;

layout(location = 0) out vec4 out_color;

void main() {
    if (light_tile_culled()) {
        discard;
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
