//! Kajiya-Kay (1989) hair / fibre shading: a function of the fibre tangent only.

use crate::vector::{dot, normalize, pow_safe, sin_from_cos, Real, V3};

/// `kd * sin(T, L) + ks * max(0, (T.L)(T.V) + sin(T, L) sin(T, V))^p`. Ignores N, is not gated;
/// a zero tangent (no fibre direction) gives 0.
pub fn kajiya_kay<R: Real>(kd: R, ks: R, p: R, t: V3<R>, v: V3<R>, l: V3<R>) -> R {
    let (Some(t), Some(v), Some(l)) = (normalize(t), normalize(v), normalize(l)) else {
        return R::zero();
    };
    let t_dot_l = dot(t, l).max(-R::one()).min(R::one());
    let t_dot_v = dot(t, v).max(-R::one()).min(R::one());
    let (sin_tl, sin_tv) = (sin_from_cos(t_dot_l), sin_from_cos(t_dot_v));
    let specular = (t_dot_l * t_dot_v + sin_tl * sin_tv)
        .max(R::zero())
        .min(R::one());
    kd * sin_tl + ks * pow_safe(specular, p)
}
