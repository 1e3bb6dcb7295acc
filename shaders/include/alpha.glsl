// Alpha entities (translucent objects, particle systems) and where their light probes are: set 1
// of the lightmap pass and of histencil's alpha pass.
// Rust mirrors: crates/vk/src/alpha/gpu.rs (AlphaEntityRecord, AlphaDrawPush); the probe frame
// is histencil_alpha::ProbeFrame, the layouts histencil_alpha::plan_regions, the object probes
// histencil_alpha::bake_probes.
#ifndef ALPHA_GLSL
#define ALPHA_GLSL

#include "light.glsl"
#include "alpha_entity.glsl"

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
