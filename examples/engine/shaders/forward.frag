#version 460
// The engine's forward reference for its lighting: every light at every pixel of every draw,
// through histencil's own shading (light.glsl, which reads set 0 as histencil's frame.glsl lays
// it out), with the same round trip through the compact G-buffer's formats as the deferred path
// (compact_round_trip), the same surface point (rebuilt from this fragment's depth as the decode
// hook rebuilds it from the depth buffer, not interpolated: a rasteriser with 4 sub-pixel bits
// interpolates off the pixel's view ray) and the same shadows (the visibility hook).
#extension GL_GOOGLE_include_directive : require
#include "light.glsl"
#include "histencil_hooks/compact_gbuffer.glsl"
#include "histencil_hooks/light_visibility.glsl"

layout(push_constant) uniform Draw {
    mat4 model;
    vec4 tint_material;
    vec4 brdf;
} draw;

layout(location = 0) in vec3 in_normal;

layout(location = 0) out vec4 out_color;

void main() {
    float linear_depth = frame.proj[3][2] / (gl_FragCoord.z + frame.proj[2][2]);
    vec3 position = world_position_on_ray(gl_FragCoord.xy, linear_depth);
    Surface s = compact_round_trip(position, normalize(in_normal), draw.tint_material.rgb,
                                   draw.brdf.xy, uint(draw.brdf.w));
    vec3 sum = vec3(0.0);
    for (uint i = 0u; i < frame.counts.x; ++i) {
        Light light = lights[i];
        vec3 lit = shade_light(light, s);
        if (any(greaterThan(lit, vec3(0.0)))) {
            lit *= light_visibility(i, light, s);
        }
        sum += lit;
    }
    out_color = vec4(sum, 0.0);
}
