#version 460
// tile_shade with 16x16 tiles (include/tile_shade.glsl).
#define TILED_TILE 16u
#include "tile_shade.glsl"
