#version 460
// Deferred light shader of the LUT technique: one draw per light, every BRDF through its
// material's table (include/lut.glsl) instead of its formula. The light, the G-buffer and the
// hi-stencil work are the branching shader's; only `f_r * cos` comes from the table, indexed by
// the material index the G-buffer stores in albedo alpha.
#include "light.glsl"
#include "surface_decode.glsl"
#include "light_visibility.glsl"
#include "light_tiles.glsl"
#define LUT_SET 3
#define LUT_BINDING 0
#include "lut.glsl"

layout(early_fragment_tests) in;

layout(location = 0) out vec4 out_color;

void main() {
    if (light_tile_culled()) {
        discard;
    }
    Surface s;
    if (!decode_surface(gl_FragCoord.xy, s)) {
        out_color = vec4(0.0);
        return;
    }
    uint index = light_draw.light_index;
    Light light = lights[index];
    vec3 L;
    vec3 incident = light_incident(light, s.position, L);
    if (all(equal(incident, vec3(0.0)))) {
        out_color = vec4(0.0);
        return;
    }
    vec3 V = normalize(frame.eye.xyz - s.position);
    vec4 f = lut_lookup(decode_lut_material(gl_FragCoord.xy), s.normal, fibre_tangent(s.normal), V, L);
    // Both factors of the entry, as brdf_eval_tinted combines a BRDF's parts. Without a white
    // part f.a is 0, and adding it changes no bit (fused or not, x * y + 0 rounds as x * y).
    out_color = vec4(incident * (s.tint * f.rgb + f.a) * light_visibility(index, light, s), 0.0);
}
