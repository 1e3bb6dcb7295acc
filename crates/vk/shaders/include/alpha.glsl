// Alpha entities (translucent objects, particle systems) and where their light probes are: set 1
// of the lightmap pass and of histencil's alpha pass.
// Rust mirrors: crates/vk/src/alpha/gpu.rs (AlphaEntityRecord, AlphaDrawPush); the probe frame
// is histencil_alpha::ProbeFrame, the layouts histencil_alpha::plan_regions, the object probes
// histencil_alpha::bake_probes.
#ifndef ALPHA_GLSL
#define ALPHA_GLSL

#include "light.glsl"
#include "alpha_entity.glsl"
#include "lightmap_sample.glsl"

layout(set = 1, binding = 0, std430) readonly buffer AlphaEntities {
    AlphaEntity entities[];
};

// Dust motes and ribbon control points: xyz position, w size.
layout(set = 1, binding = 1, std430) readonly buffer AlphaPoints {
    vec4 points[];
};

// Per entity, the lights whose range reaches its bounds (the only ones that can light it).
layout(set = 1, binding = 2, std430) readonly buffer AlphaEntityLights {
    uint entity_lights[];
};

// Objects' baked probes (histencil_alpha::Probe): object-space position (w = 1 where the mesh
// covers the texel) and normal, row by row per region from AlphaEntity.shape.z.
struct AlphaProbe {
    vec4 position;
    vec4 normal;
};
layout(set = 1, binding = 3, std430) readonly buffer AlphaProbes {
    AlphaProbe probes[];
};

layout(push_constant) uniform AlphaDraw {
    uint entity; // into `entities`
    uint light;  // into `lights` (lightmap pass)
    uint pad0;
    uint pad;
} alpha_draw;

// The entity's surface at world position P with world normal N.
Surface alpha_surface(AlphaEntity e, vec3 P, vec3 N) {
    Surface s;
    s.position = P;
    s.normal = N;
    s.tint = e.tint_opacity.rgb;
    s.params = vec4(e.params.xyz, 0.0);
    s.brdf = uint(e.params.w);
    return s;
}

// Particles face the viewer: their shading normal points at the eye.
vec3 facing_normal(vec3 P) {
    vec3 to_eye = frame.eye.xyz - P;
    return length(to_eye) > 0.0 ? normalize(to_eye) : vec3(0.0, 0.0, 1.0);
}

// The probe at (u, v) of slice k of the entity's frame (histencil_alpha::ProbeFrame::probe).
vec3 frame_probe(AlphaEntity e, vec2 uv, uint k) {
    uint n = e.shape.y;
    float half_depth = e.right_depth.w;
    float depth = n > 1u ? -half_depth + 2.0 * half_depth * float(k) / float(n - 1u) : 0.0;
    float r = e.centre_radius.w;
    return e.centre_radius.xyz + e.right_depth.xyz * r * (2.0 * uv.x - 1.0)
        - e.up.xyz * r * (2.0 * uv.y - 1.0) + e.forward.xyz * depth;
}

// The point at `t` in [0, 1] along a ribbon: linear between control points, evenly in index.
vec3 ribbon_point(AlphaEntity e, float t) {
    uint count = e.shape.w;
    float x = clamp(t, 0.0, 1.0) * float(count - 1u);
    uint i = min(uint(floor(x)), count - 2u);
    vec3 a = points[e.shape.z + i].xyz;
    vec3 b = points[e.shape.z + i + 1u].xyz;
    return mix(a, b, x - float(i));
}

// The probe of the lightmap texel at `local` (texel coordinates inside the entity's region): its
// world position P and normal N. False for a texel that holds no probe (outside the mesh's UV
// layout, past the last mote, past the last slice).
bool lightmap_probe(AlphaEntity e, ivec2 local, out vec3 P, out vec3 N) {
    P = vec3(0.0);
    N = vec3(0.0, 0.0, 1.0);
    // A texel outside the region has no probe. The draw's scissor is the region, but a 2x2
    // quad that straddles its edge runs its outside texels too, as helper invocations, and
    // their loads are real: on SwiftShader a quad at an odd region origin read probe -514 of
    // a 513-texel object, 16 KiB before the buffer, and crashed (lavapipe and the layers saw
    // nothing). Every index below is in bounds once `local` is inside the region.
    uint columns = tile_columns(e);
    uvec2 extent = uvec2(columns, (max(e.shape.y, 1u) + columns - 1u) / columns) * e.region.zw;
    if (any(lessThan(local, ivec2(0))) || any(greaterThanEqual(uvec2(local), extent))) {
        return false;
    }
    uint kind = e.shape.x;
    if (kind == ALPHA_OBJECT) {
        AlphaProbe probe = probes[e.shape.z + uint(local.y) * e.region.z + uint(local.x)];
        if (probe.position.w == 0.0) {
            return false;
        }
        P = (e.model * vec4(probe.position.xyz, 1.0)).xyz;
        N = normalize(transpose(inverse(mat3(e.model))) * probe.normal.xyz);
        return true;
    }
    if (kind == ALPHA_DUST) {
        uint i = uint(local.y) * e.region.z + uint(local.x);
        if (i >= e.shape.w) {
            return false;
        }
        P = points[e.shape.z + i].xyz;
    } else if (kind == ALPHA_RIBBON) {
        P = ribbon_point(e, (float(local.x) + 0.5) / float(e.region.z));
    } else {
        // Slices: tile k at (k % columns, k / columns) of the region.
        uvec2 tile = uvec2(local) / e.region.zw;
        uint k = tile.y * tile_columns(e) + tile.x;
        if (k >= e.shape.y) {
            return false;
        }
        vec2 in_tile = vec2(uvec2(local) - tile * e.region.zw) + 0.5;
        P = frame_probe(e, in_tile / vec2(e.region.zw), k);
    }
    N = facing_normal(P);
    return true;
}

// The BRDF without its cosine, f_r(N, V, L): evaluate_brdf divided by N.L (0 behind N).
vec3 brdf_without_cosine(Surface s, vec3 V, vec3 L) {
    float c = dot(s.normal, L);
    return c > 0.0 ? evaluate_brdf(s, s.brdf, V, L) / c : vec3(0.0);
}

// The light a direction-mapped entity reflects towards V at surface s (its own normal and
// BRDF): `irradiance` is the atlas's (the sum of incident * N.L at the probe), `direction` the
// direction map's (sum of w L, sum of w) there (lightmap_direction in lightmap_sample.glsl
// decodes it). irradiance * f_r(L) is exact for one light, and for any number on a Lambert
// surface (f_r is constant); the share of the light that one direction does not explain (lights
// on several sides) is taken as arriving along the normal.
vec3 directional_lighting(Surface s, vec3 V, vec3 irradiance, vec4 direction) {
    vec3 L;
    float directionality;
    if (!lightmap_direction(direction, L, directionality)) {
        return vec3(0.0);
    }
    vec3 along = brdf_without_cosine(s, V, L);
    vec3 spread = brdf_without_cosine(s, V, s.normal);
    return irradiance * mix(spread, along, directionality);
}

// Every light's contribution at surface s (the forward reference), over the entity's light
// list: the others contribute exactly zero inside its bounds.
vec3 forward_lighting(AlphaEntity e, Surface s) {
    vec3 sum = vec3(0.0);
    for (uint i = 0; i < e.light_range.y; ++i) {
        sum += shade_light(lights[entity_lights[e.light_range.x + i]], s);
    }
    return sum;
}

// The classic single light probe: what every light delivers at one point stands for the whole
// entity; the BRDF still sees the fragment's own normal and view direction.
vec3 probe_lighting(AlphaEntity e, Surface s) {
    vec3 probe = e.centre_radius.xyz;
    vec3 sum = vec3(0.0);
    vec3 V = normalize(frame.eye.xyz - s.position);
    for (uint i = 0; i < e.light_range.y; ++i) {
        vec3 L;
        vec3 incident = light_incident(lights[entity_lights[e.light_range.x + i]], probe, L);
        if (any(notEqual(incident, vec3(0.0)))) {
            sum += incident * evaluate_brdf(s, s.brdf, V, L);
        }
    }
    return sum;
}

#endif
