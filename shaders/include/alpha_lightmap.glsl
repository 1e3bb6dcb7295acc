// The lightmap atlas in histencil's own alpha pass: set 2, sampled through lightmap_sample.glsl
// with a linear clamp-to-edge sampler.
#ifndef ALPHA_LIGHTMAP_GLSL
#define ALPHA_LIGHTMAP_GLSL

#include "alpha.glsl"
#include "lightmap_sample.glsl"

layout(set = 2, binding = 0) uniform texture2D lightmap;
layout(set = 2, binding = 1) uniform sampler lightmap_sampler;

#endif
