#version 460
// Statistics of a hi-stencil test: drawn before a testing pass with the same geometry and cull
// mode but no depth or stencil test, it counts each covered tile once and whether the active
// surface rejects it (histencil_model::TileStats::tiles_tested / tiles_culled).
#include "light_draw.glsl"
#include "hi_stencil.glsl"

void main() {
    uint tile = hi_stencil_tile();
    if (atomicExchange(touched_tiles[tile], light_draw.stamp) != light_draw.stamp) {
        atomicAdd(hi_stats.tiles_tested, 1u);
        if (active_tiles[tile] == 0u) {
            atomicAdd(hi_stats.tiles_culled, 1u);
        }
    }
}
