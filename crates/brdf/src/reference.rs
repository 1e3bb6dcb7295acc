//! f64 reference implementations. Vectors are `[f64; 3]`, unnormalized.

use std::f64::consts::PI;

type V3 = [f64; 3];

fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn normalize(a: V3) -> Option<V3> {
    let len = dot(a, a).sqrt();
    (len > 0.0 && len.is_finite()).then(|| [a[0] / len, a[1] / len, a[2] / len])
}

/// Lambert: `rho / pi * max(N.L, 0)`.
pub fn lambert(rho: f64, n: V3, l: V3) -> f64 {
    match (normalize(n), normalize(l)) {
        (Some(n), Some(l)) => rho / PI * dot(n, l).max(0.0),
        _ => 0.0,
    }
}

/// Normalized Blinn-Phong lobe times the cosine: `(e + 8) / (8 pi) * max(N.H, 0)^e * N.L`.
/// Zero when `N.L <= 0`, `N.V < 0`, or `L == -V` (no half vector).
pub fn blinn_phong(exponent: f64, n: V3, v: V3, l: V3) -> f64 {
    let (Some(n), Some(v), Some(l)) = (normalize(n), normalize(v), normalize(l)) else {
        return 0.0;
    };
    let n_dot_l = dot(n, l);
    if n_dot_l <= 0.0 || dot(n, v) < 0.0 {
        return 0.0;
    }
    let Some(h) = normalize([l[0] + v[0], l[1] + v[1], l[2] + v[2]]) else {
        return 0.0;
    };
    (exponent + 8.0) / (8.0 * PI) * dot(n, h).max(0.0).powf(exponent) * n_dot_l
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lambert_is_rho_over_pi_at_normal_incidence() {
        let v = lambert(0.5, [0.0, 0.0, 2.0], [0.0, 0.0, 1.0]);
        assert!((v - 0.5 / PI).abs() < 1e-15);
        assert_eq!(lambert(0.5, [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]), 0.0);
    }

    #[test]
    fn blinn_phong_peak_and_gates() {
        let n = [0.0, 0.0, 1.0];
        let peak = blinn_phong(32.0, n, n, n);
        assert!((peak - 40.0 / (8.0 * PI)).abs() < 1e-12);
        assert_eq!(blinn_phong(32.0, n, [0.0, 0.0, -1.0], n), 0.0);
        assert_eq!(blinn_phong(32.0, n, [1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]), 0.0);
    }
}
