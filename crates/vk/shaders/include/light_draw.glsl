// Per-draw push constants of the light passes. Rust mirror: crates/vk/src/passes/light_passes.rs
// (LightDrawPush); flag bits: LIGHT_DRAW_* in generated.glsl.
#ifndef LIGHT_DRAW_GLSL
#define LIGHT_DRAW_GLSL

layout(push_constant) uniform LightDraw {
    uint light_index; // into `lights`
    uint stamp;       // unique per draw of a frame: marks the hi-stencil tiles it covers
    uint flags;       // LIGHT_DRAW_* bits
    uint bit;         // the preserved bit a restore draw writes
} light_draw;

#endif
