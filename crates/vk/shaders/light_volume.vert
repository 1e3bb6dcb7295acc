#version 460
// Places a unit light-volume mesh (circumscribed sphere, or cone along +Z) on a light.
#include "frame.glsl"
#include "light_draw.glsl"

layout(location = 0) in vec3 in_position;

// The hi-stencil emulation draws a write's volume again, in another pipeline, to find the
// pixels the write rasterised: both must place every vertex identically. Both run this module
// unchanged; `precise` forbids contracting its arithmetic differently per pipeline (`invariant`
// would say more, but lavapipe 22.3 warns on the SPIR-V glslang emits for it).
precise gl_Position;

void main() {
    Light light = lights[light_draw.light_index];
    vec3 center = light.position_radius.xyz;
    float range = light.position_radius.w;
    vec3 world;
    if (uint(light.color_kind.w) == LIGHT_SPOT) {
        vec3 d = light.direction.xyz;
        vec3 helper = abs(d.y) < 0.99 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
        vec3 x = normalize(cross(helper, d));
        vec3 y = cross(d, x);
        float r = range * light.spot.z;
        world = center + x * (in_position.x * r) + y * (in_position.y * r) + d * (in_position.z * range);
    } else {
        world = center + in_position * range;
    }
    gl_Position = frame.view_proj * vec4(world, 1.0);
}
