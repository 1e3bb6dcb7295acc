// The visibility hook beside the two-target decode (surface_decode.glsl): one light of the
// frame, named per frame, is shadowed by one shadow map; every other light is unshadowed.
// histencil_build compiles histencil's light shaders with it; the light shaders multiply each
// light's contribution by light_visibility where the light contributes.
//
// Reads, in set 1 beside the decode's bindings (one layout, so the light pipelines bind four
// sets, which every device can; set 4 in a layout of its own needs a fifth):
//   binding 4  sampler2DShadow  the shadow map (a D16_UNORM or D32_SFLOAT image) with a
//                               compare sampler (compareEnable, LESS_OR_EQUAL; linear filtering
//                               averages four comparisons)
//   binding 5  uniform          the shadowed light's index and matrix, and the biases
#ifndef LIGHT_VISIBILITY_GLSL
#define LIGHT_VISIBILITY_GLSL

#include "frame.glsl"   // struct Light
#include "surface.glsl" // struct Surface

layout(set = 1, binding = 4) uniform sampler2DShadow two_target_shadow_map;
layout(set = 1, binding = 5, std140) uniform TwoTargetShadow {
    mat4 world_to_shadow; // world to the shadow map's clip space (depth 0..1, nearer smaller)
    uvec4 light;          // x: the shadowed light's index in the frame's lights, or ~0u
    vec4 bias;            // x: depth bias, y: normal offset in world units
} two_target_shadow;

float light_visibility(uint light_index, Light light, Surface s) {
    if (light_index != two_target_shadow.light.x) {
        return 1.0;
    }
    vec4 clip = two_target_shadow.world_to_shadow *
                vec4(s.position + s.normal * two_target_shadow.bias.y, 1.0);
    if (clip.w <= 0.0) {
        return 1.0;
    }
    vec3 ndc = clip.xyz / clip.w;
    vec2 uv = ndc.xy * 0.5 + 0.5;
    if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0))) || ndc.z >= 1.0) {
        return 1.0;
    }
    // An explicit level: the tiled technique calls this from compute shaders, which have no
    // derivatives to pick one with.
    return textureLod(two_target_shadow_map, vec3(uv, ndc.z - two_target_shadow.bias.x), 0.0);
}

#endif
