//! A BRDF with its parameters: parsed from a name and a JSON object, evaluated in f64 or f32,
//! and packed for the GLSL spelling (`crates/vk/shaders/include/brdf/eval.glsl`).

use crate::id::{BrdfId, EngineBrdf};
use crate::models;
use crate::vector::{c, Real, V3};
#[cfg(feature = "files")]
use serde_json::{Map, Value};

/// A BRDF's value in two parts: `f_r * cos(theta_L) = tint * tinted + white`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Parts<R> {
    /// The part the surface's colour scales, per RGB channel.
    pub tinted: [R; 3],
    /// The part added untinted (glTF's dielectric specular); 0 for every other model.
    pub white: R,
}

impl<R: Real> Parts<R> {
    /// The value for a white surface.
    pub fn at_white(self) -> [R; 3] {
        self.tinted.map(|x| x + self.white)
    }

    /// The value for a surface of colour `tint`. With no white part this is exactly
    /// `tint * tinted`, as the talk's models always were.
    pub fn tinted_by(self, tint: [R; 3]) -> [R; 3] {
        let mut out = [R::zero(); 3];
        for ((o, t), x) in out.iter_mut().zip(tint).zip(self.tinted) {
            *o = if self.white == R::zero() {
                t * x
            } else {
                t * x + self.white
            };
        }
        out
    }

    /// The four channels compared between spellings: tinted RGB, then white.
    pub fn channels(self) -> [R; 4] {
        let [r, g, b] = self.tinted;
        [r, g, b, self.white]
    }

    /// The parts from their [`Parts::channels`], as the GPU evaluators return them (a `vec4`).
    pub fn from_channels([r, g, b, white]: [R; 4]) -> Self {
        Self {
            tinted: [r, g, b],
            white,
        }
    }
}

/// A BRDF model and its parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Brdf {
    /// Lambert's diffuse, albedo `rho`.
    Lambert {
        /// Albedo in [0, 1].
        rho: f64,
    },
    /// Normalized Blinn-Phong, the talk's specular.
    BlinnPhong {
        /// The cosine power `n`, 0 to 1e4.
        exponent: f64,
    },
    /// Oren-Nayar's rough diffuse with the inter-reflection term (1994).
    OrenNayarFull {
        /// Albedo in [0, 1].
        rho: f64,
        /// Slope deviation in radians, 0 to pi/2.
        sigma: f64,
    },
    /// Oren-Nayar's qualitative model: the cheaper form, without inter-reflection.
    OrenNayarQualitative {
        /// Albedo in [0, 1].
        rho: f64,
        /// Slope deviation in radians, 0 to pi/2.
        sigma: f64,
    },
    /// `alpha` is the GGX alpha (perceptual roughness squared).
    Ggx {
        /// GGX alpha, 0 to 1 (clamped below to [`GGX_MIN_ALPHA`](crate::GGX_MIN_ALPHA)).
        alpha: f64,
        /// Schlick Fresnel at normal incidence (0.04 when parsed without it).
        f0: f64,
        /// Schlick Fresnel at grazing incidence (1 when parsed without it).
        f90: f64,
    },
    /// Kajiya-Kay hair and fibre, shaded along the tangent T.
    KajiyaKay {
        /// Diffuse weight.
        kd: f64,
        /// Specular weight.
        ks: f64,
        /// Specular exponent, 0 to 1e4.
        p: f64,
    },
    /// Penner's pre-integrated skin: wraps light past the terminator by the surface's curvature.
    PennerSkin {
        /// Albedo in [0, 1].
        rho: f64,
        /// Curvature in 1/mm (a radius of `r` mm is `1 / r`); 0 is flat skin.
        curvature_per_mm: f64,
    },
    /// glTF's metallic-roughness BRDF; `alpha` is roughness squared. Its base colour is the
    /// surface's tint, which it does not simply scale ([`Brdf::eval_parts`]).
    GltfMetalRough {
        /// Roughness squared, 0 to 1.
        alpha: f64,
        /// 0 for a dielectric, 1 for a metal.
        metallic: f64,
    },
    /// An engine's own BRDF ([`BrdfSet`](crate::BrdfSet)), evaluated by its GLSL only: it has
    /// no CPU spelling, so [`Brdf::eval_parts`] gives NaN for it and every path that needs one
    /// (the f64 reference, [`crate::lut::Lut::bake`]) refuses it first; its LUT table is filled
    /// by its GLSL on the GPU.
    Engine {
        /// Which of the set's BRDFs.
        id: EngineBrdf,
        /// Its parameters in manifest order (`p.x`, `p.y`, `p.z` in its GLSL), each held to its
        /// range by the set that parsed it.
        params: [f64; 3],
    },
}

/// Names accepted by [`Brdf::parse`], in id order ([`BrdfId::ALL`]).
pub const MODEL_NAMES: [&str; 8] = {
    let mut names = [""; 8];
    let mut i = 0;
    while i < names.len() {
        names[i] = BrdfId::ALL[i].name();
        i += 1;
    }
    names
};

/// Why a BRDF description was refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum BrdfError {
    /// The name is none of [`MODEL_NAMES`].
    #[error("unknown BRDF `{0}` (known: {names}; an engine's own BRDFs are known only with the \
             BRDF set that declares them, its brdfs.toml: `--brdfs DIR` on the command line, the \
             BRDF folder of histencil_shaders_compile in C, BrdfSet::load in Rust)",
             names = MODEL_NAMES.join(", "))]
    UnknownModel(String),
    /// A name that a set with BRDFs of an engine's own does not hold
    /// ([`crate::BrdfSet::parse`]): its names are listed, with the nearest when one is close.
    #[error("unknown BRDF `{name}` (the BRDF set holds: {known}){nearest}")]
    UnknownInSet {
        /// The name given.
        name: String,
        /// The set's names, built-ins first.
        known: String,
        /// `; did you mean `x`?` when a name of the set is one or two edits away, else empty.
        nearest: String,
    },
    /// A parameter the model does not take.
    #[error("{model}: unknown parameter `{param}` (accepted: {accepted})")]
    UnknownParam {
        /// The model's name.
        model: &'static str,
        /// The parameter given.
        param: String,
        /// The parameters the model takes, comma-separated.
        accepted: String,
    },
    /// A parameter the model needs was not given.
    #[error("{model}: missing parameter `{param}`")]
    MissingParam {
        /// The model's name.
        model: &'static str,
        /// The parameter missing.
        param: &'static str,
    },
    /// A parameter outside its [`Range`] or not a number.
    #[error("{model}: parameter `{param}` must be {rule}, got {value}")]
    BadParam {
        /// The model's name.
        model: &'static str,
        /// The parameter refused.
        param: &'static str,
        /// What the range allows, in words.
        rule: String,
        /// The value given, as written.
        value: String,
    },
    /// An engine BRDF's parameter outside its range or not a number.
    #[error("{model}: parameter `{param}` must be {rule}, got {value}")]
    BadEngineParam {
        /// The BRDF's name.
        model: &'static str,
        /// The parameter refused.
        param: String,
        /// What its range allows, in words.
        rule: String,
        /// The value given, as written.
        value: String,
    },
    /// A BRDF the lighting's set does not hold.
    #[error("BRDF `{model}` is not in this lighting's BRDF set ({set})")]
    NotInSet {
        /// The BRDF's name.
        model: &'static str,
        /// The set's BRDFs, comma-separated.
        set: String,
    },
    /// Two spellings of the same parameter were given (`alpha` and `perceptual_roughness`, ...).
    #[error("{model}: give exactly one of {options}")]
    Ambiguous {
        /// The model's name.
        model: &'static str,
        /// The spellings, of which exactly one is wanted.
        options: &'static str,
    },
}

/// Reads the numeric parameters of one model, refusing unknown keys.
#[cfg(feature = "files")]
struct Params<'a> {
    model: &'static str,
    map: &'a Map<String, Value>,
}

#[cfg(feature = "files")]
impl<'a> Params<'a> {
    fn new(
        model: &'static str,
        map: &'a Map<String, Value>,
        accepted: &[&str],
    ) -> Result<Self, BrdfError> {
        if let Some(unknown) = map.keys().find(|k| !accepted.contains(&k.as_str())) {
            return Err(BrdfError::UnknownParam {
                model,
                param: unknown.clone(),
                accepted: accepted.join(", "),
            });
        }
        Ok(Self { model, map })
    }

    fn optional(&self, param: &'static str, rule: Range) -> Result<Option<f64>, BrdfError> {
        let Some(value) = self.map.get(param) else {
            return Ok(None);
        };
        let bad = || BrdfError::BadParam {
            model: self.model,
            param,
            rule: rule.text(),
            value: value.to_string(),
        };
        let x = value.as_f64().ok_or_else(bad)?;
        if rule.holds(x) {
            Ok(Some(x))
        } else {
            Err(bad())
        }
    }

    fn required(&self, param: &'static str, rule: Range) -> Result<f64, BrdfError> {
        self.optional(param, rule)?.ok_or(BrdfError::MissingParam {
            model: self.model,
            param,
        })
    }

    /// Exactly one of two spellings of the same quantity.
    fn one_of(
        &self,
        (a, rule_a): (&'static str, Range),
        (b, rule_b): (&'static str, Range),
        options: &'static str,
    ) -> Result<Result<f64, f64>, BrdfError> {
        match (self.optional(a, rule_a)?, self.optional(b, rule_b)?) {
            (Some(x), None) => Ok(Ok(x)),
            (None, Some(y)) => Ok(Err(y)),
            _ => Err(BrdfError::Ambiguous {
                model: self.model,
                options,
            }),
        }
    }
}

/// The values a parameter accepts: every physically meaningful value, and no more than the f32
/// (GLSL) spelling evaluates without overflow, so the CPU reference and the GPU agree on every
/// accepted input. `brdf-eval`, glTF extras and [`Brdf::check`] (which `Scene::validate` calls)
/// all hold parameters to these.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Range {
    /// The smallest value accepted.
    pub min: f64,
    /// The largest value accepted ([`f64::MAX`] where there is no physical bound).
    pub max: f64,
}

impl Range {
    /// The values from `min` to `max`, both included.
    pub const fn new(min: f64, max: f64) -> Self {
        Self { min, max }
    }

    /// Whether `x` is a finite number inside the range.
    pub fn holds(self, x: f64) -> bool {
        x.is_finite() && (self.min..=self.max).contains(&x)
    }

    pub(crate) fn text(self) -> String {
        if self.max == f64::MAX {
            format!("a finite number >= {}", self.min)
        } else {
            format!("a number in [{}, {}]", self.min, self.max)
        }
    }
}

/// The parameter ranges, one per quantity (the book's glTF chapter, `docs/src/gltf.md`, lists
/// them under "Numbers that reach the GPU").
pub mod ranges {
    use super::Range;
    /// Albedo of Lambert, Oren-Nayar and skin: energy conservation bounds it by 1.
    pub const RHO: Range = Range::new(0.0, 1.0);
    /// Oren-Nayar's slope deviation in radians; beyond pi/2 it has no geometric meaning.
    pub const SIGMA: Range = Range::new(0.0, std::f64::consts::FRAC_PI_2);
    /// Blinn-Phong and Kajiya-Kay exponents: the hard cases test up to 1e4; beyond it the f32
    /// power of a cosine rounded to 1 no longer tracks the f64 lobe.
    pub const EXPONENT: Range = Range::new(0.0, 1e4);
    /// GGX alpha and perceptual roughness (the GPU clamps alpha below at 1e-3).
    pub const ROUGHNESS: Range = Range::new(0.0, 1.0);
    /// Reflectances and weights: Fresnel f0 and f90, Kajiya-Kay kd and ks.
    pub const UNIT: Range = Range::new(0.0, 1.0);
    /// Skin curvature in 1/mm: the hard cases test 0 to 1e6 (a radius of 1 nm).
    pub const CURVATURE_PER_MM: Range = Range::new(0.0, 1e6);
    /// Skin radius in mm, the reciprocal of the curvature's range.
    pub const RADIUS_MM: Range = Range::new(1e-6, f64::MAX);
}

/// What any parameter must be to reach the GPU as the number it is: finite in f32.
pub(crate) const F32_FINITE: Range = Range::new(-(f32::MAX as f64), f32::MAX as f64);

#[cfg(feature = "files")]
impl Brdf {
    /// Parses a model name and its parameters, e.g. `ggx` with `{"perceptual_roughness": 0.5}`.
    /// Every parameter is held to its [`ranges`].
    pub fn parse(name: &str, params: &Map<String, Value>) -> Result<Self, BrdfError> {
        use ranges::*;
        let model = MODEL_NAMES
            .iter()
            .copied()
            .find(|m| *m == name)
            .ok_or_else(|| BrdfError::UnknownModel(name.to_owned()))?;
        let p = |accepted: &[&str]| Params::new(model, params, accepted);
        Ok(match model {
            "lambert" => Brdf::Lambert {
                rho: p(&["rho"])?.required("rho", RHO)?,
            },
            "blinn_phong" => Brdf::BlinnPhong {
                exponent: p(&["n"])?.required("n", EXPONENT)?,
            },
            "oren_nayar_full" | "oren_nayar_qualitative" => {
                let p = p(&["rho", "sigma"])?;
                let (rho, sigma) = (p.required("rho", RHO)?, p.required("sigma", SIGMA)?);
                if model == "oren_nayar_full" {
                    Brdf::OrenNayarFull { rho, sigma }
                } else {
                    Brdf::OrenNayarQualitative { rho, sigma }
                }
            }
            "ggx" => {
                let p = p(&["alpha", "perceptual_roughness", "f0", "f90"])?;
                let alpha = p
                    .one_of(
                        ("alpha", ROUGHNESS),
                        ("perceptual_roughness", ROUGHNESS),
                        "`alpha` or `perceptual_roughness`",
                    )?
                    .unwrap_or_else(|roughness| roughness * roughness);
                Brdf::Ggx {
                    alpha,
                    f0: p.optional("f0", UNIT)?.unwrap_or(0.04),
                    f90: p.optional("f90", UNIT)?.unwrap_or(1.0),
                }
            }
            "kajiya_kay" => {
                let p = p(&["kd", "ks", "p"])?;
                Brdf::KajiyaKay {
                    kd: p.required("kd", UNIT)?,
                    ks: p.required("ks", UNIT)?,
                    p: p.required("p", EXPONENT)?,
                }
            }
            "penner_skin" => {
                let p = p(&["rho", "radius_mm", "curvature_per_mm"])?;
                let curvature_per_mm = p
                    .one_of(
                        ("curvature_per_mm", CURVATURE_PER_MM),
                        ("radius_mm", RADIUS_MM),
                        "`curvature_per_mm` or `radius_mm`",
                    )?
                    .unwrap_or_else(|radius| 1.0 / radius);
                Brdf::PennerSkin {
                    rho: p.required("rho", RHO)?,
                    curvature_per_mm,
                }
            }
            "gltf_metal_rough" => {
                // glTF's names: `roughness` (perceptual, squared to alpha) and `metallic`.
                let p = p(&["alpha", "roughness", "metallic"])?;
                let alpha = p
                    .one_of(
                        ("alpha", ROUGHNESS),
                        ("roughness", ROUGHNESS),
                        "`alpha` or `roughness`",
                    )?
                    .unwrap_or_else(|roughness| roughness * roughness);
                Brdf::GltfMetalRough {
                    alpha,
                    // glTF's default metallicFactor.
                    metallic: p.optional("metallic", UNIT)?.unwrap_or(1.0),
                }
            }
            _ => unreachable!("every name in MODEL_NAMES is handled"),
        })
    }
}

impl Brdf {
    /// Each parameter with its name, as `Brdf::parse` takes them (an engine BRDF's as `p.x`,
    /// `p.y`, `p.z`: its set has their names): what a C engine passes to name the material
    /// again, or a report prints.
    pub fn params(&self) -> Vec<(&'static str, f64)> {
        self.named_params()
            .into_iter()
            .map(|(name, x, _)| (name, x))
            .collect()
    }

    /// Each parameter with its name and range.
    fn named_params(&self) -> Vec<(&'static str, f64, Range)> {
        use ranges::*;
        match *self {
            Brdf::Lambert { rho } => vec![("rho", rho, RHO)],
            Brdf::BlinnPhong { exponent } => vec![("n", exponent, EXPONENT)],
            Brdf::OrenNayarFull { rho, sigma } | Brdf::OrenNayarQualitative { rho, sigma } => {
                vec![("rho", rho, RHO), ("sigma", sigma, SIGMA)]
            }
            Brdf::Ggx { alpha, f0, f90 } => vec![
                ("alpha", alpha, ROUGHNESS),
                ("f0", f0, UNIT),
                ("f90", f90, UNIT),
            ],
            Brdf::KajiyaKay { kd, ks, p } => {
                vec![("kd", kd, UNIT), ("ks", ks, UNIT), ("p", p, EXPONENT)]
            }
            Brdf::PennerSkin {
                rho,
                curvature_per_mm,
            } => vec![
                ("rho", rho, RHO),
                ("curvature_per_mm", curvature_per_mm, CURVATURE_PER_MM),
            ],
            Brdf::GltfMetalRough { alpha, metallic } => {
                vec![("alpha", alpha, ROUGHNESS), ("metallic", metallic, UNIT)]
            }
            // The set holds them to the manifest's ranges; here only to what reaches the GPU.
            Brdf::Engine { params, .. } => ["p.x", "p.y", "p.z"]
                .into_iter()
                .zip(params)
                .map(|(name, x)| (name, x, F32_FINITE))
                .collect(),
        }
    }

    /// Holds every parameter to its [`ranges`]: what `Brdf::parse` accepts (with the `files` feature), for a `Brdf` built
    /// in code.
    pub fn check(&self) -> Result<(), BrdfError> {
        let model = self.name();
        match self
            .named_params()
            .into_iter()
            .find(|(_, x, range)| !range.holds(*x))
        {
            Some((param, value, range)) => Err(BrdfError::BadParam {
                model,
                param,
                rule: range.text(),
                value: value.to_string(),
            }),
            None => Ok(()),
        }
    }

    /// The model, without its parameters: what the stencil and the G-buffer store.
    pub fn id(&self) -> BrdfId {
        match self {
            Brdf::Lambert { .. } => BrdfId::Lambert,
            Brdf::BlinnPhong { .. } => BrdfId::BlinnPhong,
            Brdf::OrenNayarFull { .. } => BrdfId::OrenNayarFull,
            Brdf::OrenNayarQualitative { .. } => BrdfId::OrenNayarQualitative,
            Brdf::Ggx { .. } => BrdfId::Ggx,
            Brdf::KajiyaKay { .. } => BrdfId::KajiyaKay,
            Brdf::PennerSkin { .. } => BrdfId::PennerSkin,
            Brdf::GltfMetalRough { .. } => BrdfId::GltfMetalRough,
            Brdf::Engine { id, .. } => BrdfId::Engine(*id),
        }
    }

    /// The model's index in [`MODEL_NAMES`]: the id the GLSL evaluator switches on.
    pub fn model_index(&self) -> u32 {
        self.id().index()
    }

    /// The model's name as [`Brdf::parse`] (or its set) accepts it and the case files write it.
    pub fn name(&self) -> &'static str {
        self.id().name()
    }

    /// Whether a look-up table can be baked from a CPU spelling: every built-in model (a table
    /// entry holds both factors of `tint * tinted + white`, so glTF's metallic-roughness too).
    /// Not an engine's BRDF, which has no CPU spelling: whether its GLSL can fill a table is its
    /// set's to say ([`crate::BrdfSet::tabulable`]).
    pub fn is_tabulable(&self) -> bool {
        !matches!(self, Brdf::Engine { .. })
    }

    /// Whether a built-in's value has a white part ([`Parts::white`]): glTF's
    /// metallic-roughness alone. An engine BRDF's is its set's to say
    /// ([`crate::EngineBrdfSpec::white`]); false here.
    pub fn has_white_part(&self) -> bool {
        matches!(self, Brdf::GltfMetalRough { .. })
    }

    /// Only skin is coloured; every other model returns one value.
    pub fn is_rgb(&self) -> bool {
        matches!(self, Brdf::PennerSkin { .. })
    }

    /// Parameters in the order the GLSL evaluator reads them.
    pub fn packed_params(&self) -> [f64; 4] {
        match *self {
            Brdf::Lambert { rho } => [rho, 0.0, 0.0, 0.0],
            Brdf::BlinnPhong { exponent } => [exponent, 0.0, 0.0, 0.0],
            Brdf::OrenNayarFull { rho, sigma } | Brdf::OrenNayarQualitative { rho, sigma } => {
                [rho, sigma, 0.0, 0.0]
            }
            Brdf::Ggx { alpha, f0, f90 } => [alpha, f0, f90, 0.0],
            Brdf::KajiyaKay { kd, ks, p } => [kd, ks, p, 0.0],
            Brdf::PennerSkin {
                rho,
                curvature_per_mm,
            } => [rho, curvature_per_mm, 0.0, 0.0],
            Brdf::GltfMetalRough { alpha, metallic } => [alpha, metallic, 0.0, 0.0],
            Brdf::Engine {
                params: [x, y, z], ..
            } => [x, y, z, 0.0],
        }
    }

    /// `f_r * cos(theta_L)` in two parts, `tint * tinted + white`, in precision `R`: the
    /// talk's models scale with the surface's tint and have no white part; glTF's
    /// metallic-roughness BRDF is affine in its base colour (a dielectric's specular is white).
    /// Scalar models repeat their value in all three channels. `skin_panels` sets the skin
    /// integral's accuracy.
    pub fn eval_parts<R: Real>(&self, [n, t, v, l]: [V3<R>; 4], skin_panels: u32) -> Parts<R> {
        let p = self.packed_params().map(c::<R>);
        let scalar = match self {
            Brdf::Lambert { .. } => models::lambert(p[0], n, l),
            Brdf::BlinnPhong { .. } => models::blinn_phong(p[0], n, v, l),
            Brdf::OrenNayarFull { .. } => models::oren_nayar_full(p[0], p[1], n, v, l),
            Brdf::OrenNayarQualitative { .. } => {
                models::oren_nayar_qualitative(p[0], p[1], n, v, l)
            }
            Brdf::Ggx { .. } => models::ggx(p[0], p[1], p[2], n, v, l),
            Brdf::KajiyaKay { .. } => models::kajiya_kay(p[0], p[1], p[2], t, v, l),
            Brdf::PennerSkin { .. } => {
                return Parts {
                    tinted: models::penner_skin(p[0], p[1], n, l, skin_panels),
                    white: R::zero(),
                };
            }
            Brdf::GltfMetalRough { .. } => {
                let (tinted, white) = models::gltf_metal_rough(p[0], p[1], n, v, l);
                return Parts {
                    tinted: [tinted; 3],
                    white,
                };
            }
            Brdf::Engine { .. } => {
                let nan = R::nan();
                return Parts {
                    tinted: [nan; 3],
                    white: nan,
                };
            }
        };
        Parts {
            tinted: [scalar; 3],
            white: R::zero(),
        }
    }

    /// `f_r * cos(theta_L)` of a white surface (tint 1), in precision `R`: for the talk's models
    /// the value per unit tint. Scalar models repeat their value in all three channels.
    pub fn eval<R: Real>(&self, dirs: [V3<R>; 4], skin_panels: u32) -> [R; 3] {
        self.eval_parts(dirs, skin_panels).at_white()
    }

    /// `f_r * cos(theta_L)` of a surface of colour `tint`: what a light's radiance is multiplied
    /// by (`brdf_eval_tinted` in GLSL).
    pub fn eval_tinted<R: Real>(&self, tint: [R; 3], dirs: [V3<R>; 4], skin_panels: u32) -> [R; 3] {
        self.eval_parts(dirs, skin_panels).tinted_by(tint)
    }

    /// The f64 reference of [`Brdf::eval_parts`].
    pub fn reference_parts(&self, dirs: [V3<f64>; 4]) -> Parts<f64> {
        self.eval_parts(dirs, models::REFERENCE_PANELS)
    }

    /// The f32 spelling of [`Brdf::eval_parts`], as the GPU computes it.
    pub fn shipping_parts(&self, dirs: [V3<f32>; 4]) -> Parts<f32> {
        self.eval_parts(dirs, models::SHIPPING_PANELS)
    }

    /// The f64 reference.
    pub fn reference(&self, dirs: [V3<f64>; 4]) -> [f64; 3] {
        self.eval(dirs, models::REFERENCE_PANELS)
    }

    /// The f32 spelling, as the GPU computes it.
    pub fn shipping(&self, dirs: [V3<f32>; 4]) -> [f32; 3] {
        self.eval(dirs, models::SHIPPING_PANELS)
    }
}

#[cfg(all(test, feature = "files"))]
mod tests {
    use super::*;
    use serde_json::json;

    fn parse(name: &str, params: Value) -> Result<Brdf, BrdfError> {
        Brdf::parse(name, params.as_object().unwrap())
    }

    #[test]
    fn parses_every_model() {
        assert_eq!(
            parse("ggx", json!({"perceptual_roughness": 0.5})).unwrap(),
            Brdf::Ggx {
                alpha: 0.25,
                f0: 0.04,
                f90: 1.0
            }
        );
        assert_eq!(
            parse("penner_skin", json!({"rho": 0.8, "radius_mm": 4.0})).unwrap(),
            Brdf::PennerSkin {
                rho: 0.8,
                curvature_per_mm: 0.25
            }
        );
        for (i, name) in MODEL_NAMES.iter().enumerate() {
            let params = match *name {
                "lambert" => json!({"rho": 1}),
                "blinn_phong" => json!({"n": 16}),
                "ggx" => json!({"alpha": 0.1}),
                "kajiya_kay" => json!({"kd": 0.5, "ks": 0.5, "p": 40}),
                "penner_skin" => json!({"rho": 1, "curvature_per_mm": 0.5}),
                "gltf_metal_rough" => json!({"roughness": 0.5}),
                _ => json!({"rho": 1, "sigma": 0.3}),
            };
            assert_eq!(parse(name, params).unwrap().model_index() as usize, i);
        }
        // glTF's names and defaults: roughness is perceptual, metallic defaults to 1.
        assert_eq!(
            parse("gltf_metal_rough", json!({"roughness": 0.5})).unwrap(),
            Brdf::GltfMetalRough {
                alpha: 0.25,
                metallic: 1.0
            }
        );
        assert_eq!(
            parse("gltf_metal_rough", json!({"alpha": 0.3, "metallic": 0})).unwrap(),
            Brdf::GltfMetalRough {
                alpha: 0.3,
                metallic: 0.0
            }
        );
        for ambiguous in [json!({}), json!({"alpha": 0.1, "roughness": 0.1})] {
            let err = parse("gltf_metal_rough", ambiguous)
                .unwrap_err()
                .to_string();
            assert!(err.contains("`alpha` or `roughness`"), "{err}");
        }
    }

    #[test]
    fn bad_descriptions_name_the_problem() {
        let msg = |r: Result<Brdf, BrdfError>| r.unwrap_err().to_string();
        assert!(msg(parse("phong", json!({}))).contains("unknown BRDF `phong`"));
        assert!(msg(parse("lambert", json!({"rho": 1, "x": 2}))).contains("unknown parameter `x`"));
        assert!(msg(parse("lambert", json!({}))).contains("missing parameter `rho`"));
        assert!(msg(parse("lambert", json!({"rho": -1}))).contains("in [0, 1]"));
        assert!(msg(parse("lambert", json!({"rho": "a"}))).contains("\"a\""));
        assert!(msg(parse(
            "ggx",
            json!({"alpha": 0.1, "perceptual_roughness": 0.1})
        ))
        .contains("exactly one"));
        assert!(
            msg(parse("penner_skin", json!({"rho": 1, "radius_mm": 0}))).contains(">= 0.000001")
        );
    }

    /// Every model, every parameter: values just inside the range parse and pass `check`, values
    /// past either end (and those only finite in f64) are refused by both, naming the parameter.
    #[test]
    fn every_parameter_is_held_to_its_range() {
        let msg = |r: Result<Brdf, BrdfError>| r.unwrap_err().to_string();
        let base = |name: &str| match name {
            "lambert" => json!({"rho": 0.5}),
            "blinn_phong" => json!({"n": 16}),
            "ggx" => json!({"alpha": 0.1, "f0": 0.04, "f90": 1}),
            "kajiya_kay" => json!({"kd": 0.5, "ks": 0.5, "p": 40}),
            "penner_skin" => json!({"rho": 1, "curvature_per_mm": 0.5}),
            "gltf_metal_rough" => json!({"alpha": 0.1, "metallic": 0.5}),
            _ => json!({"rho": 1, "sigma": 0.3}),
        };
        for name in MODEL_NAMES {
            let params = base(name);
            let keys: Vec<String> = params.as_object().unwrap().keys().cloned().collect();
            for key in keys {
                let brdf = parse(name, params.clone()).unwrap();
                let range = brdf
                    .named_params()
                    .into_iter()
                    .find(|(p, ..)| *p == key)
                    .unwrap()
                    .2;
                for ok in [range.min, range.max.min(1e300)] {
                    let mut p = params.clone();
                    p[&key] = json!(ok);
                    let parsed =
                        parse(name, p).unwrap_or_else(|e| panic!("{name} {key}={ok}: {e}"));
                    parsed.check().unwrap();
                    let f32_params = parsed.packed_params().map(|x| x as f32);
                    assert!(
                        f32_params.iter().all(|x| x.is_finite()),
                        "{name} {key}={ok}"
                    );
                }
                let hostile = [
                    -1e-300,
                    -1.0,
                    1e39,
                    1e300,
                    f64::MAX,
                    range.max * 1.0001 + 1e-9,
                ];
                for bad in hostile.into_iter().filter(|x| !range.holds(*x)) {
                    let mut p = params.clone();
                    p[&key] = json!(bad);
                    let err = msg(parse(name, p));
                    assert!(
                        err.contains(&format!("`{key}`")),
                        "{name} {key}={bad}: {err}"
                    );
                    let mut built = brdf;
                    set_param(&mut built, &key, bad);
                    let err = built.check().unwrap_err().to_string();
                    assert!(
                        err.contains(&format!("`{key}`")),
                        "{name} {key}={bad}: {err}"
                    );
                }
            }
        }
        // radius 1e-300 would be a curvature of 1e300, an f32 infinity.
        assert!(
            msg(parse("penner_skin", json!({"rho": 1, "radius_mm": 1e-300}))).contains("radius_mm")
        );
    }

    fn set_param(brdf: &mut Brdf, key: &str, x: f64) {
        match (brdf, key) {
            (Brdf::Lambert { rho }, "rho")
            | (Brdf::OrenNayarFull { rho, .. }, "rho")
            | (Brdf::OrenNayarQualitative { rho, .. }, "rho")
            | (Brdf::PennerSkin { rho, .. }, "rho") => *rho = x,
            (Brdf::BlinnPhong { exponent }, "n") => *exponent = x,
            (Brdf::OrenNayarFull { sigma, .. }, "sigma")
            | (Brdf::OrenNayarQualitative { sigma, .. }, "sigma") => *sigma = x,
            (Brdf::Ggx { alpha, .. }, "alpha") | (Brdf::GltfMetalRough { alpha, .. }, "alpha") => {
                *alpha = x
            }
            (Brdf::GltfMetalRough { metallic, .. }, "metallic") => *metallic = x,
            (Brdf::Ggx { f0, .. }, "f0") => *f0 = x,
            (Brdf::Ggx { f90, .. }, "f90") => *f90 = x,
            (Brdf::KajiyaKay { kd, .. }, "kd") => *kd = x,
            (Brdf::KajiyaKay { ks, .. }, "ks") => *ks = x,
            (Brdf::KajiyaKay { p, .. }, "p") => *p = x,
            (
                Brdf::PennerSkin {
                    curvature_per_mm, ..
                },
                "curvature_per_mm",
            ) => *curvature_per_mm = x,
            (b, k) => panic!("{b:?} has no {k}"),
        }
    }
}
