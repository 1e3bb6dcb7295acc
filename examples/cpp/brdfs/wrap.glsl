// Wrapped diffuse: f_r * N.L = rho / pi * max((N.L + w) / (1 + w), 0), with w = p.x and
// rho = p.y. At w = 0 it is Lambert; at w = 1 a light behind the surface still reaches it.
#ifndef CPP_ENGINE_WRAP_GLSL
#define CPP_ENGINE_WRAP_GLSL

vec3 wrap_diffuse(vec4 p, vec3 N, vec3 T, vec3 V, vec3 L) {
    float w = p.x;
    float lit = max((dot(N, L) + w) / (1.0 + w), 0.0);
    return vec3(p.y * INV_PI * lit);
}

#endif
