// The smallest visibility hook: half of every light. It proves the packaged light shaders
// compile with an engine's hook through the packaged histencil-build and histencil.
#ifndef LIGHT_VISIBILITY_GLSL
#define LIGHT_VISIBILITY_GLSL

#include "frame.glsl"
#include "surface.glsl"

float light_visibility(uint light_index, Light light, Surface s) {
    return 0.5;
}

#endif
