// Shared helpers of the GLSL spelling of histencil-brdf (crates/brdf/src/vector.rs).
#ifndef BRDF_COMMON_GLSL
#define BRDF_COMMON_GLSL

#include "generated.glsl"

const float PI = 3.14159265358979323846;
const float INV_PI = 0.31830988618379067154;

// Unit vector along a; false for a zero or non-finite vector. Divides by the largest component
// first, so denormal-scale and huge inputs normalise without under- or overflow.
bool brdf_normalize(vec3 a, out vec3 unit_a) {
    unit_a = vec3(0.0);
    if (any(isnan(a)) || any(isinf(a))) {
        return false;
    }
    float largest = max(max(abs(a.x), abs(a.y)), abs(a.z));
    if (largest == 0.0) {
        return false;
    }
    vec3 s = a / largest;
    unit_a = s / sqrt(dot(s, s));
    return true;
}

// x^e with 0^0 = 1 and x <= 0 giving 0 otherwise: GLSL's pow is undefined there.
float brdf_pow(float x, float e) {
    if (e == 0.0) {
        return 1.0;
    }
    if (x <= 0.0) {
        return 0.0;
    }
    return pow(x, e);
}

// Moves the unit view `v` onto the horizon of the unit normal `n` where it lies below it (N.V < 0,
// which interpolated shading normals give along silhouettes), with its cosine, 0 there: the
// surface BRDFs stay continuous in V at the horizon, so forward and deferred, an ulp apart, cannot
// differ by a whole grazing value on silhouette pixels. False only for v = -n, which has no azimuth. As above_horizon in
// crates/brdf/src/vector.rs.
bool brdf_above_horizon(vec3 n, inout vec3 v, out float n_dot_v) {
    n_dot_v = min(dot(n, v), 1.0);
    if (n_dot_v >= 0.0) {
        return true;
    }
    bool ok = brdf_normalize(v - n * n_dot_v, v);
    n_dot_v = 0.0;
    return ok;
}

float brdf_sin_from_cos(float c) {
    return sqrt(max(1.0 - c * c, 0.0));
}

// |a x b|: accurate near 0, where sqrt(1 - cos^2) is not.
float brdf_sin_between(vec3 a, vec3 b) {
    vec3 x = cross(a, b);
    return min(sqrt(dot(x, x)), 1.0);
}

#endif
