// What a light needs to know about a surface point, whether it comes from the G-buffer (deferred)
// or straight from the draw (forward). One shading function serves both.
#ifndef SURFACE_GLSL
#define SURFACE_GLSL

struct Surface {
    vec3 position; // world space
    vec3 normal;   // world space, normalized
    vec3 tint;     // multiplies the BRDF's value
    vec4 params;   // the BRDF's packed parameters (histencil_brdf::Brdf::packed_params)
    uint brdf;     // BRDF_* id
};

#endif
