//! histencil-scene: scenes as plain data (what a glTF importer fills), the embedded scenes, meshes
//! and light volumes, bounds, and what a frame needs from a scene.
//!
//! Feature `gltf` (on by default): the glTF importer and its image decoders. An engine lighting
//! its own frames needs the types alone (lights, materials, bounds), so histencil-vk and the
//! `histencil` front door take this crate without it: no gltf, serde_json, base64 or image.

#![warn(missing_docs)]

mod alpha;
mod alpha_scenes;
mod brdf_set;
mod embedded;
#[cfg(feature = "gltf")]
mod import;
mod light_rig;
mod mesh;
mod shading;
mod split_mix;
mod tangents;
mod texture;
mod town;
mod types;

pub use alpha::{AlphaObject, Particle, ParticleLayout, ParticleSystem, MAX_SLICES};
pub use alpha_scenes::{glass_sphere, smoke_volume};
pub use brdf_set::retarget_brdfs;
pub use embedded::{embedded, embedded_names, EMBEDDED};
#[cfg(feature = "gltf")]
pub use import::{
    import_gltf, import_gltf_in, import_gltf_noted, load_gltf, load_gltf_in, load_gltf_noted,
    load_scene, load_scene_in, load_scene_noted, material_from_gltf, material_from_gltf_in,
    ImportError, Imported, MaterialError, MAX_DECODED_IMAGE_BYTES, MAX_IMAGE_FILE_BYTES,
    SUPPORTED_REQUIRED_EXTENSIONS,
};
pub use light_rig::{
    default_light_rig, with_default_lights, DefaultLights, FILL_SHARE, KEY_RADIANCE,
};
pub use mesh::{
    light_cone, light_sphere, unit_box, unit_box_bake, uv_sphere, Mesh, Vertex, BOX_UV_INSET,
    SPHERE_DETAIL,
};
pub use shading::{range_falloff, shade};
pub use texture::{
    textured_brdf, uv_transform, Filter, MaterialMaps, Sampler, TextureImage, TextureRef,
    UvTransform, Wrap, MAP_COUNT, MAX_TEXTURE_SIDE, UV_IDENTITY,
};
pub use town::{TOWN_LIGHTS, TOWN_MATERIALS};
pub use types::{
    unit_direction, Camera, Falloff, Light, LightKind, Material, Object, Scene, SceneError, Shape,
    MAX_FAR_OVER_NEAR, MAX_LIGHT_COLOR, MAX_TINT, MAX_WORLD_COORDINATE, MIN_FOV_Y,
    RANGE_CAP_PER_EXTENT,
};
