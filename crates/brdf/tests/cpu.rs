//! The f32 spelling against the f64 reference on ordinary and hard cases; physical sanity of
//! the reference itself (white furnace, reciprocity, limits).

use histencil_brdf::cases::{
    extreme_brdfs, hard_cases, ordinary_brdfs, ordinary_cases, ordinary_error, relative_error,
    with_cos, worst_per_model, Case,
};
use histencil_brdf::{skin_diffusion, Brdf, REFERENCE_PANELS, SHIPPING_PANELS};
use std::f64::consts::PI;

/// Every case evaluated by the f32 spelling, in parts (tinted RGB, white).
fn in_f32(cases: &[Case]) -> Vec<[f64; 4]> {
    cases
        .iter()
        .map(|c| {
            c.brdf
                .shipping_parts(c.dirs_f32())
                .channels()
                .map(f64::from)
        })
        .collect()
}

#[test]
fn f32_matches_f64_on_ordinary_cases() {
    let cases = ordinary_cases();
    let values = in_f32(&cases);
    // Printed for the report: plain relative error, before the near-zero absolute allowance.
    worst_per_model("f32", &cases, &values, relative_error);
    for (model, e, label) in worst_per_model("f32", &cases, &values, ordinary_error) {
        assert!(e <= 1e-3, "{model}: {e:e} at {label}");
    }
}

#[test]
fn f32_is_finite_and_close_on_hard_cases() {
    let cases = hard_cases();
    let values = in_f32(&cases);
    for (model, e, label) in worst_per_model("f32", &cases, &values, relative_error) {
        assert!(e <= 1e-2, "{model}: {e:e} at {label}");
    }
}

/// Every model is continuous in V across the horizon, in both spellings: shading normals put the
/// view a hair below it on silhouette pixels, where forward and deferred are an ulp apart, so a
/// jump there would be a difference between them of the whole grazing value. Below the horizon a surface
/// model's value is the grazing one of the same azimuth (Kajiya-Kay ignores N and goes on
/// varying with V there).
#[test]
fn every_model_is_continuous_across_the_view_horizon() {
    let n = [0.0, 0.0, 1.0];
    let t = [1.0, 0.0, 0.0];
    let l = [0.5, 0.3, 0.8];
    for brdf in ordinary_brdfs().into_iter().chain(extreme_brdfs()) {
        for phi in [0.0, 1.0, 2.5] {
            let at = |cos: f64| brdf.reference([n, t, with_cos(cos, phi), l]);
            let at_f32 = |cos: f64| {
                let d = [n, t, with_cos(cos, phi), l].map(|d| d.map(|x| x as f32));
                brdf.shipping(d).map(f64::from)
            };
            let grazing = at(0.0);
            let far_bound = if matches!(brdf, Brdf::KajiyaKay { .. }) {
                f64::INFINITY
            } else {
                1e-9
            };
            for (what, values, bound) in [
                ("just above", at(1e-9), 1e-4),
                ("just below", at(-1e-9), 1e-4),
                ("far below", at(-0.5), far_bound),
                ("f32 just above", at_f32(1e-6), 1e-2),
                ("f32 just below", at_f32(-1e-6), 1e-2),
            ] {
                for (value, grazing) in values.into_iter().zip(grazing) {
                    assert!(
                        (value - grazing).abs() <= bound * grazing.abs().max(1.0),
                        "{} {brdf:?} phi {phi}: {what} {value} against grazing {grazing}",
                        brdf.name(),
                    );
                }
            }
        }
    }
}

/// Directional albedo `int f cos dL` over the hemisphere, midpoint rule in (theta, phi).
fn albedo(brdf: &Brdf, theta_v: f64) -> f64 {
    let (nt, np) = (768, 256);
    let n = [0.0, 0.0, 1.0];
    let t = [1.0, 0.0, 0.0];
    let v = [theta_v.sin(), 0.0, theta_v.cos()];
    let (dt, dp) = (PI / 2.0 / nt as f64, 2.0 * PI / np as f64);
    let mut sum = 0.0;
    for i in 0..nt {
        let theta = (i as f64 + 0.5) * dt;
        for j in 0..np {
            let phi = (j as f64 + 0.5) * dp;
            let l = [
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            ];
            sum += brdf.reference([n, t, v, l])[0] * theta.sin() * dt * dp;
        }
    }
    sum
}

#[test]
fn white_furnace_energy_conserving_models_reflect_at_most_everything() {
    let mut models = vec![Brdf::Lambert { rho: 1.0 }];
    for alpha in [0.1, 0.3, 0.6, 1.0] {
        models.push(Brdf::Ggx {
            alpha,
            f0: 1.0,
            f90: 1.0,
        });
    }
    for brdf in &models {
        for theta_v in [0.0, 0.5, 1.0, 1.4] {
            let a = albedo(brdf, theta_v);
            println!("{brdf:?} theta_v {theta_v}: albedo {a:.5}");
            assert!(a <= 1.0 + 1e-3, "{brdf:?} at theta_v {theta_v}: albedo {a}");
        }
    }
    let lambert: f64 = albedo(&Brdf::Lambert { rho: 0.7 }, 0.8);
    assert!((lambert - 0.7).abs() < 1e-4, "Lambert albedo {lambert}");
}

/// Models that are not energy conserving by construction, held to their measured bound
/// (measured max + ~0.3%): normalized Blinn-Phong's (n + 8) / (8 pi) approximates the exact
/// normalisation and reflects up to 6.7% too much at low exponents (max 1.0669); Oren-Nayar
/// gains up to 1.4% (qualitative, 1.0143) and 3.6% (full, with inter-reflection, 1.0357) at
/// grazing view with rho = 1.
#[test]
fn white_furnace_approximate_models_stay_within_their_measured_bounds() {
    let mut models = vec![];
    for exponent in [1.0, 4.0, 16.0, 128.0, 1024.0] {
        models.push((Brdf::BlinnPhong { exponent }, BOUND_BLINN_PHONG));
    }
    for sigma in [0.2, 0.5, 1.0] {
        models.push((
            Brdf::OrenNayarQualitative { rho: 1.0, sigma },
            BOUND_ON_QUALITATIVE,
        ));
        models.push((Brdf::OrenNayarFull { rho: 1.0, sigma }, BOUND_ON_FULL));
    }
    for (brdf, bound) in &models {
        for theta_v in [0.0, 0.5, 1.0, 1.4, 1.55] {
            let a = albedo(brdf, theta_v);
            println!("{brdf:?} theta_v {theta_v}: albedo {a:.5}");
            assert!(
                a <= *bound,
                "{brdf:?} at theta_v {theta_v}: albedo {a} > {bound}"
            );
        }
    }
}

const BOUND_ON_QUALITATIVE: f64 = 1.017;
const BOUND_ON_FULL: f64 = 1.039;
const BOUND_BLINN_PHONG: f64 = 1.07;

#[test]
fn reciprocal_models_are_reciprocal() {
    let models = [
        Brdf::Lambert { rho: 0.5 },
        Brdf::BlinnPhong { exponent: 40.0 },
        Brdf::OrenNayarFull {
            rho: 0.8,
            sigma: 0.5,
        },
        Brdf::OrenNayarQualitative {
            rho: 0.8,
            sigma: 0.5,
        },
        Brdf::Ggx {
            alpha: 0.2,
            f0: 0.04,
            f90: 1.0,
        },
    ];
    let n = [0.0, 0.0, 1.0];
    let t = [1.0, 0.0, 0.0];
    for brdf in models {
        for (theta_a, theta_b, phi) in [(0.3f64, 1.1f64, 0.7f64), (1.4, 0.2, 2.5), (0.9, 0.9, 3.1)]
        {
            let a = [theta_a.sin(), 0.0, f64::cos(theta_a)];
            let b = [
                f64::sin(theta_b) * f64::cos(phi),
                f64::sin(theta_b) * f64::sin(phi),
                f64::cos(theta_b),
            ];
            // The functions return f * cos(theta_L): divide it out.
            let f_ab = brdf.reference([n, t, a, b])[0] / b[2];
            let f_ba = brdf.reference([n, t, b, a])[0] / a[2];
            assert!(
                (f_ab - f_ba).abs() <= 1e-12 * f_ab.abs().max(1.0),
                "{brdf:?}: {f_ab} vs {f_ba}"
            );
        }
    }
}

#[test]
fn skin_limits_and_convergence() {
    // Flat skin is Lambert.
    for theta in [0.0f64, 0.7, 1.5, 2.0] {
        let d = skin_diffusion(theta, 0.0, REFERENCE_PANELS);
        assert!(d
            .iter()
            .all(|x: &f64| (x - f64::cos(theta).max(0.0)).abs() < 1e-9));
    }
    // A tiny ball diffuses light all around the ring: 1 / pi everywhere.
    for theta in [0.0f64, 1.5, 3.0] {
        let d = skin_diffusion(theta, 1e6, REFERENCE_PANELS);
        assert!(d.iter().all(|x| (x - 1.0 / PI).abs() < 1e-4), "{d:?}");
    }
    // Curvature wraps light past the terminator, red furthest.
    let d = skin_diffusion(PI / 2.0 + 0.2, 1.0, REFERENCE_PANELS);
    assert!(d[0] > d[1] && d[1] > 0.0, "{d:?}");
    // The shipping panel count is within 1e-5 of the reference.
    for curvature in [0.01f64, 0.1, 0.5, 2.0, 10.0] {
        for theta in [0.0, 0.5, 1.4, 1.6, 2.5, 3.1] {
            let a = skin_diffusion(theta, curvature, SHIPPING_PANELS);
            let b = skin_diffusion(theta, curvature, REFERENCE_PANELS);
            for k in 0..3 {
                assert!(
                    (a[k] - b[k]).abs() < 1e-5,
                    "{theta} {curvature}: {a:?} vs {b:?}"
                );
            }
        }
    }
}

/// glTF 2.0 Appendix B transcribed on its own, formula by formula, in plain f64 (with its
/// `fresnel_mix` at IOR 1.5 and `conductor_fresnel`): the independent reference that
/// `gltf_metal_rough` is held to, for coloured base colours, both parts at once.
fn appendix_b(base: [f64; 3], metallic: f64, roughness: f64, v: [f64; 3], l: [f64; 3]) -> [f64; 3] {
    let norm = |a: [f64; 3]| {
        let len = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
        a.map(|x| x / len)
    };
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let (v, l) = (norm(v), norm(l));
    let n = [0.0, 0.0, 1.0];
    let h = norm([l[0] + v[0], l[1] + v[1], l[2] + v[2]]);
    let alpha = roughness * roughness;
    let a2 = alpha * alpha;
    let (n_dot_l, n_dot_v, n_dot_h, v_dot_h) = (dot(n, l), dot(n, v), dot(n, h), dot(v, h));
    let d = a2 / (PI * (n_dot_h * n_dot_h * (a2 - 1.0) + 1.0).powi(2));
    let vis = 1.0
        / ((n_dot_l.abs() + (a2 + (1.0 - a2) * n_dot_l * n_dot_l).sqrt())
            * (n_dot_v.abs() + (a2 + (1.0 - a2) * n_dot_v * n_dot_v).sqrt()));
    let specular_brdf = vis * d;
    let weight = (1.0 - v_dot_h.abs()).powi(5);
    let f0 = ((1.0 - 1.5f64) / (1.0 + 1.5)).powi(2);
    let mut out = [0.0; 3];
    for (o, bc) in out.iter_mut().zip(base) {
        let diffuse_brdf = bc / PI;
        let metal_brdf = specular_brdf * (bc + (1.0 - bc) * weight);
        let fresnel = f0 + (1.0 - f0) * weight;
        let dielectric_brdf = diffuse_brdf * (1.0 - fresnel) + specular_brdf * fresnel;
        *o = (dielectric_brdf * (1.0 - metallic) + metal_brdf * metallic) * n_dot_l;
    }
    out
}

#[test]
fn gltf_metal_rough_is_the_specifications_brdf() {
    let n = [0.0, 0.0, 1.0];
    let t = [1.0, 0.0, 0.0];
    let mut compared = 0;
    for roughness in [0.05, 0.3, 0.7, 1.0] {
        for metallic in [0.0, 0.25, 1.0] {
            let brdf = Brdf::GltfMetalRough {
                alpha: roughness * roughness,
                metallic,
            };
            for base in [[1.0, 1.0, 1.0], [0.9, 0.4, 0.05], [0.0, 0.0, 0.0]] {
                for i in 1..40 {
                    let l = histencil_brdf::cases::sphere_point(
                        histencil_brdf::cases::halton(i, 2),
                        histencil_brdf::cases::halton(i, 3),
                    );
                    let v = histencil_brdf::cases::sphere_point(
                        histencil_brdf::cases::halton(i, 5),
                        histencil_brdf::cases::halton(i, 7),
                    );
                    let (l, v) = (l.map(|x| x * 1.0), [v[0], v[1], v[2].abs()]);
                    if l[2] <= 1e-3 || v[2] <= 1e-3 {
                        continue;
                    }
                    let ours = brdf.eval_tinted(base, [n, t, v, l], REFERENCE_PANELS);
                    let spec = appendix_b(base, metallic, roughness, v, l);
                    for (a, b) in ours.iter().zip(spec) {
                        assert!(
                            (a - b).abs() <= 1e-9 * b.abs().max(1.0),
                            "{brdf:?} base {base:?} v {v:?} l {l:?}: {a} vs {b}"
                        );
                    }
                    compared += 1;
                }
            }
        }
    }
    assert!(compared > 500, "{compared}");
    // At normal incidence by hand: D = 1 / (pi a^2), the visibility 1/4, no Fresnel weight.
    let (alpha, metallic) = (0.09, 0.4);
    let brdf = Brdf::GltfMetalRough { alpha, metallic };
    let parts = brdf.reference_parts([n, t, n, n]);
    let specular = 1.0 / (4.0 * PI * alpha * alpha);
    let tinted = (1.0 - metallic) * 0.96 / PI + metallic * specular;
    let white = (1.0 - metallic) * 0.04 * specular;
    assert!(
        (parts.tinted[0] - tinted).abs() < 1e-12 * tinted,
        "{parts:?}"
    );
    assert!((parts.white - white).abs() < 1e-12 * white, "{parts:?}");
}

#[test]
fn gltf_metal_rough_albedo_is_bounded_and_it_is_reciprocal() {
    let n = [0.0, 0.0, 1.0];
    let t = [1.0, 0.0, 0.0];
    // Sharper lobes than alpha 0.1 need a finer grid than the albedo integral's.
    for alpha in [0.1, 0.4, 1.0] {
        for metallic in [0.0, 1.0] {
            let brdf = Brdf::GltfMetalRough { alpha, metallic };
            for theta_v in [0.0, 0.7, 1.4] {
                let a = albedo(&brdf, theta_v);
                println!("{brdf:?} theta_v {theta_v}: albedo {a:.5}");
                // A metal reflects at most everything (single scattering loses energy at high
                // roughness: 0.31 at alpha 1). The specification's dielectric is not energy
                // conserving at grazing view: it weights diffuse by 1 - F(V.H) per light
                // direction, not by what the specular lobe leaves, and reflects up to 1.2065
                // (alpha 0.1, theta_v 1.4) here; held to that measure plus 0.3 %.
                let bound = if metallic == 1.0 { 1.0 + 1e-3 } else { 1.21 };
                assert!(a <= bound, "{brdf:?} at theta_v {theta_v}: albedo {a}");
            }
            for (a, b) in [
                ([0.3, 0.1, 0.9], [-0.4, 0.5, 0.6]),
                ([0.9, 0.0, 0.2], [0.0, 0.1, 1.0]),
            ] {
                let f_ab = brdf.reference([n, t, a, b])[0] / (b[2] / norm(b));
                let f_ba = brdf.reference([n, t, b, a])[0] / (a[2] / norm(a));
                assert!((f_ab - f_ba).abs() <= 1e-12 * f_ab.max(1.0), "{brdf:?}");
            }
        }
    }
}

fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}
