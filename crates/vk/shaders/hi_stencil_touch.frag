#version 460
// Hi-stencil write, first half: marks every tile the draw rasterises, whatever the depth and
// stencil tests decide (the shader has a side effect and no early tests, so it runs for every
// covered pixel), and lists each tile once, so `hi_stencil_update.comp` re-evaluates only the
// listed tiles. The plain read first keeps the atomics to a tile's first fragments.
#include "light_draw.glsl"
#include "hi_stencil.glsl"

void main() {
    uint tile = hi_stencil_tile();
    uint stamp = light_draw.stamp;
    if (touched_tiles[tile] != stamp && atomicExchange(touched_tiles[tile], stamp) != stamp) {
        uint i = atomicAdd(touched_list.count, 1u);
        touched_list.tiles[i] = tile;
        if (i % HI_STENCIL_UPDATE_GROUP == 0u) {
            atomicAdd(touched_list.groups, 1u);
        }
    }
}
