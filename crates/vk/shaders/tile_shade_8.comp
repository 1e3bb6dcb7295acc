#version 460
// tile_shade with 8x8 tiles (include/tile_shade.glsl).
#define TILED_TILE 8u
#include "tile_shade.glsl"
