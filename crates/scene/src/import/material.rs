//! A glTF material as a histencil [`Material`]: the BRDF named in its `extras`, or glTF's own
//! metallic-roughness BRDF with its factors.

use crate::{Material, MAX_TINT};
use glam::Vec3;
use histencil_brdf::{Brdf, BrdfError, BrdfSet};
use serde_json::{Map, Value};

/// Why a material's `extras` were refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MaterialError {
    /// The extras are JSON, but not an object of named values.
    #[error("extras are not a JSON object")]
    NotAnObject,
    /// `brdf` is there but not a string.
    #[error("`brdf` must be a string naming a model")]
    NameNotAString,
    /// `tint` is not three numbers in range.
    #[error("`tint` must be an array of 3 numbers in [0, {MAX_TINT}]")]
    BadTint,
    /// The model or its parameters were refused, as `histencil brdf-eval` would refuse them.
    #[error(transparent)]
    Brdf(#[from] BrdfError),
}

/// The material of `extras` (the material's raw JSON extras, if any) and the metallic-roughness
/// factors. With `"brdf"` in the extras, the BRDF is `Brdf::parse(name, other keys)`, exactly as
/// `histencil brdf-eval` takes it, and the tint is `"tint"` or the base colour. Without it, the
/// material is glTF's own: [`Brdf::GltfMetalRough`] with `alpha = roughness^2` and the
/// `metallic` factor (each clamped to `[0, 1]`), the base colour as its tint, and the
/// metallic-roughness texture applied per texel as glTF defines ([`crate::textured_brdf`]).
///
/// Base-colour textures are applied by the renderer (they multiply the tint per texel).
pub fn material_from_gltf(
    extras: Option<&str>,
    base_color: [f32; 4],
    metallic: f32,
    roughness: f32,
) -> Result<Material, MaterialError> {
    material_from_gltf_in(&BrdfSet::default(), extras, base_color, metallic, roughness)
}

/// [`material_from_gltf`] where `"brdf"` may also name one of `set`'s own BRDFs, its
/// parameters read by [`BrdfSet::parse`] (those left out take the manifest's defaults).
pub fn material_from_gltf_in(
    set: &BrdfSet,
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
        return Ok(Material::new(gltf_brdf(metallic, roughness), base_tint));
    };
    let name = match params.remove("brdf") {
        Some(Value::String(name)) => name,
        _ => return Err(MaterialError::NameNotAString),
    };
    let tint = match params.remove("tint") {
        None => base_tint,
        Some(value) => parse_tint(&value).ok_or(MaterialError::BadTint)?,
    };
    Ok(Material::new(set.parse(&name, &params)?, tint))
}

fn parse_tint(value: &Value) -> Option<Vec3> {
    let items = value.as_array().filter(|a| a.len() == 3)?;
    let mut rgb = [0.0f32; 3];
    for (out, item) in rgb.iter_mut().zip(items) {
        // Held to the scene's range here, in f64: a value finite in f64 but not in f32
        // (1e39) would otherwise become an infinite tint (found by fuzzing).
        let x = item
            .as_f64()
            .filter(|x| (0.0..=f64::from(MAX_TINT)).contains(x))?;
        *out = x as f32;
    }
    Some(Vec3::from(rgb))
}

fn gltf_brdf(metallic: f32, roughness: f32) -> Brdf {
    let roughness = f64::from(roughness).clamp(0.0, 1.0);
    Brdf::GltfMetalRough {
        alpha: roughness * roughness,
        metallic: f64::from(metallic).clamp(0.0, 1.0),
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
        let err = |extras: &str| material_from_gltf(Some(extras), WHITE, 0.0, 1.0).unwrap_err();
        assert!(matches!(
            err(r#"{"brdf": "velvet"}"#),
            MaterialError::Brdf(BrdfError::UnknownModel(name)) if name == "velvet"
        ));
        assert_eq!(err(r#"{"brdf": 3}"#), MaterialError::NameNotAString);
        assert_eq!(err(r#"[1, 2]"#), MaterialError::NotAnObject);
        for tint in [
            "[1, -1, 0]",
            "[1e39, 0, 0]",
            "[0, 3e20, 0]",
            "[1001, 0, 0]",
            "[1, 1]",
        ] {
            let extras = format!(r#"{{"brdf": "lambert", "rho": 1, "tint": {tint}}}"#);
            assert_eq!(err(&extras), MaterialError::BadTint, "{tint}");
        }
        assert!(matches!(
            err(r#"{"brdf": "lambert", "rho": 1, "shininess": 3}"#),
            MaterialError::Brdf(BrdfError::UnknownParam { .. })
        ));
    }

    #[test]
    fn without_a_brdf_in_the_extras_a_material_is_gltfs_own() {
        let rough = material_from_gltf(None, [0.5, 0.4, 0.3, 1.0], 0.0, 1.0).unwrap();
        assert_eq!(
            rough.brdf,
            Brdf::GltfMetalRough {
                alpha: 1.0,
                metallic: 0.0
            }
        );
        assert_eq!(rough.tint, Vec3::new(0.5, 0.4, 0.3));
        let other_extras = material_from_gltf(Some(r#"{"author": "x"}"#), WHITE, 1.0, 0.5).unwrap();
        assert_eq!(
            other_extras.brdf,
            Brdf::GltfMetalRough {
                alpha: 0.25,
                metallic: 1.0
            }
        );
        // Factors outside glTF's range are clamped into it.
        let clamped = material_from_gltf(None, WHITE, 3.0, -1.0).unwrap();
        assert_eq!(
            clamped.brdf,
            Brdf::GltfMetalRough {
                alpha: 0.0,
                metallic: 1.0
            }
        );
    }
}
