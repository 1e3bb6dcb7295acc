// The lightmap atlas (and direction map) in histencil's own alpha pass: set 2, sampled through
// lightmap_sample.glsl with a linear clamp-to-edge sampler.
#ifndef ALPHA_LIGHTMAP_GLSL
#define ALPHA_LIGHTMAP_GLSL

#include "alpha.glsl"
#include "lightmap_sample.glsl"

layout(set = 2, binding = 0) uniform texture2D lightmap;
// The direction map of directional frames (lightmap_directional.frag); bound in every mode.
layout(set = 2, binding = 1) uniform texture2D direction_map;
layout(set = 2, binding = 2) uniform sampler lightmap_sampler;

#endif
