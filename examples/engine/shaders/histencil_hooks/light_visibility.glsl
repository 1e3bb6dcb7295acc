// The engine's visibility hook: its shadowed spot light is looked up in the engine's shadow map;
// every other light is unshadowed. Its resources sit in set 1 beside the decode hook's (bindings
// 3 and 4 of the engine's one hook layout), not in a set of their own: the light pipelines then
// bind four sets, which every Vulkan device can (SwiftShader binds no more). histencil_build compiles
// histencil's light shaders with this file; the engine's forward reference (forward.frag)
// includes it too, so both apply the same shadows.
#ifndef LIGHT_VISIBILITY_GLSL
#define LIGHT_VISIBILITY_GLSL

#include "frame.glsl"
#include "surface.glsl"

// A depth-compare sampler: linear filtering averages the four nearest comparisons (2x2 PCF).
layout(set = 1, binding = 3) uniform sampler2DShadow shadow_map;
layout(set = 1, binding = 4, std140) uniform Shadow {
    mat4 light_view_proj; // world to the shadow map's clip space (depth 0..1, nearer is smaller)
    uvec4 light;          // x: the index of the shadowed light in the frame's lights, or ~0u
    vec4 bias;            // x: depth bias, y: normal offset (world units)
} shadow;

float light_visibility(uint light_index, Light light, Surface s) {
    if (light_index != shadow.light.x) {
        return 1.0;
    }
    vec4 clip = shadow.light_view_proj * vec4(s.position + s.normal * shadow.bias.y, 1.0);
    if (clip.w <= 0.0) {
        return 1.0;
    }
    vec3 ndc = clip.xyz / clip.w;
    vec2 uv = ndc.xy * 0.5 + 0.5;
    if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0))) || ndc.z >= 1.0) {
        return 1.0;
    }
    return texture(shadow_map, vec3(uv, ndc.z - shadow.bias.x));
}

#endif
