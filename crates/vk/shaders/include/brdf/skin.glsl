// Penner's pre-integrated skin: the GLSL spelling of crates/brdf/src/models/skin.rs, with the
// profile and panel count generated from Rust (SKIN_VARIANCE, SKIN_WEIGHT, SKIN_PANELS).
#ifndef BRDF_SKIN_GLSL
#define BRDF_SKIN_GLSL

#include "brdf/common.glsl"

float brdf_skin_gaussian(float x, float r, float variance) {
    float d = 2.0 * r * sin(x * 0.5);
    return exp(-(d * d) / (2.0 * variance)) / (2.0 * PI * variance);
}

// Composite Simpson of G (lit = false) or cos+(theta + x) G (lit = true) over [a, b].
float brdf_skin_simpson(float a, float b, float theta, float r, float variance, bool lit) {
    if (b <= a) {
        return 0.0;
    }
    uint n = SKIN_PANELS + SKIN_PANELS % 2u;
    float h = (b - a) / float(n);
    float sum = 0.0;
    for (uint k = 0u; k <= n; ++k) {
        float x = a + h * float(k);
        float weight = (k == 0u || k == n) ? 1.0 : ((k % 2u == 1u) ? 4.0 : 2.0);
        float f = brdf_skin_gaussian(x, r, variance);
        if (lit) {
            f *= max(cos(theta + x), 0.0);
        }
        sum += weight * f;
    }
    return sum * h / 3.0;
}

vec3 brdf_skin_diffusion(float theta, float curvature_per_mm) {
    float half_pi = PI * 0.5;
    float curvature = max(curvature_per_mm, 0.0);
    vec3 numerator = vec3(0.0);
    vec3 denominator = vec3(0.0);
    for (int i = 0; i < 6; ++i) {
        float variance = SKIN_VARIANCE[i];
        float width = min(8.0 * sqrt(variance) * curvature, PI);
        float mass;
        float lit;
        if (width < SKIN_FLAT_LIMIT) {
            mass = sqrt(2.0 * PI * variance) / (2.0 * PI * variance);
            lit = mass * max(cos(theta), 0.0);
        } else {
            float r = 1.0 / curvature;
            mass = r * brdf_skin_simpson(-width, width, theta, r, variance, false);
            float a0 = max(-half_pi - theta, -width);
            float b0 = min(half_pi - theta, width);
            float a1 = max(3.0 * half_pi - theta, -width);
            float b1 = min(PI, width);
            lit = r * (brdf_skin_simpson(a0, b0, theta, r, variance, true)
                + brdf_skin_simpson(a1, b1, theta, r, variance, true));
        }
        numerator += SKIN_WEIGHT[i] * lit;
        denominator += SKIN_WEIGHT[i] * mass;
    }
    return numerator / denominator;
}

vec3 brdf_penner_skin(float rho, float curvature_per_mm, vec3 N, vec3 L) {
    vec3 n, l;
    if (!brdf_normalize(N, n) || !brdf_normalize(L, l)) {
        return vec3(0.0);
    }
    float theta = atan(brdf_sin_between(n, l), dot(n, l));
    return rho * INV_PI * brdf_skin_diffusion(theta, curvature_per_mm);
}

#endif
