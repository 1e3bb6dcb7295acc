// The GLSL spelling of histencil-brdf (crates/brdf/src/reference.rs): same names, parameters and
// convention. Each returns f_r * cos(theta_L); N, V, L are normalized and point away from the
// surface. N.L <= 0 or N.V < 0 gives 0.
#ifndef BRDF_GLSL
#define BRDF_GLSL

float brdf_lambert(float rho, vec3 N, vec3 L) {
    return rho / PI * max(dot(N, L), 0.0);
}

float brdf_blinn_phong(float exponent, vec3 N, vec3 V, vec3 L) {
    float n_dot_l = dot(N, L);
    if (n_dot_l <= 0.0 || dot(N, V) < 0.0) {
        return 0.0;
    }
    vec3 h = L + V;
    float h_len = length(h);
    if (h_len <= 0.0) {
        return 0.0; // L == -V: no half vector
    }
    float n_dot_h = max(dot(N, h / h_len), 0.0);
    return (exponent + 8.0) / (8.0 * PI) * pow(n_dot_h, exponent) * n_dot_l;
}

#endif
