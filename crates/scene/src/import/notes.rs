//! What a glTF file holds that histencil reads past without rendering: said once per scene, so
//! that a user comparing a render with another viewer knows which differences are expected.
//! Each note names the feature, how much of the file uses it, and why it is not rendered.

use super::document::SUPPORTED_REQUIRED_EXTENSIONS;
use gltf::material::AlphaMode;

/// The notes for `document`, in a fixed order; empty when everything in it is rendered.
pub fn unrendered(document: &gltf::Document) -> Vec<String> {
    let mut notes = Vec::new();
    let count = |n: usize, what: &str| format!("{n} {what}{}", if n == 1 { "" } else { "s" });
    let materials: Vec<gltf::Material> = document.materials().collect();
    let occlusion = materials
        .iter()
        .filter(|m| m.occlusion_texture().is_some())
        .count();
    if occlusion > 0 {
        notes.push(format!(
            "occlusionTexture ({}): glTF defines it for indirect light, and histencil lights \
             directly only",
            count(occlusion, "material")
        ));
    }
    let blend_maps = materials
        .iter()
        .filter(|m| m.alpha_mode() == AlphaMode::Blend)
        .filter(|m| {
            let pbr = m.pbr_metallic_roughness();
            pbr.base_color_texture().is_some()
                || pbr.metallic_roughness_texture().is_some()
                || m.normal_texture().is_some()
                || m.emissive_texture().is_some()
                || m.emissive_factor() != [0.0; 3]
        })
        .count();
    if blend_maps > 0 {
        notes.push(format!(
            "textures and emission of translucent (BLEND) materials ({}): alpha entities are \
             lit per entity from their lightmaps and read no maps yet; their opacity is \
             baseColorFactor's alpha",
            count(blend_maps, "material")
        ));
    }
    let unread: Vec<&str> = document
        .extensions_used()
        .filter(|e| !SUPPORTED_REQUIRED_EXTENSIONS.contains(e))
        .collect();
    if !unread.is_empty() {
        notes.push(format!(
            "extensions {}: not read, so rendered as if absent",
            unread.join(", ")
        ));
    }
    let animations = document.animations().count();
    if animations > 0 {
        notes.push(format!(
            "{}: not played; the scene renders at its rest pose",
            count(animations, "animation")
        ));
    }
    let skins = document.skins().count();
    if skins > 0 {
        notes.push(format!(
            "{}: meshes render unskinned, at their bind pose",
            count(skins, "skin")
        ));
    }
    let morphed = document
        .meshes()
        .flat_map(|m| m.primitives().collect::<Vec<_>>())
        .filter(|p| p.morph_targets().next().is_some())
        .count();
    if morphed > 0 {
        notes.push(format!(
            "morph targets ({}): render without their weights applied",
            count(morphed, "primitive")
        ));
    }
    let scenes = document.scenes().count();
    if scenes > 1 {
        let shown = document.default_scene().map_or(0, |s| s.index());
        notes.push(format!(
            "{scenes} scenes: only scene {shown} (the default) is rendered"
        ));
    }
    notes
}

#[cfg(test)]
mod tests {
    use super::*;

    fn notes(json: &str) -> Vec<String> {
        unrendered(&gltf::Gltf::from_slice(json.as_bytes()).unwrap().document)
    }

    #[test]
    fn each_unrendered_feature_is_named_once_with_its_count() {
        assert!(notes(r#"{"asset": {"version": "2.0"}}"#).is_empty());
        let json = r#"{"asset": {"version": "2.0"},
            "extensionsUsed": ["KHR_materials_clearcoat", "KHR_texture_transform"],
            "images": [{"uri": "a.png"}], "textures": [{"source": 0}],
            "materials": [
                {"occlusionTexture": {"index": 0}},
                {"occlusionTexture": {"index": 0}},
                {"alphaMode": "BLEND", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}
            ],
            "scenes": [{"nodes": []}, {"nodes": []}], "scene": 1,
            "animations": []}"#;
        let found = notes(json);
        assert_eq!(found.len(), 4, "{found:#?}");
        assert!(found[0].starts_with("occlusionTexture (2 materials)"));
        assert!(found[1].contains("(1 material)") && found[1].contains("BLEND"));
        assert!(found[2].contains("KHR_materials_clearcoat") && !found[2].contains("transform"));
        assert_eq!(found[3], "2 scenes: only scene 1 (the default) is rendered");
    }
}
