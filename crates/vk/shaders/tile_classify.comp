#version 460
// tile_classify with 16x16 tiles (include/tile_classify.glsl).
#define TILED_TILE 16u
#include "tile_classify.glsl"
