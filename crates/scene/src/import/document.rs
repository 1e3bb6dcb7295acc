//! The glTF document from a file's bytes: the GLB container or the JSON, then the checks the
//! `gltf` crate's own validation relies on but does not make, then that validation.
//!
//! `gltf` 1.4 panics on two kinds of malformed file (both found by fuzzing, `fuzz/regressions/
//! gltf`): a GLB header whose length is under its own 12 bytes (it subtracts 12 unchecked), and
//! a primitive whose `POSITION` names an accessor that does not exist (its validation hook
//! indexes the accessors unchecked). Both are refused here first, with the element named.
//! Extensions the file requires but histencil does not read are refused in one line before
//! validation, rather than as a validation error that blames the file.

use super::ImportError;

/// The extensions histencil reads: those `gltf` parses for it (its features in the workspace
/// manifest) and `KHR_mesh_quantization` (import/attributes.rs). A file requiring any other
/// cannot be imported.
pub const SUPPORTED_REQUIRED_EXTENSIONS: [&str; 4] = [
    "KHR_lights_punctual",
    "KHR_texture_transform",
    "KHR_materials_emissive_strength",
    super::attributes::MESH_QUANTIZATION,
];

const GLB_MAGIC: &[u8; 4] = b"glTF";
const GLB_HEADER_BYTES: u32 = 12;

/// Parses and validates `bytes`, a `.gltf` (JSON) or `.glb` file.
pub fn parse(bytes: &[u8]) -> Result<gltf::Gltf, ImportError> {
    if bytes.starts_with(GLB_MAGIC) {
        check_glb_header(bytes)?;
    }
    let parse_error = |e: gltf::Error| ImportError::Parse(e.to_string());
    let gltf::Gltf { document, blob } =
        gltf::Gltf::from_slice_without_validation(bytes).map_err(parse_error)?;
    let mut json = document.into_json();
    if let Some(unsupported) = json
        .extensions_required
        .iter()
        .find(|e| !SUPPORTED_REQUIRED_EXTENSIONS.contains(&e.as_str()))
    {
        return Err(ImportError::UnsupportedExtension(unsupported.clone()));
    }
    check_position_accessors(&json)?;
    // The `gltf` crate does not know KHR_mesh_quantization and its validation would refuse the
    // file for requiring it; histencil reads it (import/attributes.rs), and `extensionsUsed`
    // still says it is used.
    json.extensions_required
        .retain(|e| e != super::attributes::MESH_QUANTIZATION);
    let document = gltf::Document::from_json(json).map_err(parse_error)?;
    Ok(gltf::Gltf { document, blob })
}

/// The header's length covers at least the header itself.
fn check_glb_header(bytes: &[u8]) -> Result<(), ImportError> {
    let Some(length) = bytes.get(8..12) else {
        return Err(ImportError::Parse(format!(
            "a GLB file needs a {GLB_HEADER_BYTES}-byte header; this one has {} bytes",
            bytes.len()
        )));
    };
    let length = u32::from_le_bytes(length.try_into().expect("four bytes"));
    if length < GLB_HEADER_BYTES {
        return Err(ImportError::Parse(format!(
            "GLB header: total length {length} is shorter than the {GLB_HEADER_BYTES}-byte \
             header itself"
        )));
    }
    Ok(())
}

/// Every primitive's `POSITION` names an existing accessor.
fn check_position_accessors(json: &gltf::json::Root) -> Result<(), ImportError> {
    let positions = gltf::json::validation::Checked::Valid(gltf::Semantic::Positions);
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            if let Some(accessor) = primitive.attributes.get(&positions) {
                if json.accessors.get(accessor.value()).is_none() {
                    return Err(ImportError::Parse(format!(
                        "meshes[{m}].primitives[{p}].attributes.POSITION: accessor {} does not \
                         exist ({} accessors)",
                        accessor.value(),
                        json.accessors.len()
                    )));
                }
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn refusal(json: &str) -> String {
        parse(json.as_bytes()).expect_err("refused").to_string()
    }

    #[test]
    fn an_unsupported_required_extension_is_named_before_any_accessor_error() {
        // As Draco files are: accessors without buffer views, which the extension would fill.
        let draco = r#"{"asset": {"version": "2.0"},
            "extensionsUsed": ["KHR_draco_mesh_compression"],
            "extensionsRequired": ["KHR_draco_mesh_compression"],
            "accessors": [{"componentType": 5126, "count": 3, "type": "VEC3"}]}"#;
        let err = refusal(draco);
        assert!(
            err.starts_with("the file requires the glTF extension `KHR_draco_mesh_compression`"),
            "{err}"
        );
        assert!(!err.contains("bufferView") && !err.contains('\n'), "{err}");
        let supported = r#"{"asset": {"version": "2.0"},
            "extensionsRequired": ["KHR_texture_transform"]}"#;
        assert!(parse(supported.as_bytes()).is_ok());
    }

    #[test]
    fn what_gltf_would_panic_on_is_refused() {
        let mut glb = b"glTF".to_vec();
        glb.extend(2u32.to_le_bytes());
        glb.extend(8u32.to_le_bytes());
        assert!(refusal(std::str::from_utf8(&glb).unwrap()).contains("total length 8"));
        assert!(refusal("glTF\x02\0").contains("12-byte header"));
        let missing = r#"{"asset": {"version": "2.0"},
            "meshes": [{"primitives": [{"attributes": {"POSITION": 4}}]}]}"#;
        let err = refusal(missing);
        assert!(
            err.contains("meshes[0].primitives[0].attributes.POSITION: accessor 4 does not exist"),
            "{err}"
        );
    }
}
