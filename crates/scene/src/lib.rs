//! histencil-scene: scenes as plain data (what a glTF importer fills), the embedded scenes, meshes
//! and light volumes, bounds, and what a frame needs from a scene.

mod embedded;
mod mesh;
mod types;

pub use embedded::{embedded, embedded_names, EMBEDDED};
pub use mesh::{light_cone, light_sphere, unit_box, uv_sphere, Mesh, Vertex};
pub use types::{Camera, Light, LightKind, Material, Object, Scene, SceneError, Shape};
