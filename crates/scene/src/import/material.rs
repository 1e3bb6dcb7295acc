//! A glTF material as a histencil [`Material`]: the BRDF named in its `extras`, or a documented
//! approximation of its metallic-roughness parameters.

use crate::Material;
use glam::Vec3;
use histencil_brdf::{Brdf, BrdfError};
use serde_json::{Map, Value};

/// Why a material's `extras` were refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MaterialError {
    #[error("extras are not a JSON object")]
    NotAnObject,
    #[error("`brdf` must be a string naming a model")]
    NameNotAString,
    #[error("`tint` must be an array of 3 non-negative numbers")]
    BadTint,
    #[error(transparent)]
    Brdf(#[from] BrdfError),
}

/// The material of `extras` (the material's raw JSON extras, if any) and the metallic-roughness
/// factors. With `"brdf"` in the extras, the BRDF is `Brdf::parse(name, other keys)`, exactly as
/// `histencil brdf-eval` takes it, and the tint is `"tint"` or the base colour. Without it, the
/// fallback is:
///
/// - `metallic < 0.5` and `roughness >= 0.5`: Lambert (a rough dielectric is mostly diffuse);
/// - otherwise GGX with `alpha = roughness^2` (at least 0.01: a mirror's alpha 0 has no highlight
///   to rasterise), `f0 = 0.04` blended to 1 by `metallic`, `f90 = 1`.
///
/// Base-colour textures are ignored: the tint is `baseColorFactor`'s RGB.
pub fn material_from_gltf(
    extras: Option<&str>,
    base_color: [f32; 4],
    metallic: f32,
    roughness: f32,
) -> Result<Material, MaterialError> {
    let base_tint = Vec3::new(base_color[0], base_color[1], base_color[2]);
    let extras: Option<Map<String, Value>> = match extras {
        None => None,
        Some(raw) => match serde_json::from_str(raw) {
            Ok(Value::Object(map)) => Some(map),
            _ => return Err(MaterialError::NotAnObject),
        },
    };
    let Some(mut params) = extras.filter(|m| m.contains_key("brdf")) else {
        return Ok(Material::new(fallback_brdf(metallic, roughness), base_tint));
    };
    let name = match params.remove("brdf") {
        Some(Value::String(name)) => name,
        _ => return Err(MaterialError::NameNotAString),
    };
    let tint = match params.remove("tint") {
        None => base_tint,
        Some(value) => parse_tint(&value).ok_or(MaterialError::BadTint)?,
    };
    Ok(Material::new(Brdf::parse(&name, &params)?, tint))
}

fn parse_tint(value: &Value) -> Option<Vec3> {
    let items = value.as_array().filter(|a| a.len() == 3)?;
    let mut rgb = [0.0f32; 3];
    for (out, item) in rgb.iter_mut().zip(items) {
        let x = item.as_f64().filter(|x| x.is_finite() && *x >= 0.0)?;
        *out = x as f32;
    }
    Some(Vec3::from(rgb))
}

fn fallback_brdf(metallic: f32, roughness: f32) -> Brdf {
    let (metallic, roughness) = (
        f64::from(metallic).clamp(0.0, 1.0),
        f64::from(roughness).clamp(0.0, 1.0),
    );
    if metallic < 0.5 && roughness >= 0.5 {
        Brdf::Lambert { rho: 1.0 }
    } else {
        Brdf::Ggx {
            alpha: (roughness * roughness).max(0.01),
            f0: 0.04 + 0.96 * metallic,
            f90: 1.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const WHITE: [f32; 4] = [1.0; 4];

    #[test]
    fn extras_name_the_brdf_and_its_parameters() {
        let m = material_from_gltf(
            Some(r#"{"brdf": "oren_nayar_full", "rho": 0.8, "sigma": 0.3, "tint": [1, 0.5, 0]}"#),
            WHITE,
            0.0,
            1.0,
        )
        .unwrap();
        assert_eq!(
            m.brdf,
            Brdf::OrenNayarFull {
                rho: 0.8,
                sigma: 0.3
            }
        );
        assert_eq!(m.tint, Vec3::new(1.0, 0.5, 0.0));
    }

    #[test]
    fn bad_extras_are_named() {
        let err = |extras| material_from_gltf(Some(extras), WHITE, 0.0, 1.0).unwrap_err();
        assert!(matches!(
            err(r#"{"brdf": "velvet"}"#),
            MaterialError::Brdf(BrdfError::UnknownModel(name)) if name == "velvet"
        ));
        assert_eq!(err(r#"{"brdf": 3}"#), MaterialError::NameNotAString);
        assert_eq!(err(r#"[1, 2]"#), MaterialError::NotAnObject);
        assert_eq!(
            err(r#"{"brdf": "lambert", "rho": 1, "tint": [1, -1, 0]}"#),
            MaterialError::BadTint
        );
        assert!(matches!(
            err(r#"{"brdf": "lambert", "rho": 1, "shininess": 3}"#),
            MaterialError::Brdf(BrdfError::UnknownParam { .. })
        ));
    }

    #[test]
    fn the_pbr_fallback() {
        let rough = material_from_gltf(None, [0.5, 0.5, 0.5, 1.0], 0.0, 1.0).unwrap();
        assert_eq!(rough.brdf, Brdf::Lambert { rho: 1.0 });
        assert_eq!(rough.tint, Vec3::splat(0.5));
        let other_extras = material_from_gltf(Some(r#"{"author": "x"}"#), WHITE, 1.0, 0.0).unwrap();
        assert_eq!(
            other_extras.brdf,
            Brdf::Ggx {
                alpha: 0.01,
                f0: 1.0,
                f90: 1.0
            }
        );
    }
}
