//! glTF 2.0's metallic-roughness BRDF, as the specification's Appendix B defines it:
//!
//! ```text
//! metal      = V * D * (base + (1 - base) * (1 - |V.H|)^5)
//! dielectric = mix(base / pi, V * D, 0.04 + 0.96 * (1 - |V.H|)^5)
//! f          = mix(dielectric, metal, metallic)
//! ```
//!
//! with GGX / Trowbridge-Reitz `D` of `alpha = roughness^2` and the separable Smith-GGX
//! visibility `V = 1 / ((|N.L| + sqrt(a2 + (1 - a2) N.L^2)) (|N.V| + sqrt(a2 + (1 - a2) N.V^2)))`.
//!
//! Unlike the talk's models its value is not the tint (the base colour) times a function of the
//! angles: a dielectric's specular lobe is white. It is affine in the base colour, so it is
//! returned in two parts, `f * N.L = base * tinted + white` ([`crate::Brdf::eval_parts`]), which
//! the renderer combines with the surface's tint in one place (`brdf_eval_tinted` in
//! `crates/vk/shaders/include/brdf/eval.glsl`, [`crate::Brdf::eval_tinted`]).

use super::surface::{ggx_d, lit};
use crate::vector::{add, c, dot, normalize, Real, V3};

/// `(tinted, white)`, both already times `N.L`: the BRDF is `base * tinted + white`. Gated and
/// continuous at the view horizon like the other surface models; `alpha` is clamped below to
/// [`super::GGX_MIN_ALPHA`] as GGX's is, and `metallic` to `[0, 1]`.
pub fn gltf_metal_rough<R: Real>(alpha: R, metallic: R, n: V3<R>, v: V3<R>, l: V3<R>) -> (R, R) {
    let zero = (R::zero(), R::zero());
    let Some(s) = lit(n, v, l) else {
        return zero;
    };
    let Some(h) = normalize(add(s.l, s.v)) else {
        return zero;
    };
    let (d, a2) = ggx_d(alpha, s.n, h);
    let (nl, nv) = (s.n_dot_l, s.n_dot_v);
    let masking = |x: R| x + (a2 + (R::one() - a2) * x * x).sqrt();
    let vis = R::one() / (masking(nl) * masking(nv));
    let specular = d * vis * nl;
    let v_dot_h = dot(s.v, h).max(R::zero()).min(R::one());
    let schlick = (R::one() - v_dot_h).powi(5);
    let f_dielectric = c::<R>(0.04) + c::<R>(0.96) * schlick;
    let m = metallic.max(R::zero()).min(R::one());
    let dielectric = R::one() - m;
    let diffuse = (R::one() - f_dielectric) * R::FRAC_1_PI() * nl;
    let tinted = dielectric * diffuse + m * specular * (R::one() - schlick);
    let white = dielectric * f_dielectric * specular + m * specular * schlick;
    (tinted, white)
}
