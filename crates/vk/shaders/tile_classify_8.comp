#version 460
// tile_classify with 8x8 tiles (include/tile_classify.glsl).
#define TILED_TILE 8u
#include "tile_classify.glsl"
