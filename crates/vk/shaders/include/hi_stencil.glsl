// The hi-stencil emulation's tile surface (set 2 of the light pipelines): one word per tile of
// HI_STENCIL_TILE x HI_STENCIL_TILE pixels, row-major. Rust side: crates/vk/src/hi_stencil/mod.rs;
// semantics: histencil_model::TileSurface.
#ifndef HI_STENCIL_GLSL
#define HI_STENCIL_GLSL

#include "frame.glsl"
#include "stencil_bytes.glsl"

// Non-zero where the active surface lets fragments through.
layout(set = 2, binding = 0, std430) readonly buffer HiStencilActive {
    uint active_tiles[];
};
// The stamp of the last statistics draw that covered each tile (hi_stencil_count.frag).
layout(set = 2, binding = 1, std430) buffer HiStencilTouched {
    uint touched_tiles[];
};
// Statistics (histencil_model::TileStats): counted only by draws with LIGHT_DRAW_COUNT.
layout(set = 2, binding = 2, std430) buffer HiStencilStats {
    uint tiles_tested;
    uint tiles_culled;
    uint fragments_shaded;
    uint unused;
} hi_stats;
// The stencil bytes saved before lighting (four pixels per word), for restoring preserved bits.
layout(set = 2, binding = 3, std430) readonly buffer SavedStencil {
    uint saved_stencil[];
};

uint hi_stencil_tile() {
    uint tiles_x = (uint(frame.viewport.x) + HI_STENCIL_TILE - 1u) / HI_STENCIL_TILE;
    uvec2 tile = uvec2(gl_FragCoord.xy) / HI_STENCIL_TILE;
    return tile.y * tiles_x + tile.x;
}

#endif
