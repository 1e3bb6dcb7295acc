// What a light needs to know about a surface point, whether it comes from the G-buffer (deferred)
// or straight from the draw (forward). One shading function serves both.
#ifndef SURFACE_GLSL
#define SURFACE_GLSL

struct Surface {
    vec3 position; // world space
    vec3 normal;   // world space, normalized
    vec3 albedo;   // diffuse albedo
    float specular;
    vec4 params;   // x: Blinn-Phong exponent; y, z: reserved for other BRDFs
    uint brdf;     // BRDF_* id
};

#endif
