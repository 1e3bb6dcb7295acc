// The surface decode hook, as histencil's own G-buffer provides it. The light shaders
// (deferred_light.frag, lut_light.frag) include "surface_decode.glsl" and call two functions:
//
//   bool decode_surface(vec2 frag_coord, out Surface s)
//       The surface under pixel `frag_coord` (gl_FragCoord.xy, the pixel centre): world-space
//       position and unit normal, tint, the BRDF's packed parameters and model id
//       (surface.glsl). False where nothing was drawn.
//   uint decode_lut_material(vec2 frag_coord)
//       The LUT technique's table index of that pixel (0 where an engine has no tables).
//
// An engine replaces this file with its own `surface_decode.glsl` (histencil_build compiles the
// light shaders with the engine's hook folder searched first). Its resources live in set 1, in
// the engine's own descriptor set layout (HookedShaders); set 0's frame uniforms (frame.glsl) give
// the camera for reconstructing positions from depth.
#ifndef SURFACE_DECODE_GLSL
#define SURFACE_DECODE_GLSL

#include "gbuffer.glsl"

// The tiled classification reads depth and BRDF id straight from histencil's G-buffer.
#define HISTENCIL_BUILTIN_DECODE

bool decode_surface(vec2 frag_coord, out Surface s) {
    return gbuffer_load(frag_coord, s);
}

uint decode_lut_material(vec2 frag_coord) {
    return gbuffer_material_index(frag_coord);
}

#endif
