#version 460
// Deferred light shader: one light, every BRDF (branching on the G-buffer's BRDF id).
#include "light.glsl"
#include "gbuffer.glsl"

layout(push_constant) uniform LightDraw {
    uint light_index;
} light_draw;

layout(location = 0) out vec4 out_color;

void main() {
    Surface s;
    if (!gbuffer_load(gl_FragCoord.xy, s)) {
        out_color = vec4(0.0);
        return;
    }
    out_color = vec4(shade_light(lights[light_draw.light_index], s), 0.0);
}
