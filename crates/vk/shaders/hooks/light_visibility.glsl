// The light visibility hook, as histencil provides it: every light reaches every surface. The
// light shaders include "light_visibility.glsl" and multiply each light's contribution by
//
//   float light_visibility(uint light_index, Light light, Surface s)
//       How much of `light` (lights[light_index], in the order of the frame's lights) reaches
//       surface point `s`, in [0, 1]: shadows, light functions, anything an engine has. Called
//       only where the light contributes.
//
// An engine replaces this file with its own `light_visibility.glsl`; its resources (shadow maps,
// their matrices) live in set 4, in the engine's own descriptor set layout (HookedShaders).
#ifndef LIGHT_VISIBILITY_GLSL
#define LIGHT_VISIBILITY_GLSL

#include "frame.glsl"
#include "surface.glsl"

float light_visibility(uint light_index, Light light, Surface s) {
    return 1.0;
}

#endif
