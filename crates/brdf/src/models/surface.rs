//! Lambert, normalized Blinn-Phong, Oren-Nayar (full and qualitative) and GGX: the surface
//! BRDFs, gated by `N.L > 0`, with a view below the horizon taken as grazing (see `lit`).

use crate::vector::{above_horizon, add, c, cross, dot, normalize, pow_safe, scale, sub, Real, V3};

/// Unit directions and cosines of a lit surface point, or `None` when it is not lit.
pub(crate) struct Lit<R: Real> {
    pub n: V3<R>,
    pub v: V3<R>,
    pub l: V3<R>,
    pub n_dot_l: R,
    pub n_dot_v: R,
}

/// Normalises and gates: `None` for zero vectors or `N.L <= 0`. A view below the horizon
/// (`N.V < 0`, which interpolated shading normals give on visible front faces along
/// silhouettes) is taken as the grazing view of the same azimuth: `V` projected onto the tangent
/// plane, `N.V = 0`. That keeps every surface BRDF continuous in `V` at the horizon. A gate there
/// (0 below, the whole grazing value above) would let two computations an ulp apart, forward's
/// interpolated position and deferred's reconstructed one, differ by that whole value on a
/// silhouette pixel. Only `V = -N` exactly, with no azimuth, gives `None`.
pub(crate) fn lit<R: Real>(n: V3<R>, v: V3<R>, l: V3<R>) -> Option<Lit<R>> {
    let (n, v, l) = (normalize(n)?, normalize(v)?, normalize(l)?);
    let n_dot_l = dot(n, l).min(R::one());
    if n_dot_l <= R::zero() {
        return None;
    }
    let (v, n_dot_v) = above_horizon(n, v)?;
    Some(Lit {
        n,
        v,
        l,
        n_dot_l,
        n_dot_v,
    })
}

/// `sin` of the angle between unit vectors: `|a x b|`, accurate near 0 where `1 - cos^2` is not.
fn sin_between<R: Real>(a: V3<R>, b: V3<R>) -> R {
    let x = cross(a, b);
    dot(x, x).sqrt().min(R::one())
}

/// `rho / pi * max(N.L, 0)`.
pub fn lambert<R: Real>(rho: R, n: V3<R>, l: V3<R>) -> R {
    match (normalize(n), normalize(l)) {
        (Some(n), Some(l)) => rho * R::FRAC_1_PI() * dot(n, l).max(R::zero()).min(R::one()),
        _ => R::zero(),
    }
}

/// Normalized Blinn-Phong: `(e + 8) / (8 pi) * max(N.H, 0)^e * N.L`, with `0^0 = 1`.
pub fn blinn_phong<R: Real>(exponent: R, n: V3<R>, v: V3<R>, l: V3<R>) -> R {
    let Some(s) = lit(n, v, l) else {
        return R::zero();
    };
    let Some(h) = normalize(add(s.l, s.v)) else {
        return R::zero();
    };
    let n_dot_h = dot(s.n, h).max(R::zero()).min(R::one());
    (exponent + c(8.0)) / (c::<R>(8.0) * R::PI()) * pow_safe(n_dot_h, exponent) * s.n_dot_l
}

/// The angles of Oren-Nayar: `alpha = max(theta_i, theta_r)` and its sine, `beta = min(...)`,
/// `cos(phi_i - phi_r)` (0 when either direction is the normal), and `cos(theta_i) tan(beta)`
/// formed as a ratio with `cos(beta) >= cos(theta_i)`, so grazing angles stay finite.
struct OrenNayarAngles<R: Real> {
    sin_alpha: R,
    alpha: R,
    beta: R,
    cos_phi: R,
    cos_i_tan_beta: R,
}

fn oren_nayar_angles<R: Real>(s: &Lit<R>) -> OrenNayarAngles<R> {
    let (sin_i, sin_r) = (sin_between(s.n, s.l), sin_between(s.n, s.v));
    let theta_i = sin_i.atan2(s.n_dot_l);
    let theta_r = sin_r.atan2(s.n_dot_v);
    let in_plane = |d: V3<R>, n_dot_d: R| normalize(sub(d, scale(s.n, n_dot_d)));
    let cos_phi = match (in_plane(s.l, s.n_dot_l), in_plane(s.v, s.n_dot_v)) {
        (Some(lp), Some(vp)) => dot(lp, vp).max(-R::one()).min(R::one()),
        _ => R::zero(),
    };
    // The larger angle has the smaller cosine.
    if theta_i >= theta_r {
        OrenNayarAngles {
            sin_alpha: sin_i,
            alpha: theta_i,
            beta: theta_r,
            cos_phi,
            cos_i_tan_beta: s.n_dot_l * sin_r / s.n_dot_v.max(s.n_dot_l),
        }
    } else {
        OrenNayarAngles {
            sin_alpha: sin_r,
            alpha: theta_r,
            beta: theta_i,
            cos_phi,
            cos_i_tan_beta: s.n_dot_l * sin_i / s.n_dot_l,
        }
    }
}

/// Oren-Nayar 1994, the full model with the inter-reflection term (their eq. 30 and 39).
/// `sigma` is the slope deviation in radians.
pub fn oren_nayar_full<R: Real>(rho: R, sigma: R, n: V3<R>, v: V3<R>, l: V3<R>) -> R {
    let Some(s) = lit(n, v, l) else {
        return R::zero();
    };
    let a = oren_nayar_angles(&s);
    let s2 = sigma * sigma;
    let pi = R::PI();
    let two_beta_over_pi = c::<R>(2.0) * a.beta / pi;
    let c1 = R::one() - c::<R>(0.5) * s2 / (s2 + c(0.33));
    let c2_base = c::<R>(0.45) * s2 / (s2 + c(0.09));
    let c2 = if a.cos_phi >= R::zero() {
        c2_base * a.sin_alpha
    } else {
        c2_base * (a.sin_alpha - two_beta_over_pi.powi(3))
    };
    let c3 =
        c::<R>(0.125) * s2 / (s2 + c(0.09)) * (c::<R>(4.0) * a.alpha * a.beta / (pi * pi)).powi(2);
    let half = (a.alpha + a.beta) * c(0.5);
    // half < pi/2 unless both angles are grazing, which the gate excludes.
    let cos_i_tan_half = s.n_dot_l * half.sin() / half.cos().max(R::min_positive_value());
    let direct = rho
        * R::FRAC_1_PI()
        * (c1 * s.n_dot_l
            + a.cos_phi * c2 * a.cos_i_tan_beta
            + (R::one() - a.cos_phi.abs()) * c3 * cos_i_tan_half);
    let interreflection = c::<R>(0.17) * rho * rho * R::FRAC_1_PI() * s.n_dot_l * s2
        / (s2 + c(0.13))
        * (R::one() - a.cos_phi * two_beta_over_pi * two_beta_over_pi);
    direct + interreflection
}

/// Oren-Nayar's qualitative model: `rho / pi * N.L * (A + B max(0, cos phi) sin(alpha) tan(beta))`.
pub fn oren_nayar_qualitative<R: Real>(rho: R, sigma: R, n: V3<R>, v: V3<R>, l: V3<R>) -> R {
    let Some(s) = lit(n, v, l) else {
        return R::zero();
    };
    let a = oren_nayar_angles(&s);
    let s2 = sigma * sigma;
    let big_a = R::one() - c::<R>(0.5) * s2 / (s2 + c(0.33));
    let big_b = c::<R>(0.45) * s2 / (s2 + c(0.09));
    rho * R::FRAC_1_PI()
        * (big_a * s.n_dot_l + big_b * a.cos_phi.max(R::zero()) * a.sin_alpha * a.cos_i_tan_beta)
}

/// The smallest GGX alpha evaluated: a perfect mirror has no finite BRDF, and below this the
/// peak (`1 / (pi alpha^2)`) loses f32 precision. Both spellings clamp to it.
pub const GGX_MIN_ALPHA: f64 = 1e-3;

/// GGX / Trowbridge-Reitz D at unit normal `n` and half vector `h`, with `alpha` clamped to
/// `[GGX_MIN_ALPHA, 1]`, and the clamped `alpha^2`. `1 - (N.H)^2` is formed as `|N x H|^2` to
/// avoid cancellation.
pub(crate) fn ggx_d<R: Real>(alpha: R, n: V3<R>, h: V3<R>) -> (R, R) {
    let a = alpha.max(c(GGX_MIN_ALPHA)).min(R::one());
    let a2 = a * a;
    let n_dot_h = dot(n, h).max(R::zero()).min(R::one());
    let n_cross_h = cross(n, h);
    let d_denominator = n_dot_h * n_dot_h * a2 + dot(n_cross_h, n_cross_h);
    (a2 * R::FRAC_1_PI() / (d_denominator * d_denominator), a2)
}

/// Cook-Torrance with GGX / Trowbridge-Reitz D, Smith height-correlated visibility and Schlick
/// Fresnel: `D * Vis * F * N.L`, D with `1 - (N.H)^2` formed as `|N x H|^2` against cancellation.
pub fn ggx<R: Real>(alpha: R, f0: R, f90: R, n: V3<R>, v: V3<R>, l: V3<R>) -> R {
    let Some(s) = lit(n, v, l) else {
        return R::zero();
    };
    let Some(h) = normalize(add(s.l, s.v)) else {
        return R::zero();
    };
    let (d, a2) = ggx_d(alpha, s.n, h);
    let (nl, nv) = (s.n_dot_l, s.n_dot_v);
    let vis = c::<R>(0.5)
        / (nl * (nv * nv * (R::one() - a2) + a2).sqrt()
            + nv * (nl * nl * (R::one() - a2) + a2).sqrt());
    let v_dot_h = dot(s.v, h).max(R::zero()).min(R::one());
    let fresnel = f0 + (f90 - f0) * (R::one() - v_dot_h).powi(5);
    d * vis * fresnel * nl
}
