//! What the G-buffer's storage does to the BRDFs: the normal and the material parameters are
//! quantised on the way through, and the lighting sees the quantised values. This module spells
//! the encodings (histencil's own and the compact ones engines use) and measures the error they
//! add to `f_r * cos`, so a G-buffer format can be chosen with its cost known.
//!
//! - Normals: f32 (histencil's G-buffer: exact to f32) or octahedral (Meyer et al. 2010) with
//!   `bits` per component as snorm.
//! - Parameters: f16 (histencil's RGBA16F material target) or 8-bit unorm through a per-parameter
//!   mapping into [0, 1]: linear for reflectances, `sqrt(alpha)` (perceptual roughness) for GGX,
//!   `sigma / (pi / 2)` for Oren-Nayar, `log2(1 + n) / log2(1 + 10^4)` for exponents and
//!   `k / (k + 1)` for skin curvature, the warps that spread 256 levels over what the eye sees.

use crate::cases::{halton, sphere_point};
use crate::half_float::round_to_f16;
use crate::model::Brdf;
use crate::vector::{angle_between, cross, normalize, V3};

/// How the G-buffer stores the normal.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NormalEncoding {
    /// Three f32 components, histencil's own G-buffer: no error beyond f32 rounding.
    Float32,
    /// Octahedral, each of the two components as a `bits`-bit snorm.
    Octahedral {
        /// Snorm bits per component (2 to 16 make sense; 8 and 10 are the usual).
        bits: u32,
    },
}

/// How the G-buffer stores the material parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ParamEncoding {
    /// Half floats, histencil's RGBA16F material target.
    Float16,
    /// 8-bit unorm through the warp of each parameter (see the module doc).
    Unorm8,
}

/// `x` in [-1, 1] rounded to the nearest of the `2^(bits-1) - 1` snorm steps.
fn snorm(x: f64, bits: u32) -> f64 {
    let steps = f64::from((1u32 << (bits - 1)) - 1);
    (x.clamp(-1.0, 1.0) * steps).round() / steps
}

/// `x` in [0, 1] rounded to the nearest 8-bit unorm level.
fn unorm8(x: f64) -> f64 {
    (x.clamp(0.0, 1.0) * 255.0).round() / 255.0
}

fn sign(x: f64) -> f64 {
    if x >= 0.0 {
        1.0
    } else {
        -1.0
    }
}

/// A unit normal as two coordinates in [-1, 1]: the octahedron's faces unfolded onto a square.
pub fn octahedral_encode(n: V3<f64>) -> [f64; 2] {
    let l1 = n[0].abs() + n[1].abs() + n[2].abs();
    let (x, y) = (n[0] / l1, n[1] / l1);
    if n[2] >= 0.0 {
        [x, y]
    } else {
        [(1.0 - y.abs()) * sign(x), (1.0 - x.abs()) * sign(y)]
    }
}

/// The inverse of [`octahedral_encode`], normalised.
pub fn octahedral_decode([x, y]: [f64; 2]) -> V3<f64> {
    let z = 1.0 - x.abs() - y.abs();
    let (x, y) = if z >= 0.0 {
        (x, y)
    } else {
        ((1.0 - y.abs()) * sign(x), (1.0 - x.abs()) * sign(y))
    };
    normalize([x, y, z]).unwrap_or([0.0, 0.0, 1.0])
}

impl NormalEncoding {
    /// The normal the lighting sees after storing `n`.
    pub fn round_trip(self, n: V3<f64>) -> V3<f64> {
        match self {
            NormalEncoding::Float32 => n.map(|x| f64::from(x as f32)),
            NormalEncoding::Octahedral { bits } => {
                let Some(n) = normalize(n) else { return n };
                octahedral_decode(octahedral_encode(n).map(|x| snorm(x, bits)))
            }
        }
    }
}

/// An exponent up to 10^4 warped into [0, 1].
fn exponent_warp(n: f64, inverse: bool) -> f64 {
    let top = (1.0f64 + 1e4).log2();
    if inverse {
        (n * top).exp2() - 1.0
    } else {
        (1.0 + n).log2() / top
    }
}

impl ParamEncoding {
    /// One parameter through the encoding, with `warp(x, inverse)` mapping it into [0, 1].
    fn store(self, x: f64, warp: fn(f64, bool) -> f64) -> f64 {
        match self {
            ParamEncoding::Float16 => round_to_f16(x),
            ParamEncoding::Unorm8 => warp(unorm8(warp(x, false)), true),
        }
    }

    /// The material the lighting sees after storing `brdf`'s parameters.
    pub fn round_trip(self, brdf: Brdf) -> Brdf {
        let linear: fn(f64, bool) -> f64 = |x, _| x;
        let sigma: fn(f64, bool) -> f64 = |s, inverse| {
            if inverse {
                s * std::f64::consts::FRAC_PI_2
            } else {
                s / std::f64::consts::FRAC_PI_2
            }
        };
        let roughness: fn(f64, bool) -> f64 = |a, inverse| if inverse { a * a } else { a.sqrt() };
        let curvature: fn(f64, bool) -> f64 = |k, inverse| {
            if inverse {
                k / (1.0 - k).max(1e-6)
            } else {
                k / (k + 1.0)
            }
        };
        let s = |x, warp| self.store(x, warp);
        match brdf {
            Brdf::Lambert { rho } => Brdf::Lambert {
                rho: s(rho, linear),
            },
            Brdf::BlinnPhong { exponent } => Brdf::BlinnPhong {
                exponent: s(exponent, exponent_warp),
            },
            Brdf::OrenNayarFull { rho, sigma: sg } => Brdf::OrenNayarFull {
                rho: s(rho, linear),
                sigma: s(sg, sigma),
            },
            Brdf::OrenNayarQualitative { rho, sigma: sg } => Brdf::OrenNayarQualitative {
                rho: s(rho, linear),
                sigma: s(sg, sigma),
            },
            Brdf::Ggx { alpha, f0, f90 } => Brdf::Ggx {
                alpha: s(alpha, roughness),
                f0: s(f0, linear),
                f90: s(f90, linear),
            },
            Brdf::GltfMetalRough { alpha, metallic } => Brdf::GltfMetalRough {
                alpha: s(alpha, roughness),
                metallic: s(metallic, linear),
            },
            Brdf::KajiyaKay { kd, ks, p } => Brdf::KajiyaKay {
                kd: s(kd, linear),
                ks: s(ks, linear),
                p: s(p, exponent_warp),
            },
            Brdf::PennerSkin {
                rho,
                curvature_per_mm,
            } => Brdf::PennerSkin {
                rho: s(rho, linear),
                curvature_per_mm: s(curvature_per_mm, curvature),
            },
            // Its ranges are the engine's: no warp into [0, 1] (8-bit UNORM clamps to it).
            Brdf::Engine { id, params } => Brdf::Engine {
                id,
                params: params.map(|x| s(x, linear)),
            },
        }
    }
}

/// Shading points with normals all over the sphere (octahedral error depends on where the
/// normal falls): `count` Halton points, V and L uniform over the hemisphere of N, T in its
/// tangent plane.
pub fn encoding_directions(count: usize) -> Vec<[V3<f64>; 4]> {
    (0..count)
        .map(|i| {
            let n = sphere_point(2.0 * halton(i, 2) - 1.0, halton(i, 3));
            let helper = if n[2].abs() < 0.9 {
                [0.0, 0.0, 1.0]
            } else {
                [1.0, 0.0, 0.0]
            };
            let t = normalize(cross(helper, n)).expect("helper is not parallel to n");
            let b = cross(n, t);
            let local = |z: f64, s: f64| {
                let d = sphere_point(z, s);
                [0, 1, 2].map(|k| t[k] * d[0] + b[k] * d[1] + n[k] * d[2])
            };
            let v = local(halton(i, 5), halton(i, 7));
            let l = local(halton(i, 11), halton(i, 13));
            [n, t, v, l]
        })
        .collect()
}

/// The error an encoding adds, over a set of shading points, in units of the BRDF's value and
/// relative to its peak over the set.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EncodingError {
    /// The largest error over the points.
    pub max_abs: f64,
    /// The mean error over the points.
    pub mean_abs: f64,
    /// The largest reference value over the points: the scale the errors are read against.
    pub peak: f64,
    /// The largest angle (degrees) between a normal and its stored version.
    pub max_normal_degrees: f64,
}

impl EncodingError {
    /// Round-trips the normal (per point) and the parameters through the encodings and compares
    /// the f64 value with the stored inputs against the value with the exact ones, at `directions`
    /// (`[N, T, V, L]` each, e.g. [`encoding_directions`]).
    pub fn measure(
        brdf: Brdf,
        normals: NormalEncoding,
        params: ParamEncoding,
        directions: &[[V3<f64>; 4]],
    ) -> Self {
        let stored = params.round_trip(brdf);
        let (mut max_abs, mut sum, mut peak, mut max_angle) = (0f64, 0f64, 0f64, 0f64);
        for &[n, t, v, l] in directions {
            let n_stored = normals.round_trip(n);
            let reference = brdf.reference([n, t, v, l]);
            let seen = stored.reference([n_stored, t, v, l]);
            let error = (0..3)
                .map(|k| (seen[k] - reference[k]).abs())
                .fold(0.0, f64::max);
            max_abs = max_abs.max(error);
            sum += error;
            peak = reference.into_iter().fold(peak, f64::max);
            if let (Some(a), Some(b)) = (normalize(n), normalize(n_stored)) {
                max_angle = max_angle.max(angle_between(a, b).to_degrees());
            }
        }
        Self {
            max_abs,
            mean_abs: sum / directions.len().max(1) as f64,
            peak,
            max_normal_degrees: max_angle,
        }
    }

    /// `max_abs / peak`: the error as a fraction of the brightest value.
    pub fn max_relative(&self) -> f64 {
        self.max_abs / self.peak.max(f64::MIN_POSITIVE)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn octahedral_round_trips_every_octant() {
        for d in encoding_directions(2000) {
            let n = d[0];
            let back = octahedral_decode(octahedral_encode(n));
            assert!(
                (0..3).all(|k| (back[k] - n[k]).abs() < 1e-12),
                "{n:?} {back:?}"
            );
        }
    }

    #[test]
    fn octahedral_16_bit_error_is_tiny_and_8_bit_is_not() {
        let dirs = encoding_directions(4000);
        let brdf = Brdf::Lambert { rho: 1.0 };
        let angle = |bits| {
            EncodingError::measure(
                brdf,
                NormalEncoding::Octahedral { bits },
                ParamEncoding::Float16,
                &dirs,
            )
            .max_normal_degrees
        };
        // One snorm step is 2 / (2^bits - 2) of the square; near the octahedron's corners it
        // spans about twice that in angle.
        assert!(angle(16) < 0.01, "{}", angle(16));
        assert!(angle(8) > 0.3 && angle(8) < 1.5, "{}", angle(8));
    }

    #[test]
    fn unorm_parameters_round_trip_their_range() {
        let stored = ParamEncoding::Unorm8.round_trip(Brdf::BlinnPhong { exponent: 1e4 });
        let Brdf::BlinnPhong { exponent } = stored else {
            unreachable!()
        };
        assert!((exponent - 1e4).abs() < 1e-6 * 1e4, "{exponent}");
        let skin = ParamEncoding::Unorm8.round_trip(Brdf::PennerSkin {
            rho: 1.0,
            curvature_per_mm: 1e6,
        });
        assert!(
            matches!(skin, Brdf::PennerSkin { curvature_per_mm, .. } if curvature_per_mm.is_finite())
        );
    }
}
