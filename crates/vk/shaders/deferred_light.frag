#version 460
// Deferred light shader for one light. SHADED_BRDF picks the BRDF at pipeline creation: a
// BRDF_* id gives the talk's per-BRDF shader (the stencil test guarantees the pixel's BRDF), and
// BRANCH_ON_GBUFFER gives the uber shader that branches on the G-buffer's id.
// The hi-stencil emulation's work: include/light_tiles.glsl. The surface comes from the decode
// hook and each light is scaled by the visibility hook (hooks/: histencil's G-buffer and no
// shadows, unless an engine compiled this with its own; histencil_build).
#include "light.glsl"
#include "surface_decode.glsl"
#include "light_visibility.glsl"
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
    if (!decode_surface(gl_FragCoord.xy, s)) {
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
    uint index = light_draw.light_index;
    Light light = lights[index];
    vec3 lit = shade_light_with(light, s, model);
    if (any(greaterThan(lit, vec3(0.0)))) {
        lit *= light_visibility(index, light, s);
    }
    out_color = vec4(lit, 0.0);
}
