//! Penner's pre-integrated skin diffuse (GPU Pro 2, 2011): the cosine falloff convolved with
//! the d'Eon / Luebke sum-of-Gaussians diffusion profile (GPU Gems 3, ch. 14) around a ring of
//! the surface's radius of curvature.
//!
//! ```text
//! D(theta, r) = sum_i w_i int cos+(theta + x) G_i(2 r sin(x/2)) dx / sum_i w_i int G_i(2 r sin(x/2)) dx
//! value       = rho / pi * D(theta, 1 / curvature)            (per RGB channel)
//! ```
//! Each Gaussian is integrated over `|x| <= min(pi, 8 sigma_i / r)` and only where the cosine is
//! positive, so the kink of `cos+` never sits inside a Simpson panel and the integrand is smooth:
//! a few dozen samples reach 1e-6. Curvature 0 (flat) is Lambert; huge curvature tends to the
//! ring average `1 / pi`.

use crate::vector::{angle_between, c, normalize, Real, V3};

/// Variances (mm^2) and RGB weights of the six Gaussians of d'Eon and Luebke's skin profile.
pub const SKIN_PROFILE: [(f64, [f64; 3]); 6] = [
    (0.0064, [0.233, 0.455, 0.649]),
    (0.0484, [0.100, 0.336, 0.344]),
    (0.187, [0.118, 0.198, 0.0]),
    (0.567, [0.113, 0.007, 0.007]),
    (1.99, [0.358, 0.004, 0.0]),
    (7.41, [0.078, 0.0, 0.0]),
];

/// Simpson panels per integral in the f64 reference.
pub const REFERENCE_PANELS: u32 = 256;
/// Simpson panels per integral in the f32 and GLSL spellings.
pub const SHIPPING_PANELS: u32 = 32;

/// Half-widths below this (radians) use the flat limit: the error is `O(width^2)`.
pub const FLAT_LIMIT: f64 = 1e-4;

/// Composite Simpson over `[a, b]` with `panels` (even) panels.
fn simpson<R: Real>(a: R, b: R, panels: u32, f: impl Fn(R) -> R) -> R {
    if b <= a {
        return R::zero();
    }
    let n = panels + panels % 2;
    let h = (b - a) / c(f64::from(n));
    let mut sum = f(a) + f(b);
    for k in 1..n {
        let weight = if k % 2 == 1 { c::<R>(4.0) } else { c(2.0) };
        sum = sum + weight * f(a + h * c(f64::from(k)));
    }
    sum * h / c(3.0)
}

/// `D(theta)` for curvature `curvature_per_mm` (1/mm), RGB.
pub fn skin_diffusion<R: Real>(theta: R, curvature_per_mm: R, panels: u32) -> [R; 3] {
    let pi = R::PI();
    let half_pi = pi * c(0.5);
    let curvature = curvature_per_mm.max(R::zero());
    let mut numerator = [R::zero(); 3];
    let mut denominator = [R::zero(); 3];
    for (variance, weights) in SKIN_PROFILE {
        let variance: R = c(variance);
        let width = (c::<R>(8.0) * variance.sqrt() * curvature).min(pi);
        // Integrals of G_i and cos+ * G_i along the ring.
        let (mass, lit) = if width < c(FLAT_LIMIT) {
            // Flat: the profile is a delta on the ring; its 1D mass along a line.
            let mass = (c::<R>(2.0) * pi * variance).sqrt() / (c::<R>(2.0) * pi * variance);
            (mass, mass * theta.cos().max(R::zero()))
        } else {
            let r = curvature.recip();
            let gaussian = |x: R| {
                let d = c::<R>(2.0) * r * (x * c(0.5)).sin();
                (-(d * d) / (c::<R>(2.0) * variance)).exp() / (c::<R>(2.0) * pi * variance)
            };
            // Integrals over x are in radians; times r they are along the surface, like the
            // flat limit's, so Gaussians in either regime add up consistently.
            let mass = r * simpson(-width, width, panels, gaussian);
            let lit_on = |lo: R, hi: R| {
                simpson(lo.max(-width), hi.min(width), panels, |x| {
                    (theta + x).cos().max(R::zero()) * gaussian(x)
                })
            };
            // cos(theta + x) > 0 for theta + x in (-pi/2, pi/2) and (3 pi/2, 5 pi/2).
            let lit = r
                * (lit_on(-half_pi - theta, half_pi - theta)
                    + lit_on(c::<R>(3.0) * half_pi - theta, pi));
            (mass, lit)
        };
        for k in 0..3 {
            let w: R = c(weights[k]);
            numerator[k] = numerator[k] + w * lit;
            denominator[k] = denominator[k] + w * mass;
        }
    }
    [0, 1, 2].map(|k| numerator[k] / denominator[k])
}

/// `rho / pi * D(theta, curvature)` per channel, with `theta` the angle between N and L
/// (not gated: light wraps around). Ignores V. Zero vectors give 0.
pub fn penner_skin<R: Real>(
    rho: R,
    curvature_per_mm: R,
    n: V3<R>,
    l: V3<R>,
    panels: u32,
) -> [R; 3] {
    let (Some(n), Some(l)) = (normalize(n), normalize(l)) else {
        return [R::zero(); 3];
    };
    let theta = angle_between(n, l);
    skin_diffusion(theta, curvature_per_mm, panels).map(|d| rho * R::FRAC_1_PI() * d)
}
