//! The evaluation cases every spelling is checked on: ordinary directions and parameters, and
//! the hard cases (grazing, exactly 0 and slightly negative cosines, roughness 0, huge and zero
//! exponents, L == V / -V / N, tangents parallel to L or V or zero, curvature 0 and huge,
//! denormal-scale and huge vectors). Shared by the CPU tests and the GPU test in histencil-vk.

use crate::model::Brdf;
use crate::vector::V3;

/// One evaluation: a BRDF and its directions `[N, T, V, L]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Case {
    /// What a failure names: the model, its parameters and the directions' hard case.
    pub label: String,
    /// The model and parameters under test.
    pub brdf: Brdf,
    /// `[N, T, V, L]` in f64; the f32 spellings get them rounded ([`Case::dirs_f32`]).
    pub dirs: [V3<f64>; 4],
}

impl Case {
    /// The directions rounded to f32, as the f32 and GLSL spellings receive them.
    pub fn dirs_f32(&self) -> [V3<f32>; 4] {
        self.dirs.map(|d| d.map(|x| x as f32))
    }
}

/// Everything the BRDFs are evaluated with, across their parameter ranges.
pub fn ordinary_brdfs() -> Vec<Brdf> {
    let mut out = vec![];
    for rho in [0.2, 0.9] {
        out.push(Brdf::Lambert { rho });
        for sigma in [0.1, 0.35, 0.8] {
            out.push(Brdf::OrenNayarFull { rho, sigma });
            out.push(Brdf::OrenNayarQualitative { rho, sigma });
        }
        for curvature_per_mm in [0.05, 0.3, 1.5] {
            out.push(Brdf::PennerSkin {
                rho,
                curvature_per_mm,
            });
        }
    }
    for exponent in [1.0, 16.0, 200.0] {
        out.push(Brdf::BlinnPhong { exponent });
    }
    for alpha in [0.05, 0.3, 0.8] {
        out.push(Brdf::Ggx {
            alpha,
            f0: 0.04,
            f90: 1.0,
        });
    }
    out.push(Brdf::KajiyaKay {
        kd: 0.4,
        ks: 0.6,
        p: 30.0,
    });
    for alpha in [0.05, 0.3, 0.8] {
        for metallic in [0.0, 0.5, 1.0] {
            out.push(Brdf::GltfMetalRough { alpha, metallic });
        }
    }
    out
}

/// The parameter extremes of the hard cases.
pub fn extreme_brdfs() -> Vec<Brdf> {
    let mut out = vec![Brdf::Lambert { rho: 1.0 }];
    for exponent in [0.0, 1e4] {
        out.push(Brdf::BlinnPhong { exponent });
    }
    for alpha in [0.0, 1e-4 * 1e-4, 1e-4, 1.0] {
        out.push(Brdf::Ggx {
            alpha,
            f0: 0.04,
            f90: 1.0,
        });
    }
    for sigma in [0.0, 1.5] {
        out.push(Brdf::OrenNayarFull { rho: 1.0, sigma });
        out.push(Brdf::OrenNayarQualitative { rho: 1.0, sigma });
    }
    for p in [0.0, 1e4] {
        out.push(Brdf::KajiyaKay {
            kd: 1.0,
            ks: 1.0,
            p,
        });
    }
    for curvature_per_mm in [0.0, 1e-6, 1e6] {
        out.push(Brdf::PennerSkin {
            rho: 1.0,
            curvature_per_mm,
        });
    }
    for alpha in [0.0, 1e-4, 1.0] {
        for metallic in [0.0, 1.0] {
            out.push(Brdf::GltfMetalRough { alpha, metallic });
        }
    }
    out
}

/// The `i`-th point of the Halton sequence in `base` (a prime), in (0, 1): the low-discrepancy
/// samples the fixed direction sets are built from.
pub fn halton(i: usize, base: usize) -> f64 {
    let (mut f, mut r, mut i) = (1.0, 0.0, i + 1);
    while i > 0 {
        f /= base as f64;
        r += f * (i % base) as f64;
        i /= base;
    }
    r
}

/// The unit vector with height `z` in [-1, 1] at azimuth `s` turns: uniform on the sphere for
/// uniform `z` and `s`.
pub fn sphere_point(z: f64, s: f64) -> V3<f64> {
    let phi = std::f64::consts::TAU * s;
    let radius = (1.0 - z * z).max(0.0).sqrt();
    [radius * phi.cos(), radius * phi.sin(), z]
}

fn unit(theta: f64, phi: f64) -> V3<f64> {
    [
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    ]
}

/// A unit direction with the given cosine to +Z (the cases' normal), in azimuth `phi`.
pub fn with_cos(cos: f64, phi: f64) -> V3<f64> {
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    [sin * phi.cos(), sin * phi.sin(), cos]
}

const N: V3<f64> = [0.0, 0.0, 1.0];
const T: V3<f64> = [1.0, 0.0, 0.0];

/// A grid of ordinary directions above the surface (N = +Z, T = +X).
pub fn ordinary_directions() -> Vec<(String, [V3<f64>; 4])> {
    let mut out = vec![];
    for (i, theta_v) in [0.1, 0.6, 1.2].into_iter().enumerate() {
        for (j, theta_l) in [0.05, 0.5, 1.0, 1.4].into_iter().enumerate() {
            for (k, phi) in [0.0, 1.3, 2.9].into_iter().enumerate() {
                let t = unit(1.2, 0.4);
                out.push((
                    format!("v{i}-l{j}-phi{k}"),
                    [N, t, unit(theta_v, 0.2), unit(theta_l, 0.2 + phi)],
                ));
            }
        }
    }
    out
}

/// Degenerate and extreme directions.
pub fn hard_directions() -> Vec<(String, [V3<f64>; 4])> {
    let v = unit(0.7, 0.3);
    let l = unit(0.9, 2.5);
    let mut out: Vec<(String, [V3<f64>; 4])> = vec![];
    for cos in [1e-6, 0.0, -1e-6] {
        out.push((format!("n.l={cos:e}"), [N, T, v, with_cos(cos, 2.0)]));
        out.push((format!("n.v={cos:e}"), [N, T, with_cos(cos, 0.5), l]));
        out.push((
            format!("n.l=n.v={cos:e}"),
            [N, T, with_cos(cos, 0.5), with_cos(cos, 0.5 + 3.0)],
        ));
    }
    // Shading normals put the view below the horizon along silhouettes; opposite the normal it
    // has no azimuth.
    out.push(("n.v=-0.3".into(), [N, T, with_cos(-0.3, 0.5), l]));
    out.push(("v==-n".into(), [N, T, N.map(|x| -x), l]));
    out.push(("l==v".into(), [N, T, l, l]));
    out.push(("l==-v".into(), [N, T, l.map(|x| -x), l]));
    out.push(("l==n".into(), [N, T, v, N]));
    out.push(("l==v==n".into(), [N, T, N, N]));
    out.push(("mirror".into(), [N, T, [-l[0], -l[1], l[2]], l]));
    out.push(("t||l".into(), [N, l, v, l]));
    out.push(("t||v".into(), [N, v, v, l]));
    out.push(("t||l||v".into(), [N, l, l, l]));
    out.push(("zero-tangent".into(), [N, [0.0; 3], v, l]));
    out.push((
        "denormal-scale".into(),
        [N, T, v, l].map(|d| d.map(|x| x * 1e-39)),
    ));
    out.push((
        "huge-scale".into(),
        [N, T, v, l].map(|d| d.map(|x| x * 1e30)),
    ));
    out.push((
        "unnormalised".into(),
        [
            N.map(|x| x * 3.0),
            T.map(|x| x * 0.2),
            v.map(|x| x * 7.0),
            l.map(|x| x * 0.01),
        ],
    ));
    out
}

fn cross_product(brdfs: Vec<Brdf>, dirs: Vec<(String, [V3<f64>; 4])>) -> Vec<Case> {
    let mut out = vec![];
    for brdf in brdfs {
        for (label, d) in &dirs {
            out.push(Case {
                label: format!("{} {brdf:?} {label}", brdf.name()),
                brdf,
                dirs: *d,
            });
        }
    }
    out
}

/// Ordinary parameters on ordinary directions.
pub fn ordinary_cases() -> Vec<Case> {
    cross_product(ordinary_brdfs(), ordinary_directions())
}

/// Extreme parameters on every direction, and ordinary parameters on hard directions.
pub fn hard_cases() -> Vec<Case> {
    let mut out = cross_product(extreme_brdfs(), ordinary_directions());
    out.extend(cross_product(extreme_brdfs(), hard_directions()));
    out.extend(cross_product(ordinary_brdfs(), hard_directions()));
    out
}

/// The comparison used for every spelling: `|a - b| / max(1, |b|)`, NaN and Inf counting as
/// infinitely wrong.
pub fn relative_error(actual: f64, reference: f64) -> f64 {
    if !actual.is_finite() {
        return f64::INFINITY;
    }
    (actual - reference).abs() / reference.abs().max(1.0)
}

/// The ordinary-case comparison of the issue: relative error, or absolute near zero.
pub fn ordinary_error(actual: f64, reference: f64) -> f64 {
    if !actual.is_finite() {
        return f64::INFINITY;
    }
    let abs = (actual - reference).abs();
    if abs <= 1e-5 {
        0.0
    } else {
        abs / reference.abs()
    }
}

/// The worst error of each model over `cases`: `(model, error, label of the case)`. `actual[i]`
/// is case `i` as evaluated by the spelling under test, its [`crate::Parts::channels`] (tinted
/// RGB, white), against the f64 reference; skin compares its three tinted channels, scalar
/// models their one, and a model with a white part that too. Prints one line per model,
/// prefixed by `spelling`, for the report.
///
/// # Panics
/// If the f64 reference itself is not finite: that is a bug in the reference.
pub fn worst_per_model(
    spelling: &str,
    cases: &[Case],
    actual: &[[f64; 4]],
    error: fn(f64, f64) -> f64,
) -> Vec<(&'static str, f64, String)> {
    let mut out: Vec<(&'static str, f64, String)> = vec![];
    for (case, value) in cases.iter().zip(actual) {
        let reference = case.brdf.reference_parts(case.dirs).channels();
        let tinted = if case.brdf.is_rgb() { 0..3 } else { 0..1 };
        let white = if case.brdf.has_white_part() {
            3..4
        } else {
            3..3
        };
        for k in tinted.chain(white) {
            assert!(
                reference[k].is_finite(),
                "reference not finite: {}",
                case.label
            );
            let e = error(value[k], reference[k]);
            match out.iter_mut().find(|(m, ..)| *m == case.brdf.name()) {
                Some(entry) if e > entry.1 => *entry = (entry.0, e, case.label.clone()),
                Some(_) => {}
                None => out.push((case.brdf.name(), e, case.label.clone())),
            }
        }
    }
    for (model, e, label) in &out {
        println!("{spelling} {model:24} worst {e:.3e}  ({label})");
    }
    out
}
