#version 460
// Hi-stencil write, first half: marks every tile the draw rasterises, whatever the depth and
// stencil tests decide (the shader has a side effect and no early tests, so it runs for every
// covered pixel). `hi_stencil_update.comp` then re-evaluates the marked tiles.
#include "light_draw.glsl"
#include "hi_stencil.glsl"

void main() {
    touched_tiles[hi_stencil_tile()] = light_draw.stamp;
}
