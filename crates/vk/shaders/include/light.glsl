// Light code shared by the deferred light shaders and the forward reference: what arrives from a
// light at a point, and how a surface's BRDF turns it into outgoing radiance.
#ifndef LIGHT_GLSL
#define LIGHT_GLSL

#include "frame.glsl"
#include "brdf/eval.glsl"
#include "surface.glsl"

// Distance falloff within the range, by convention (histencil_scene::Falloff, whose docs give
// the equations): exactly zero at d >= range, so a volume that circumscribes the range sphere
// never misses light and rasterising more than the sphere adds nothing.
float range_falloff(float d, float range, uint falloff) {
    float x = d / range;
    float x2 = x * x;
    float window = clamp(1.0 - x2 * x2, 0.0, 1.0);
    float windowed = window * window;
    if (falloff == LIGHT_FALLOFF_GLTF) {
        windowed = window;
    } else if (falloff == LIGHT_FALLOFF_INVERSE_SQUARE) {
        windowed = d < range ? 1.0 : 0.0;
    }
    return windowed / max(d * d, 1e-4);
}

// A spot's scale at cosine c to its axis (histencil_scene::Falloff::cone): histencil's
// smoothstep, or glTF's squared linear ramp.
float spot_cone(vec4 spot, float c, uint falloff) {
    if (falloff == LIGHT_FALLOFF_SQUARED_WINDOW) {
        return smoothstep(spot.x, spot.y, c);
    }
    float t = clamp((c - spot.x) / max(spot.y - spot.x, 1e-3), 0.0, 1.0);
    return t * t;
}

// Radiance scale arriving at P from the light, and the unit direction L towards it.
vec3 light_incident(Light light, vec3 P, out vec3 L) {
    uint kind = uint(light.color_kind.w);
    if (kind == LIGHT_DIRECTIONAL) {
        L = -light.direction.xyz;
        return light.color_kind.rgb;
    }
    vec3 to_light = light.position_radius.xyz - P;
    float d = length(to_light);
    float range = light.position_radius.w;
    if (d >= range || d <= 0.0) {
        L = vec3(0.0, 0.0, 1.0);
        return vec3(0.0);
    }
    L = to_light / d;
    uint falloff = uint(light.direction.w);
    float a = range_falloff(d, range, falloff);
    if (kind == LIGHT_SPOT) {
        a *= spot_cone(light.spot, dot(-L, light.direction.xyz), falloff);
    }
    return light.color_kind.rgb * a;
}

// Kajiya-Kay's fibre direction: world +Y projected onto the surface ("combed downwards"). A
// function of the normal only, so the G-buffer needs no tangent and deferred and forward agree
// bit for bit; zero where the normal is vertical, which the BRDF maps to 0.
vec3 fibre_tangent(vec3 N) {
    return vec3(0.0, 1.0, 0.0) - N * N.y;
}

// Outgoing radiance towards V for unit light of direction L, by BRDF model `model` with the
// surface's parameters.
vec3 evaluate_brdf(Surface s, uint model, vec3 V, vec3 L) {
    return brdf_eval_tinted(model, s.params, s.tint, s.normal, fibre_tangent(s.normal), V, L);
}

// One light's contribution to one surface point seen from the camera, by BRDF `model` (the
// surface's own, or a shader's specialised one).
vec3 shade_light_with(Light light, Surface s, uint model) {
    vec3 L;
    vec3 incident = light_incident(light, s.position, L);
    if (all(equal(incident, vec3(0.0)))) {
        return vec3(0.0);
    }
    vec3 V = normalize(frame.eye.xyz - s.position);
    return incident * evaluate_brdf(s, model, V, L);
}

vec3 shade_light(Light light, Surface s) {
    return shade_light_with(light, s, s.brdf);
}

#endif
