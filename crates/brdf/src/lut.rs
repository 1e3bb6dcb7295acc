//! BRDF look-up tables: the talk's alternative to multi-pass stencil and branching. A table
//! holds `f_r * cos(theta_L)` of one material, sampled on a regular grid over the model's
//! geometric axes and looked up with multilinear interpolation.
//!
//! # Two factors per entry
//! A value is affine in the surface's colour, `tint * tinted + white` ([`crate::Parts`]), so an
//! entry holds both factors where the model has a white part: the tinted RGB and the white
//! scalar, as a split-sum table stores a scale and a bias per entry. glTF's metallic-roughness
//! (its dielectric specular is white) and an engine BRDF with a `white` function are held so;
//! a model without one stores the tinted RGB alone. What no table holds is a value that is not
//! affine in the tint: an engine BRDF whose function takes the tint itself is refused, naming
//! why ([`crate::BrdfSet::tabulable`]).
//!
//! # Parameterisation
//! The axes are angles (not cosines): the specular lobes are as wide in angle at grazing as at
//! normal incidence, so a uniform angle grid spends its samples evenly. Grid point `i` of `res`
//! sits at `u = i / (res - 1)` on every axis, so both ends of each range are sampled exactly.
//!
//! | model | axes | size |
//! |---|---|---|
//! | lambert | `N.L` in [0, 1] (exact: Lambert is linear in it) | `res` |
//! | blinn_phong, oren_nayar_*, ggx | `theta_L`, `theta_V` in [0, pi/2], `phi` (azimuth between L and V about N) in [0, pi] | `res^3` |
//! | kajiya_kay | angles `T^L`, `T^V` in [0, pi] | `res^2` |
//! | gltf_metal_rough | as blinn_phong | `res^3`, tinted and white |
//! | penner_skin | `theta` (N to L) in [0, pi], curvature as `k / (k + 1)` with `k` in 1/mm | `res^2`, RGB |
//! | an engine's that reads no tangent and takes no tint | as blinn_phong | `res^3`, RGB (and white, with a white part) |
//!
//! An engine BRDF ([`crate::BrdfSet`]) has no CPU spelling: its table is the same grid
//! ([`Lut::grid`]) filled by its own GLSL on the GPU (histencil-vk's `LutTables`), then
//! [`Lut::from_values`]. One that reads no tangent is taken to be isotropic, a function of the
//! three angles; one that reads the tangent, or takes the tint, is refused
//! ([`crate::BrdfSet::tabulable`]).
//!
//! Every parameter is fixed at bake time except the skin's curvature, which varies per pixel and
//! is therefore an axis: the "limited control over parameters" the talk warns about is real, a
//! material with another roughness needs another table. The three angles are the complete
//! geometry of an isotropic BRDF, so the only error is the grid's; the report
//! ([`LutAccuracy::measure`]) states it against resolution.

use crate::cases::{halton, sphere_point};
use crate::model::{Brdf, Parts};
use crate::vector::{above_horizon, angle_between, dot, normalize, scale, sub, V3};
use std::f64::consts::{FRAC_PI_2, PI};

/// The geometric axes a table is sampled over (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LutAxes {
    /// `N.L`.
    CosLight,
    /// `theta_L`, `theta_V`, `phi`.
    Isotropic,
    /// The angles between T and L, and between T and V.
    Fibre,
    /// `theta` between N and L, and the warped curvature.
    SkinCurvature,
}

/// Skin curvature (1/mm) stored at the far end of the curvature axis: 1/k^2 from the ring
/// average, far below the f32 resolution of the table.
const SKIN_CURVATURE_AT_END: f64 = 1e6;

impl LutAxes {
    /// Every parameterisation, in [`LutAxes::index`] order.
    pub const ALL: [LutAxes; 4] = [
        LutAxes::CosLight,
        LutAxes::Isotropic,
        LutAxes::Fibre,
        LutAxes::SkinCurvature,
    ];

    /// The code the GPU tables store (GLSL `LUT_AXES_*`, generated from [`LutAxes::ALL`]).
    pub fn index(self) -> u32 {
        self as u32
    }

    /// The name of the GLSL constant holding [`LutAxes::index`].
    pub fn glsl_constant(self) -> &'static str {
        match self {
            LutAxes::CosLight => "LUT_AXES_COS_LIGHT",
            LutAxes::Isotropic => "LUT_AXES_ISOTROPIC",
            LutAxes::Fibre => "LUT_AXES_FIBRE",
            LutAxes::SkinCurvature => "LUT_AXES_SKIN_CURVATURE",
        }
    }

    /// The parameterisation a model's table is baked over: the fewest angles its value depends on.
    pub fn of(brdf: &Brdf) -> Self {
        match brdf {
            Brdf::Lambert { .. } => LutAxes::CosLight,
            Brdf::BlinnPhong { .. }
            | Brdf::OrenNayarFull { .. }
            | Brdf::OrenNayarQualitative { .. }
            | Brdf::Ggx { .. }
            | Brdf::GltfMetalRough { .. } => LutAxes::Isotropic,
            Brdf::KajiyaKay { .. } => LutAxes::Fibre,
            Brdf::PennerSkin { .. } => LutAxes::SkinCurvature,
            // An engine BRDF that a table can hold reads no tangent
            // (`BrdfSet::tabulable`): a function of N, V and L, taken as isotropic.
            Brdf::Engine { .. } => LutAxes::Isotropic,
        }
    }

    /// How many axes the table has (1 to 3).
    pub fn dimensions(self) -> usize {
        match self {
            LutAxes::CosLight => 1,
            LutAxes::Fibre | LutAxes::SkinCurvature => 2,
            LutAxes::Isotropic => 3,
        }
    }

    /// The table coordinates (each in [0, 1]) of a shading point, or `None` where the model
    /// gives 0 without looking anything up (zero vectors; `N.L <= 0` for the surface models, as
    /// their gate says; a view below the horizon is looked up as grazing, as they evaluate it). `curvature_per_mm` is only read by skin.
    pub fn coordinates(
        self,
        [n, t, v, l]: [V3<f64>; 4],
        curvature_per_mm: f64,
    ) -> Option<[f64; 3]> {
        match self {
            LutAxes::CosLight => {
                let (n, l) = (normalize(n)?, normalize(l)?);
                let cos = dot(n, l).min(1.0);
                (cos > 0.0).then_some([cos, 0.0, 0.0])
            }
            LutAxes::Isotropic => {
                let (n, v, l) = (normalize(n)?, normalize(v)?, normalize(l)?);
                if dot(n, l) <= 0.0 {
                    return None;
                }
                let (v, _) = above_horizon(n, v)?;
                let in_plane = |d: V3<f64>| normalize(sub(d, scale(n, dot(n, d))));
                let phi = match (in_plane(l), in_plane(v)) {
                    (Some(lp), Some(vp)) => angle_between(lp, vp),
                    // Along the normal the azimuth is undefined and the BRDF does not depend
                    // on it.
                    _ => 0.0,
                };
                Some([
                    angle_between(n, l) / FRAC_PI_2,
                    angle_between(n, v) / FRAC_PI_2,
                    phi / PI,
                ])
            }
            LutAxes::Fibre => {
                let (t, v, l) = (normalize(t)?, normalize(v)?, normalize(l)?);
                Some([angle_between(t, l) / PI, angle_between(t, v) / PI, 0.0])
            }
            LutAxes::SkinCurvature => {
                let (n, l) = (normalize(n)?, normalize(l)?);
                let k = curvature_per_mm.max(0.0);
                Some([angle_between(n, l) / PI, k / (k + 1.0), 0.0])
            }
        }
    }

    /// Directions `[N, T, V, L]` at table coordinates `u`, and the skin curvature there.
    fn directions(self, u: [f64; 3]) -> ([V3<f64>; 4], f64) {
        let n = [0.0, 0.0, 1.0];
        let x = [1.0, 0.0, 0.0];
        let polar = |theta: f64, phi: f64| {
            [
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            ]
        };
        match self {
            LutAxes::CosLight => {
                let l = [(1.0 - u[0] * u[0]).max(0.0).sqrt(), 0.0, u[0]];
                ([n, x, n, l], 0.0)
            }
            LutAxes::Isotropic => {
                let l = polar(u[0] * FRAC_PI_2, 0.0);
                let v = polar(u[1] * FRAC_PI_2, u[2] * PI);
                ([n, x, v, l], 0.0)
            }
            LutAxes::Fibre => {
                // T along +Z; L and V at their angles to it.
                let l = polar(u[0] * PI, 0.0);
                let v = polar(u[1] * PI, FRAC_PI_2);
                ([x, n, v, l], 0.0)
            }
            LutAxes::SkinCurvature => {
                let l = polar(u[0] * PI, 0.0);
                let k = if u[1] >= 1.0 {
                    SKIN_CURVATURE_AT_END
                } else {
                    u[1] / (1.0 - u[1])
                };
                ([n, x, n, l], k)
            }
        }
    }
}

/// Why a table could not be built.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum LutError {
    /// The resolution is outside `2..=`[`Lut::MAX_RESOLUTION`].
    #[error("LUT resolution {0} is out of range (2..={max})", max = Lut::MAX_RESOLUTION)]
    Resolution(u32),
    /// An engine BRDF a table cannot hold: one whose function takes the tint (a value that is
    /// not affine in the tint has no two factors to store), or one that reads the tangent (the
    /// tables are over the three angles of an isotropic BRDF; the fibre table's axes are
    /// Kajiya-Kay's own); or any engine BRDF given to [`Lut::bake`], which has no CPU spelling.
    #[error("no look-up table for engine BRDF `{brdf}`: {reason}")]
    EngineUntabulable {
        /// Its name.
        brdf: &'static str,
        /// Why a table cannot hold it.
        reason: &'static str,
    },
    /// Values handed to [`Lut::from_values`] that are not one per grid point (the white
    /// part's: one per grid point for a model with a white part, none for another).
    #[error("a {resolution}-point table of {brdf} has {expected} grid points, not {given}")]
    ValueCount {
        /// The material's model.
        brdf: &'static str,
        /// Grid points per axis.
        resolution: u32,
        /// Grid points of the table.
        expected: usize,
        /// Values given.
        given: usize,
    },
}

/// One grid point of a table ([`Lut::grid`]): its directions `[N, T, V, L]`, and the material
/// evaluated there.
pub type GridPoint = ([V3<f64>; 4], Brdf);

/// A baked table for one material.
#[derive(Clone, Debug)]
pub struct Lut {
    /// The material the table was baked from.
    pub brdf: Brdf,
    /// What the table's axes are ([`LutAxes::of`] the material).
    pub axes: LutAxes,
    /// Grid points per axis.
    pub resolution: u32,
    /// The tinted factor of `f_r * cos` at the grid points, RGB, first axis fastest.
    pub values: Vec<[f32; 3]>,
    /// The white factor at the same points, for a model with a white part ([`Lut::has_white`]);
    /// empty for the others, whose entries are the tinted RGB alone.
    pub white: Vec<f32>,
}

impl Lut {
    /// 512 points per axis is 1.5 GiB of RGB f32 for a 3D table (2 GiB with a white part):
    /// beyond anything useful, and refused by the device's storage-buffer range long before.
    pub const MAX_RESOLUTION: u32 = 512;

    /// `Ok` for a resolution [`Lut::bake`] accepts: 2 to [`Lut::MAX_RESOLUTION`] points per axis.
    pub fn check_resolution(resolution: u32) -> Result<(), LutError> {
        if (2..=Self::MAX_RESOLUTION).contains(&resolution) {
            Ok(())
        } else {
            Err(LutError::Resolution(resolution))
        }
    }

    /// Samples `brdf` (its f64 reference) at `resolution` points per axis.
    pub fn bake(brdf: Brdf, resolution: u32) -> Result<Self, LutError> {
        Self::check_resolution(resolution)?;
        if let Brdf::Engine { id, .. } = brdf {
            return Err(LutError::EngineUntabulable {
                brdf: id.name(),
                reason: "it has no CPU spelling; its table is baked by its GLSL \
                         (histencil-vk's LutTables)",
            });
        }
        let parts: Vec<_> = Self::grid(brdf, resolution)?
            .into_iter()
            .map(|(dirs, at)| at.reference_parts(dirs))
            .collect();
        let values = parts.iter().map(|p| p.tinted.map(|x| x as f32)).collect();
        let white = if brdf.has_white_part() {
            parts.iter().map(|p| p.white as f32).collect()
        } else {
            Vec::new()
        };
        Self::from_values(brdf, resolution, values, white)
    }

    /// Whether the entries hold a white factor beside the tinted RGB.
    pub fn has_white(&self) -> bool {
        !self.white.is_empty()
    }

    /// Every grid point of `brdf`'s table at `resolution` points per axis, first axis fastest:
    /// its directions `[N, T, V, L]` and the material evaluated there (the skin's curvature is
    /// an axis). What [`Lut::bake`] evaluates on the CPU, and what an engine BRDF's table is
    /// evaluated at by its GLSL (histencil-vk's `LutTables`): the grid is one, whoever fills it.
    ///
    /// # Errors
    /// [`LutError::Resolution`] outside `2..=`[`Lut::MAX_RESOLUTION`].
    pub fn grid(brdf: Brdf, resolution: u32) -> Result<Vec<GridPoint>, LutError> {
        Self::check_resolution(resolution)?;
        let axes = LutAxes::of(&brdf);
        let dims = axes.dimensions();
        let r = resolution as usize;
        let count = r.pow(dims as u32);
        let step = 1.0 / f64::from(resolution - 1);
        Ok((0..count)
            .map(|index| {
                let mut u = [0.0; 3];
                let mut rest = index;
                for axis in u.iter_mut().take(dims) {
                    *axis = (rest % r) as f64 * step;
                    rest /= r;
                }
                let (dirs, curvature) = axes.directions(u);
                let at = match brdf {
                    Brdf::PennerSkin { rho, .. } => Brdf::PennerSkin {
                        rho,
                        curvature_per_mm: curvature,
                    },
                    other => other,
                };
                (dirs, at)
            })
            .collect())
    }

    /// A table of `brdf` from its factors at the points of [`Lut::grid`], in that order: the
    /// tinted RGB, and the white part (empty for a table without one).
    ///
    /// # Errors
    /// [`LutError::Resolution`], and [`LutError::ValueCount`] unless there is one tinted value
    /// per grid point and, when `white` is given (always for glTF's metallic-roughness), one
    /// white value per grid point.
    pub fn from_values(
        brdf: Brdf,
        resolution: u32,
        values: Vec<[f32; 3]>,
        white: Vec<f32>,
    ) -> Result<Self, LutError> {
        Self::check_resolution(resolution)?;
        let axes = LutAxes::of(&brdf);
        let expected = (resolution as usize).pow(axes.dimensions() as u32);
        // The white part may be absent, except for a built-in that has one (an engine BRDF's is
        // its set's to say); the tinted part may not.
        let white_optional = !brdf.has_white_part();
        let wrong = [(values.len(), false), (white.len(), white_optional)]
            .into_iter()
            .find(|&(given, optional)| given != expected && !(optional && given == 0));
        if let Some((given, _)) = wrong {
            return Err(LutError::ValueCount {
                brdf: brdf.name(),
                resolution,
                expected,
                given,
            });
        }
        Ok(Self {
            brdf,
            axes,
            resolution,
            values,
            white,
        })
    }

    /// The table's two factors at a shading point: multilinear interpolation between grid
    /// points, in f32 as a shader does it (the white part 0 for a table without one). Gated
    /// points give 0.
    pub fn lookup(&self, dirs: [V3<f64>; 4]) -> Parts<f32> {
        let mut out = Parts {
            tinted: [0.0; 3],
            white: 0.0,
        };
        let Some(u) = self.axes.coordinates(dirs, self.curvature_per_mm()) else {
            return out;
        };
        let dims = self.axes.dimensions();
        let r = self.resolution as usize;
        let last = (self.resolution - 1) as f32;
        // Per axis: the lower grid index and the weight of the upper one.
        let mut base = [0usize; 3];
        let mut frac = [0f32; 3];
        for a in 0..dims {
            let x = (u[a] as f32).clamp(0.0, 1.0) * last;
            let i = (x.floor() as usize).min(r - 2);
            base[a] = i;
            frac[a] = x - i as f32;
        }
        for corner in 0..(1usize << dims) {
            let mut weight = 1f32;
            let mut index = 0usize;
            let mut stride = 1usize;
            for a in 0..dims {
                let upper = (corner >> a) & 1;
                weight *= if upper == 1 { frac[a] } else { 1.0 - frac[a] };
                index += (base[a] + upper) * stride;
                stride *= r;
            }
            for (o, v) in out.tinted.iter_mut().zip(self.values[index]) {
                *o += weight * v;
            }
            if let Some(w) = self.white.get(index) {
                out.white += weight * w;
            }
        }
        out
    }

    /// The skin curvature the table is looked up at (0 for the other models): the material's
    /// own, since curvature is an axis of the skin table.
    pub fn curvature_per_mm(&self) -> f64 {
        match self.brdf {
            Brdf::PennerSkin {
                curvature_per_mm, ..
            } => curvature_per_mm,
            _ => 0.0,
        }
    }

    /// Bytes of the table: RGB f32 per entry, and an f32 more with a white part.
    pub fn size_bytes(&self) -> usize {
        self.values.len() * std::mem::size_of::<[f32; 3]>()
            + self.white.len() * std::mem::size_of::<f32>()
    }
}

/// The fixed direction set the tables are judged on: `count` Halton points, L and V uniform over
/// the upper hemisphere (L over the whole sphere for skin, which wraps), N = +Z, T = +X.
pub fn report_directions(count: usize) -> Vec<[V3<f64>; 4]> {
    (0..count)
        .map(|i| {
            let l = sphere_point(2.0 * halton(i, 2) - 1.0, halton(i, 3));
            let v = sphere_point(halton(i, 5), halton(i, 7));
            [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], v, l]
        })
        .collect()
}

/// A table's error against the f64 reference over [`report_directions`], in the units of the
/// BRDF's value (`f_r * cos`), worst channel: per channel `|tinted error| + |white error|`,
/// which bounds the error of a surface of any tint in [0, 1] (for a table without a white part
/// that is the tinted error alone, a white surface's).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LutAccuracy {
    /// The largest error over the set.
    pub max_abs: f64,
    /// The mean error over the set.
    pub mean_abs: f64,
    /// The largest reference value over the set: the scale the errors are read against.
    pub peak: f64,
}

impl LutAccuracy {
    /// Looks the table up at every shading point of `directions` (`[N, T, V, L]` each) and
    /// compares with [`Brdf::reference`](crate::Brdf::reference).
    pub fn measure(lut: &Lut, directions: &[[V3<f64>; 4]]) -> Self {
        let (mut max_abs, mut sum, mut peak) = (0f64, 0f64, 0f64);
        for dirs in directions {
            let parts = lut.brdf.reference_parts(*dirs);
            let reference = parts.at_white();
            let table = lut.lookup(*dirs);
            let white = (f64::from(table.white) - parts.white).abs();
            let error = (0..3)
                .map(|k| (f64::from(table.tinted[k]) - parts.tinted[k]).abs() + white)
                .fold(0.0, f64::max);
            max_abs = max_abs.max(error);
            sum += error;
            peak = reference.into_iter().fold(peak, f64::max);
        }
        Self {
            max_abs,
            mean_abs: sum / directions.len().max(1) as f64,
            peak,
        }
    }
}

/// The materials the LUT report covers: one or two per model, spanning sharp and broad lobes.
pub fn report_materials() -> Vec<Brdf> {
    vec![
        Brdf::Lambert { rho: 0.9 },
        Brdf::BlinnPhong { exponent: 16.0 },
        Brdf::BlinnPhong { exponent: 200.0 },
        Brdf::OrenNayarFull {
            rho: 0.9,
            sigma: 0.35,
        },
        Brdf::OrenNayarQualitative {
            rho: 0.9,
            sigma: 0.35,
        },
        Brdf::Ggx {
            alpha: 0.3,
            f0: 0.04,
            f90: 1.0,
        },
        Brdf::Ggx {
            alpha: 0.05,
            f0: 0.04,
            f90: 1.0,
        },
        Brdf::KajiyaKay {
            kd: 0.4,
            ks: 0.6,
            p: 30.0,
        },
        Brdf::PennerSkin {
            rho: 0.9,
            curvature_per_mm: 0.3,
        },
        Brdf::PennerSkin {
            rho: 0.9,
            curvature_per_mm: 1.5,
        },
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_table_from_values_is_the_baked_one_and_counts_its_points() {
        let ggx = Brdf::Ggx {
            alpha: 0.16,
            f0: 0.04,
            f90: 1.0,
        };
        let baked = Lut::bake(ggx, 5).unwrap();
        let grid = Lut::grid(ggx, 5).unwrap();
        assert_eq!(grid.len(), 125);
        let values = grid
            .iter()
            .map(|(dirs, at)| at.reference(*dirs).map(|x| x as f32))
            .collect();
        let again = Lut::from_values(ggx, 5, values, Vec::new()).unwrap();
        assert_eq!(again.values, baked.values);
        assert!(!baked.has_white());
        assert!(matches!(
            Lut::from_values(ggx, 5, vec![[0.0; 3]; 125], vec![0.0; 3]),
            Err(LutError::ValueCount {
                expected: 125,
                given: 3,
                ..
            })
        ));
        assert!(matches!(
            Lut::from_values(ggx, 5, vec![[0.0; 3]; 124], Vec::new()),
            Err(LutError::ValueCount {
                expected: 125,
                given: 124,
                ..
            })
        ));
    }

    #[test]
    fn grid_points_are_reproduced_exactly() {
        let brdf = Brdf::Ggx {
            alpha: 0.3,
            f0: 0.04,
            f90: 1.0,
        };
        let lut = Lut::bake(brdf, 5).unwrap();
        let (dirs, _) = lut.axes.directions([0.25, 0.5, 0.75]);
        let reference = brdf.reference(dirs)[0];
        let found = f64::from(lut.lookup(dirs).tinted[0]);
        assert!((found - reference).abs() < 1e-6 * reference.max(1.0));
    }

    /// glTF's metallic-roughness is `base * tinted + white`: its table holds both factors, and
    /// at a grid point gives each as the reference does, for any base colour.
    #[test]
    fn a_table_with_a_white_part_holds_both_factors() {
        let brdf = Brdf::GltfMetalRough {
            alpha: 0.3,
            metallic: 0.4,
        };
        let lut = Lut::bake(brdf, 5).unwrap();
        assert!(lut.has_white());
        assert_eq!(lut.size_bytes(), 125 * 16);
        // Its white part cannot be left out: the dielectric specular would go in silence.
        assert!(matches!(
            Lut::from_values(brdf, 5, lut.values.clone(), Vec::new()),
            Err(LutError::ValueCount { given: 0, .. })
        ));
        let (dirs, _) = lut.axes.directions([0.25, 0.5, 0.75]);
        let reference = brdf.reference_parts(dirs);
        assert!(reference.white > 1e-3, "{reference:?}");
        let found = lut.lookup(dirs);
        let close = |a: f32, b: f64| (f64::from(a) - b).abs() < 1e-6 * b.max(1.0);
        assert!(
            close(found.white, reference.white),
            "{found:?} {reference:?}"
        );
        assert!(close(found.tinted[1], reference.tinted[1]), "{found:?}");
        let tint = [0.9, 0.2, 0.05];
        let shaded = found.tinted_by(tint.map(|x| x as f32));
        for (k, t) in tint.into_iter().enumerate() {
            assert!(close(shaded[k], t * reference.tinted[k] + reference.white));
        }
    }

    #[test]
    fn lambert_is_exact_and_gated() {
        let lut = Lut::bake(Brdf::Lambert { rho: 0.5 }, 2).unwrap();
        let error = LutAccuracy::measure(&lut, &report_directions(256));
        assert!(error.max_abs < 1e-7, "{error:?}");
    }

    #[test]
    fn axes_codes_follow_all() {
        for (i, axes) in LutAxes::ALL.into_iter().enumerate() {
            assert_eq!(axes.index() as usize, i);
        }
    }

    #[test]
    fn resolution_is_checked() {
        let brdf = Brdf::Lambert { rho: 1.0 };
        assert_eq!(Lut::bake(brdf, 1).unwrap_err(), LutError::Resolution(1));
        assert!(Lut::bake(brdf, 513).is_err());
    }

    #[test]
    fn coordinates_cover_the_unit_cube() {
        for dirs in report_directions(512) {
            for axes in [
                LutAxes::Isotropic,
                LutAxes::Fibre,
                LutAxes::SkinCurvature,
                LutAxes::CosLight,
            ] {
                if let Some(u) = axes.coordinates(dirs, 3.0) {
                    assert!(u.iter().all(|x| (0.0..=1.0).contains(x)), "{axes:?} {u:?}");
                }
            }
        }
    }
}
