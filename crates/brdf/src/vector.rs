//! The few vector operations the BRDFs need, generic over `f32` and `f64` so one definition
//! serves as both the reference (f64) and the shipping precision (f32).

use num_traits::{Float, FloatConst};

/// `f32` or `f64`.
pub trait Real: Float + FloatConst + std::fmt::Debug {}
impl<T: Float + FloatConst + std::fmt::Debug> Real for T {}

/// A constant in the working precision.
pub(crate) fn c<R: Real>(x: f64) -> R {
    R::from(x).expect("f64 constants convert to f32 and f64")
}

/// A 3-vector in working precision: `[x, y, z]`, the shape GLSL's `vec3` and the case files use.
pub type V3<R> = [R; 3];

pub(crate) fn dot<R: Real>(a: V3<R>, b: V3<R>) -> R {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(crate) fn add<R: Real>(a: V3<R>, b: V3<R>) -> V3<R> {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

pub(crate) fn scale<R: Real>(a: V3<R>, s: R) -> V3<R> {
    [a[0] * s, a[1] * s, a[2] * s]
}

pub(crate) fn sub<R: Real>(a: V3<R>, b: V3<R>) -> V3<R> {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(crate) fn cross<R: Real>(a: V3<R>, b: V3<R>) -> V3<R> {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Unit vector along `a`, or `None` for a zero or non-finite vector. Rescales by the largest
/// component first, so denormal-scale and huge inputs normalise without under- or overflow.
pub fn normalize<R: Real>(a: V3<R>) -> Option<V3<R>> {
    if !a.iter().all(|x| x.is_finite()) {
        return None;
    }
    let largest = a[0].abs().max(a[1].abs()).max(a[2].abs());
    if largest == R::zero() {
        return None;
    }
    // Divide, not multiply by the reciprocal: 1 / denormal overflows f32.
    let a = [a[0] / largest, a[1] / largest, a[2] / largest];
    let len = dot(a, a).sqrt();
    Some(scale(a, len.recip()))
}

/// The angle between two vectors, from `atan2(|a x b|, a . b)`: accurate near 0 and pi, where
/// `acos` of the dot product is not.
pub(crate) fn angle_between<R: Real>(a: V3<R>, b: V3<R>) -> R {
    let x = cross(a, b);
    dot(x, x).sqrt().atan2(dot(a, b))
}

/// `sin` of the angle between unit vectors, from their cosine, never NaN.
pub(crate) fn sin_from_cos<R: Real>(cos: R) -> R {
    (R::one() - cos * cos).max(R::zero()).sqrt()
}

/// `x^e` with `0^0 = 1` and `x <= 0` giving 0 otherwise: GLSL's `pow` is undefined there.
pub(crate) fn pow_safe<R: Real>(x: R, e: R) -> R {
    if e == R::zero() {
        R::one()
    } else if x <= R::zero() {
        R::zero()
    } else {
        x.powf(e)
    }
}

/// A unit view `v` moved onto the horizon of the unit normal `n` where it lies below it, with
/// its cosine (0 there): see `models::surface::lit`.
pub(crate) fn above_horizon<R: Real>(n: V3<R>, v: V3<R>) -> Option<(V3<R>, R)> {
    let n_dot_v = dot(n, v).min(R::one());
    if n_dot_v >= R::zero() {
        return Some((v, n_dot_v));
    }
    Some((normalize(sub(v, scale(n, n_dot_v)))?, R::zero()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn denormal_and_huge_vectors_normalise() {
        let tiny: V3<f32> = [1e-40, 0.0, 1e-40];
        let n = normalize(tiny).unwrap();
        assert!((n[0] - std::f32::consts::FRAC_1_SQRT_2).abs() < 1e-6);
        let huge: V3<f32> = [3e38, 3e38, 0.0];
        assert!(normalize(huge).unwrap()[0].is_finite());
        assert!(normalize([0.0f32; 3]).is_none());
        assert!(normalize([f32::NAN, 0.0, 1.0]).is_none());
    }
}
