#version 460
// The depth-id technique's id copy, as Bevy's deferred renderer copies each pixel's lighting-pass
// id into a depth texture (`copy_lighting_id.rs`): a full-screen triangle over a 16-bit unorm
// depth image cleared to 1, writing each surface pixel's BRDF slot as the depth `(slot + 1) /
// 65535` (depth_id.rs, `depth_code`), and nothing where the frame lights no surface. Each BRDF's
// full-screen pass (depth_id_shade.frag) then draws at its own depth with compare EQUAL, so a
// GPU's hierarchical depth rejects whole tiles of other BRDFs before any fragment runs. The slot
// comes from the surface (the decode hook), as the tiled technique's classification reads it.
#include "pixel_surface.glsl"

void main() {
    uint model;
    float depth;
    if (!tile_surface(ivec2(gl_FragCoord.xy), model, depth)) {
        discard;
    }
    uint slot = slot_of_model(model);
    if (slot >= 32u) {
        discard;
    }
    gl_FragDepth = float(slot + 1u) / 65535.0;
}
