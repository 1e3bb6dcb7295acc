#version 460
// The per-frame lightmap pass: one draw per (entity, light that reaches it) over the entity's
// region, additive. Each texel is a light probe; it is lit by the same light and BRDF code as
// the deferred pass (include/light.glsl), with the entity's own BRDF, towards the camera.
#include "alpha.glsl"

layout(location = 0) out vec4 out_color;

void main() {
    AlphaEntity e = entities[alpha_draw.entity];
    ivec2 local = ivec2(gl_FragCoord.xy) - ivec2(e.region.xy);
    uint kind = e.shape.x;
    vec3 P;
    vec3 N;
    if (kind == ALPHA_OBJECT) {
        AlphaProbe probe = probes[e.shape.z + uint(local.y) * e.region.z + uint(local.x)];
        if (probe.position.w == 0.0) {
            out_color = vec4(0.0);
            return;
        }
        P = (e.model * vec4(probe.position.xyz, 1.0)).xyz;
        N = normalize(transpose(inverse(mat3(e.model))) * probe.normal.xyz);
    } else if (kind == ALPHA_DUST) {
        uint i = uint(local.y) * e.region.z + uint(local.x);
        if (i >= e.shape.w) {
            out_color = vec4(0.0);
            return;
        }
        P = points[e.shape.z + i].xyz;
        N = facing_normal(P);
    } else if (kind == ALPHA_RIBBON) {
        P = ribbon_point(e, (float(local.x) + 0.5) / float(e.region.z));
        N = facing_normal(P);
    } else {
        // Slices: tile k at (k % columns, k / columns) of the region.
        uvec2 tile = uvec2(local) / e.region.zw;
        uint k = tile.y * tile_columns(e) + tile.x;
        if (k >= e.shape.y) {
            out_color = vec4(0.0);
            return;
        }
        vec2 in_tile = vec2(uvec2(local) - tile * e.region.zw) + 0.5;
        P = frame_probe(e, in_tile / vec2(e.region.zw), k);
        N = facing_normal(P);
    }
    Surface s = alpha_surface(e, P, N);
    out_color = vec4(shade_light(lights[alpha_draw.light], s), 0.0);
}
