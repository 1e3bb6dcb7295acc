// Surface BRDFs: the GLSL spelling of crates/brdf/src/models/surface.rs. Same names, parameters
// and convention: each returns f_r * cos(theta_L); vectors need not be normalized; N.L <= 0 or
// N.V < 0 gives 0.
#ifndef BRDF_SURFACE_GLSL
#define BRDF_SURFACE_GLSL

#include "brdf/common.glsl"

struct BrdfLit {
    vec3 n;
    vec3 v;
    vec3 l;
    float n_dot_l;
    float n_dot_v;
};

bool brdf_lit(vec3 N, vec3 V, vec3 L, out BrdfLit s) {
    s = BrdfLit(vec3(0.0), vec3(0.0), vec3(0.0), 0.0, 0.0);
    if (!brdf_normalize(N, s.n) || !brdf_normalize(V, s.v) || !brdf_normalize(L, s.l)) {
        return false;
    }
    s.n_dot_l = min(dot(s.n, s.l), 1.0);
    return s.n_dot_l > 0.0 && brdf_above_horizon(s.n, s.v, s.n_dot_v);
}

float brdf_lambert(float rho, vec3 N, vec3 L) {
    vec3 n, l;
    if (!brdf_normalize(N, n) || !brdf_normalize(L, l)) {
        return 0.0;
    }
    return rho * INV_PI * clamp(dot(n, l), 0.0, 1.0);
}

float brdf_blinn_phong(float exponent, vec3 N, vec3 V, vec3 L) {
    BrdfLit s;
    vec3 h;
    if (!brdf_lit(N, V, L, s) || !brdf_normalize(s.l + s.v, h)) {
        return 0.0;
    }
    float n_dot_h = clamp(dot(s.n, h), 0.0, 1.0);
    return (exponent + 8.0) / (8.0 * PI) * brdf_pow(n_dot_h, exponent) * s.n_dot_l;
}

struct OrenNayarAngles {
    float sin_alpha;
    float alpha;
    float beta;
    float cos_phi;
    float cos_i_tan_beta; // cos(theta_i) tan(beta), as a bounded ratio
};

OrenNayarAngles brdf_oren_nayar_angles(BrdfLit s) {
    float sin_i = brdf_sin_between(s.n, s.l);
    float sin_r = brdf_sin_between(s.n, s.v);
    float theta_i = atan(sin_i, s.n_dot_l);
    float theta_r = atan(sin_r, s.n_dot_v);
    vec3 lp, vp;
    float cos_phi = 0.0;
    if (brdf_normalize(s.l - s.n * s.n_dot_l, lp) && brdf_normalize(s.v - s.n * s.n_dot_v, vp)) {
        cos_phi = clamp(dot(lp, vp), -1.0, 1.0);
    }
    // The larger angle has the smaller cosine; cos(beta) >= cos(theta_i) keeps the ratio finite.
    if (theta_i >= theta_r) {
        float cos_i_tan_beta = s.n_dot_l * sin_r / max(s.n_dot_v, s.n_dot_l);
        return OrenNayarAngles(sin_i, theta_i, theta_r, cos_phi, cos_i_tan_beta);
    }
    float cos_i_tan_beta = s.n_dot_l * sin_i / s.n_dot_l;
    return OrenNayarAngles(sin_r, theta_r, theta_i, cos_phi, cos_i_tan_beta);
}

float brdf_oren_nayar_full(float rho, float sigma, vec3 N, vec3 V, vec3 L) {
    BrdfLit s;
    if (!brdf_lit(N, V, L, s)) {
        return 0.0;
    }
    OrenNayarAngles a = brdf_oren_nayar_angles(s);
    float s2 = sigma * sigma;
    float two_beta_over_pi = 2.0 * a.beta / PI;
    float c1 = 1.0 - 0.5 * s2 / (s2 + 0.33);
    float c2_base = 0.45 * s2 / (s2 + 0.09);
    float c2 = a.cos_phi >= 0.0
        ? c2_base * a.sin_alpha
        : c2_base * (a.sin_alpha - two_beta_over_pi * two_beta_over_pi * two_beta_over_pi);
    float k = 4.0 * a.alpha * a.beta / (PI * PI);
    float c3 = 0.125 * s2 / (s2 + 0.09) * k * k;
    float half_angle = (a.alpha + a.beta) * 0.5;
    float cos_i_tan_half = s.n_dot_l * sin(half_angle) / max(cos(half_angle), 1.17549435e-38);
    float direct = rho * INV_PI
        * (c1 * s.n_dot_l + a.cos_phi * c2 * a.cos_i_tan_beta
            + (1.0 - abs(a.cos_phi)) * c3 * cos_i_tan_half);
    float interreflection = 0.17 * rho * rho * INV_PI * s.n_dot_l * s2 / (s2 + 0.13)
        * (1.0 - a.cos_phi * two_beta_over_pi * two_beta_over_pi);
    return direct + interreflection;
}

float brdf_oren_nayar_qualitative(float rho, float sigma, vec3 N, vec3 V, vec3 L) {
    BrdfLit s;
    if (!brdf_lit(N, V, L, s)) {
        return 0.0;
    }
    OrenNayarAngles a = brdf_oren_nayar_angles(s);
    float s2 = sigma * sigma;
    float big_a = 1.0 - 0.5 * s2 / (s2 + 0.33);
    float big_b = 0.45 * s2 / (s2 + 0.09);
    return rho * INV_PI
        * (big_a * s.n_dot_l + big_b * max(a.cos_phi, 0.0) * a.sin_alpha * a.cos_i_tan_beta);
}

// GGX / Trowbridge-Reitz D with alpha clamped to [GGX_MIN_ALPHA, 1] (returned squared in a2);
// 1 - (N.H)^2 is formed as |N x H|^2 against cancellation.
float brdf_ggx_d(float alpha, vec3 n, vec3 h, out float a2) {
    float a = clamp(alpha, GGX_MIN_ALPHA, 1.0);
    a2 = a * a;
    float n_dot_h = clamp(dot(n, h), 0.0, 1.0);
    vec3 n_cross_h = cross(n, h);
    float d_denominator = n_dot_h * n_dot_h * a2 + dot(n_cross_h, n_cross_h);
    return a2 * INV_PI / (d_denominator * d_denominator);
}

float brdf_ggx(float alpha, float f0, float f90, vec3 N, vec3 V, vec3 L) {
    BrdfLit s;
    vec3 h;
    if (!brdf_lit(N, V, L, s) || !brdf_normalize(s.l + s.v, h)) {
        return 0.0;
    }
    float a2;
    float d = brdf_ggx_d(alpha, s.n, h, a2);
    float nl = s.n_dot_l;
    float nv = s.n_dot_v;
    float vis = 0.5 / (nl * sqrt(nv * nv * (1.0 - a2) + a2) + nv * sqrt(nl * nl * (1.0 - a2) + a2));
    float v_dot_h = clamp(dot(s.v, h), 0.0, 1.0);
    float m = 1.0 - v_dot_h;
    float fresnel = f0 + (f90 - f0) * (m * m * m * m * m);
    return d * vis * fresnel * nl;
}

#endif
