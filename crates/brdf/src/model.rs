//! A BRDF with its parameters: parsed from a name and a JSON object, evaluated in f64 or f32,
//! and packed for the GLSL spelling (`shaders/include/brdf/eval.glsl`).

use crate::id::BrdfId;
use crate::models;
use crate::vector::{c, Real, V3};
use serde_json::{Map, Value};

/// A BRDF model and its parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Brdf {
    Lambert {
        rho: f64,
    },
    BlinnPhong {
        exponent: f64,
    },
    OrenNayarFull {
        rho: f64,
        sigma: f64,
    },
    OrenNayarQualitative {
        rho: f64,
        sigma: f64,
    },
    /// `alpha` is the GGX alpha (perceptual roughness squared).
    Ggx {
        alpha: f64,
        f0: f64,
        f90: f64,
    },
    KajiyaKay {
        kd: f64,
        ks: f64,
        p: f64,
    },
    PennerSkin {
        rho: f64,
        curvature_per_mm: f64,
    },
}

/// Names accepted by [`Brdf::parse`], in id order ([`BrdfId::ALL`]).
pub const MODEL_NAMES: [&str; 7] = {
    let mut names = [""; 7];
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
    #[error("unknown BRDF `{0}` (known: {names})", names = MODEL_NAMES.join(", "))]
    UnknownModel(String),
    #[error("{model}: unknown parameter `{param}` (accepted: {accepted})")]
    UnknownParam {
        model: &'static str,
        param: String,
        accepted: String,
    },
    #[error("{model}: missing parameter `{param}`")]
    MissingParam {
        model: &'static str,
        param: &'static str,
    },
    #[error("{model}: parameter `{param}` must be {rule}, got {value}")]
    BadParam {
        model: &'static str,
        param: &'static str,
        rule: &'static str,
        value: String,
    },
    #[error("{model}: give exactly one of {options}")]
    Ambiguous {
        model: &'static str,
        options: &'static str,
    },
}

/// Reads the numeric parameters of one model, refusing unknown keys.
struct Params<'a> {
    model: &'static str,
    map: &'a Map<String, Value>,
}

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

    fn optional(&self, param: &'static str, rule: Rule) -> Result<Option<f64>, BrdfError> {
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

    fn required(&self, param: &'static str, rule: Rule) -> Result<f64, BrdfError> {
        self.optional(param, rule)?.ok_or(BrdfError::MissingParam {
            model: self.model,
            param,
        })
    }

    /// Exactly one of two spellings of the same quantity.
    fn one_of(
        &self,
        (a, rule_a): (&'static str, Rule),
        (b, rule_b): (&'static str, Rule),
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

#[derive(Clone, Copy)]
enum Rule {
    NonNegative,
    Positive,
    Unit,
}

impl Rule {
    fn holds(self, x: f64) -> bool {
        x.is_finite()
            && match self {
                Rule::NonNegative => x >= 0.0,
                Rule::Positive => x > 0.0,
                Rule::Unit => (0.0..=1.0).contains(&x),
            }
    }

    fn text(self) -> &'static str {
        match self {
            Rule::NonNegative => "a finite number >= 0",
            Rule::Positive => "a finite number > 0",
            Rule::Unit => "a number in [0, 1]",
        }
    }
}

impl Brdf {
    /// Parses a model name and its parameters, e.g. `ggx` with `{"perceptual_roughness": 0.5}`.
    pub fn parse(name: &str, params: &Map<String, Value>) -> Result<Self, BrdfError> {
        use Rule::*;
        let model = MODEL_NAMES
            .iter()
            .copied()
            .find(|m| *m == name)
            .ok_or_else(|| BrdfError::UnknownModel(name.to_owned()))?;
        let p = |accepted: &[&str]| Params::new(model, params, accepted);
        Ok(match model {
            "lambert" => Brdf::Lambert {
                rho: p(&["rho"])?.required("rho", NonNegative)?,
            },
            "blinn_phong" => Brdf::BlinnPhong {
                exponent: p(&["n"])?.required("n", NonNegative)?,
            },
            "oren_nayar_full" | "oren_nayar_qualitative" => {
                let p = p(&["rho", "sigma"])?;
                let (rho, sigma) = (
                    p.required("rho", NonNegative)?,
                    p.required("sigma", NonNegative)?,
                );
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
                        ("alpha", NonNegative),
                        ("perceptual_roughness", NonNegative),
                        "`alpha` or `perceptual_roughness`",
                    )?
                    .unwrap_or_else(|roughness| roughness * roughness);
                Brdf::Ggx {
                    alpha,
                    f0: p.optional("f0", Unit)?.unwrap_or(0.04),
                    f90: p.optional("f90", Unit)?.unwrap_or(1.0),
                }
            }
            "kajiya_kay" => {
                let p = p(&["kd", "ks", "p"])?;
                Brdf::KajiyaKay {
                    kd: p.required("kd", NonNegative)?,
                    ks: p.required("ks", NonNegative)?,
                    p: p.required("p", NonNegative)?,
                }
            }
            "penner_skin" => {
                let p = p(&["rho", "radius_mm", "curvature_per_mm"])?;
                let curvature_per_mm = p
                    .one_of(
                        ("curvature_per_mm", NonNegative),
                        ("radius_mm", Positive),
                        "`curvature_per_mm` or `radius_mm`",
                    )?
                    .unwrap_or_else(|radius| 1.0 / radius);
                Brdf::PennerSkin {
                    rho: p.required("rho", NonNegative)?,
                    curvature_per_mm,
                }
            }
            _ => unreachable!("every name in MODEL_NAMES is handled"),
        })
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
        }
    }

    /// The model's index in [`MODEL_NAMES`]: the id the GLSL evaluator switches on.
    pub fn model_index(&self) -> u32 {
        self.id().index()
    }

    pub fn name(&self) -> &'static str {
        MODEL_NAMES[self.model_index() as usize]
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
        }
    }

    /// `f_r * cos(theta_L)` in precision `R`; scalar models repeat their value in all three
    /// channels. `skin_panels` sets the skin integral's accuracy.
    pub fn eval<R: Real>(&self, [n, t, v, l]: [V3<R>; 4], skin_panels: u32) -> [R; 3] {
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
                return models::penner_skin(p[0], p[1], n, l, skin_panels);
            }
        };
        [scalar; 3]
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

#[cfg(test)]
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
                _ => json!({"rho": 1, "sigma": 0.3}),
            };
            assert_eq!(parse(name, params).unwrap().model_index() as usize, i);
        }
    }

    #[test]
    fn bad_descriptions_name_the_problem() {
        let msg = |r: Result<Brdf, BrdfError>| r.unwrap_err().to_string();
        assert!(msg(parse("phong", json!({}))).contains("unknown BRDF `phong`"));
        assert!(msg(parse("lambert", json!({"rho": 1, "x": 2}))).contains("unknown parameter `x`"));
        assert!(msg(parse("lambert", json!({}))).contains("missing parameter `rho`"));
        assert!(msg(parse("lambert", json!({"rho": -1}))).contains(">= 0"));
        assert!(msg(parse("lambert", json!({"rho": "a"}))).contains("\"a\""));
        assert!(msg(parse(
            "ggx",
            json!({"alpha": 0.1, "perceptual_roughness": 0.1})
        ))
        .contains("exactly one"));
        assert!(msg(parse("penner_skin", json!({"rho": 1, "radius_mm": 0}))).contains("> 0"));
    }
}
