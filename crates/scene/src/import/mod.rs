//! glTF 2.0 scenes (`.gltf` with external or embedded buffers, or `.glb`) as histencil scenes.
//!
//! - **Meshes:** every triangle primitive of every node in the default scene becomes an object.
//!   Its vertices are fitted into `[-1, 1]^3` and the fit is folded into the object's transform
//!   ([`crate::Shape::Mesh`]). Missing normals are flat, as the glTF spec asks.
//! - **Materials:** the BRDF comes from the material's `extras` (see [`material_from_gltf`]).
//!   `alphaMode: BLEND` makes the primitive an [`AlphaObject`] with the base colour's alpha as its
//!   opacity. It then needs `TEXCOORD_0` as its lightmap layout: unique and inside `[0, 1]^2`.
//!   `MASK` is drawn opaque.
//! - **Lights:** from `KHR_lights_punctual`. `color * intensity` is the light's radiance scale,
//!   falling off as glTF recommends and Khronos' Sample Viewer draws it ([`Falloff::Gltf`]:
//!   `w / d^2` with `w = clamp(1 - (d / range)^4, 0, 1)`, spot cones a squared linear ramp). A
//!   light without a `range` is unlimited in glTF: it falls off as `1 / d^2` up to the distance
//!   where `intensity / d^2` is 1/255 and ends there ([`Falloff::InverseSquare`]). Spot cones
//!   must stay within 80 degrees.
//! - **Camera:** the first perspective camera met, else one framing the scene's bounds.
//!
//! Anything the renderer cannot take gives an [`ImportError`] naming the file's element, never a
//! panic: truncated files, missing or short buffers, accessors past their views, unknown BRDFs.

mod attributes;
mod buffers;
mod document;
mod images;
mod material;
mod notes;
mod uv_layout;

use buffers::ReadLimit;
pub use buffers::MAX_IMPORT_BYTES;
pub use document::SUPPORTED_REQUIRED_EXTENSIONS;
pub use images::{MAX_DECODED_IMAGE_BYTES, MAX_IMAGE_FILE_BYTES};

use histencil_brdf::BrdfSet;
pub use material::{material_from_gltf, material_from_gltf_in, MaterialError};

use crate::tangents;
use crate::{
    uv_transform, AlphaObject, Camera, Falloff, Light, LightKind, MaterialMaps, Mesh, Object,
    Scene, SceneError, Shape, Vertex, UV_IDENTITY,
};
use glam::{Mat4, Vec3};
use gltf::accessor::{DataType, Dimensions};
use gltf::khr_lights_punctual::Kind;
use std::collections::HashMap;
use std::path::Path;

/// Why a glTF file could not become a scene.
#[derive(Debug, thiserror::Error)]
pub enum ImportError {
    /// The file, or a file it refers to, could not be read; `problem` names the path.
    #[error("{problem}")]
    Io {
        /// The file that could not be read.
        path: String,
        /// What went wrong, with the path.
        problem: String,
    },
    /// Not JSON glTF or GLB, or not valid against the glTF schema.
    #[error("not a valid glTF file: {0}")]
    Parse(String),
    /// A valid file that needs an extension histencil does not read.
    #[error(
        "the file requires the glTF extension `{0}`, which histencil does not support \
         (supported: {supported})",
        supported = document::SUPPORTED_REQUIRED_EXTENSIONS.join(", ")
    )]
    UnsupportedExtension(String),
    /// A buffer that is missing, too short, too large to import, or at a URI that cannot be read.
    #[error("buffer {index}: {problem}")]
    Buffer {
        /// The buffer's index in the file.
        index: usize,
        /// What is wrong with it.
        problem: String,
    },
    /// A mesh primitive histencil cannot draw (its mode, its accessors, its attributes).
    #[error("mesh {index} (`{name}`): {problem}")]
    Mesh {
        /// The mesh's index in the file.
        index: usize,
        /// Its name in the file, empty if it has none.
        name: String,
        /// What is wrong with it.
        problem: String,
    },
    /// `problem` is in the message, so it is not also the error's source (a chain would print
    /// it twice).
    #[error("material {index} (`{name}`): {problem}")]
    Material {
        /// The material's index in the file.
        index: usize,
        /// Its name in the file, `default` if it has none.
        name: String,
        /// What is wrong with its extras.
        problem: MaterialError,
    },
    /// An image that cannot be read or decoded: `problem` says why.
    #[error("image {index} (`{name}`) {problem}")]
    Image {
        /// The image's index in the file.
        index: usize,
        /// Its name in the file, else its URI, else `image<index>`.
        name: String,
        /// What is wrong with it.
        problem: String,
    },
    /// A `KHR_lights_punctual` light histencil cannot draw.
    #[error("light {index} (`{name}`): {problem}")]
    Light {
        /// The light's index in the extension's list.
        index: usize,
        /// Its name in the file, empty if it has none.
        name: String,
        /// What is wrong with it.
        problem: String,
    },
    /// A camera histencil cannot use: an orthographic one.
    #[error("camera {index}: {problem}")]
    Camera {
        /// The camera's index in the file.
        index: usize,
        /// What is wrong with it.
        problem: String,
    },
    /// The file's structure: no scene, a node hierarchy too deep (a cycle), a transform that is
    /// not finite, ...
    #[error("{0}")]
    Structure(String),
    /// The scene imported, but fails [`Scene::validate`].
    #[error(transparent)]
    Scene(#[from] SceneError),
}

/// The threshold on texel alpha times vertex alpha that glTF's `alpha * factor >= cutoff` is:
/// `cutoff / factor`, with a factor of 0 keeping everything (cutoff 0) or nothing, and a
/// cutoff that is not a finite number in glTF's `[0, 1]`-ish sense taken at its nearest end.
fn mask_threshold(cutoff: f32, factor: f32) -> f32 {
    let cutoff = if cutoff.is_nan() {
        0.5
    } else {
        cutoff.max(0.0)
    };
    let factor = if factor.is_nan() {
        1.0
    } else {
        factor.clamp(0.0, 1.0)
    };
    if cutoff == 0.0 {
        0.0
    } else if factor == 0.0 {
        // Above any alpha a texel and a vertex can multiply to.
        2.0
    } else {
        (cutoff / factor).min(2.0)
    }
}

/// Deepest node hierarchy accepted; deeper is taken for a cycle.
const MAX_NODE_DEPTH: usize = 64;

/// An embedded scene by name, or a glTF file when `spec` ends in `.gltf` or `.glb`.
pub fn load_scene(spec: &str) -> Result<Scene, ImportError> {
    load_scene_noted(spec).map(|imported| imported.scene)
}

/// A scene and what its file holds that histencil does not render (for the user: said once).
#[derive(Clone, Debug)]
pub struct Imported {
    /// The scene, validated.
    pub scene: Scene,
    /// One line per glTF feature read past without rendering it (`occlusionTexture`,
    /// animations, extensions not read, ...); empty for embedded scenes.
    pub unrendered: Vec<String>,
}

/// [`load_scene`] with the notes of what a glTF file holds but histencil does not render.
pub fn load_scene_noted(spec: &str) -> Result<Imported, ImportError> {
    load_scene_in(spec, &BrdfSet::default())
}

/// [`load_scene_noted`] where a glTF material's extras may name one of `set`'s own BRDFs.
pub fn load_scene_in(spec: &str, set: &BrdfSet) -> Result<Imported, ImportError> {
    let lower = spec.to_ascii_lowercase();
    if lower.ends_with(".gltf") || lower.ends_with(".glb") {
        load_gltf_in(Path::new(spec), set)
    } else {
        Ok(Imported {
            scene: crate::embedded(spec)?,
            unrendered: Vec::new(),
        })
    }
}

/// Reads and imports a `.gltf` or `.glb` file; external buffers are read next to it.
pub fn load_gltf(path: &Path) -> Result<Scene, ImportError> {
    load_gltf_noted(path).map(|imported| imported.scene)
}

/// [`load_gltf`] with the notes of what the file holds but histencil does not render.
pub fn load_gltf_noted(path: &Path) -> Result<Imported, ImportError> {
    load_gltf_in(path, &BrdfSet::default())
}

/// [`load_gltf_noted`] where a material's extras may name one of `set`'s own BRDFs.
pub fn load_gltf_in(path: &Path, set: &BrdfSet) -> Result<Imported, ImportError> {
    let bytes = buffers::read_regular_file(path, ReadLimit::AtMost(MAX_IMPORT_BYTES)).map_err(
        |problem| ImportError::Io {
            path: path.display().to_string(),
            problem,
        },
    )?;
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut imported = import_gltf_in(&bytes, path.parent(), &name, set)?;
    imported.scene.description = format!("glTF {}", path.display());
    Ok(imported)
}

/// Imports glTF or GLB bytes; relative buffer URIs are read from `base_dir`.
pub fn import_gltf(
    bytes: &[u8],
    base_dir: Option<&Path>,
    name: &str,
) -> Result<Scene, ImportError> {
    import_gltf_noted(bytes, base_dir, name).map(|imported| imported.scene)
}

/// [`import_gltf`] with the notes of what the file holds but histencil does not render.
pub fn import_gltf_noted(
    bytes: &[u8],
    base_dir: Option<&Path>,
    name: &str,
) -> Result<Imported, ImportError> {
    import_gltf_in(bytes, base_dir, name, &BrdfSet::default())
}

/// [`import_gltf_noted`] where a material's extras may name one of `set`'s own BRDFs.
pub fn import_gltf_in(
    bytes: &[u8],
    base_dir: Option<&Path>,
    name: &str,
    set: &BrdfSet,
) -> Result<Imported, ImportError> {
    let gltf = document::parse(bytes)?;
    let unrendered = notes::unrendered(&gltf.document);
    let buffers = buffers::load_buffers(&gltf.document, gltf.blob, base_dir)?;
    let quantized = gltf
        .document
        .extensions_used()
        .any(|e| e == attributes::MESH_QUANTIZATION);
    let mut importer = Importer {
        set,
        buffers: &buffers,
        quantized,
        scene: Scene {
            name: name.to_owned(),
            description: "glTF".to_owned(),
            camera: placeholder_camera(),
            objects: vec![],
            lights: vec![],
            alpha_objects: vec![],
            particle_systems: vec![],
            meshes: vec![],
            images: Vec::new(),
        },
        images: images::Images::new(&gltf.document, &buffers, base_dir),
        mesh_slots: HashMap::new(),
        camera: None,
    };
    let document = &gltf.document;
    let root = document
        .default_scene()
        .or_else(|| document.scenes().next())
        .ok_or_else(|| ImportError::Structure("the file has no scene".into()))?;
    for node in root.nodes() {
        importer.visit(&node, Mat4::IDENTITY, 0)?;
    }
    let mut scene = importer.scene;
    scene.camera = match importer.camera {
        Some(camera) => camera,
        None => framing_camera(&scene),
    };
    scene.validate()?;
    scene.normalise_lights();
    Ok(Imported { scene, unrendered })
}

struct Importer<'a> {
    /// The BRDFs a material's extras may name besides the built-ins.
    set: &'a BrdfSet,
    buffers: &'a [Vec<u8>],
    /// The file uses `KHR_mesh_quantization`: integer attribute types are allowed.
    quantized: bool,
    scene: Scene,
    images: images::Images<'a>,
    /// `(mesh, primitive, mirrored)` to its index in `scene.meshes`: a mesh used by several
    /// nodes is stored once per winding.
    mesh_slots: HashMap<(usize, usize, bool), (u32, Mat4)>,
    camera: Option<Camera>,
}

impl Importer<'_> {
    fn visit(&mut self, node: &gltf::Node, parent: Mat4, depth: usize) -> Result<(), ImportError> {
        if depth > MAX_NODE_DEPTH {
            return Err(ImportError::Structure(format!(
                "node {} is nested deeper than {MAX_NODE_DEPTH} levels (a cycle?)",
                node.index()
            )));
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if !world.is_finite() {
            return Err(ImportError::Structure(format!(
                "node {}: transform is not finite",
                node.index()
            )));
        }
        if let Some(mesh) = node.mesh() {
            self.add_mesh(&mesh, world)?;
        }
        if let Some(light) = node.light() {
            let light = import_light(&light, world)?;
            self.scene.lights.push(light);
        }
        if let (None, Some(camera)) = (&self.camera, node.camera()) {
            self.camera = Some(import_camera(&camera, world)?);
        }
        for child in node.children() {
            self.visit(&child, world, depth + 1)?;
        }
        Ok(())
    }

    fn add_mesh(&mut self, mesh: &gltf::Mesh, world: Mat4) -> Result<(), ImportError> {
        let mesh_error = |problem: String| ImportError::Mesh {
            index: mesh.index(),
            name: mesh.name().unwrap_or("").to_owned(),
            problem,
        };
        let mirrored = world.determinant() < 0.0;
        for primitive in mesh.primitives() {
            let gltf_material = primitive.material();
            let pbr = gltf_material.pbr_metallic_roughness();
            let material = material_from_gltf_in(
                self.set,
                gltf_material.extras().as_ref().map(|raw| raw.get()),
                pbr.base_color_factor(),
                pbr.metallic_factor(),
                pbr.roughness_factor(),
            )
            .map_err(|problem| ImportError::Material {
                index: gltf_material.index().unwrap_or(usize::MAX),
                name: gltf_material.name().unwrap_or("default").to_owned(),
                problem,
            })?;
            let blend = gltf_material.alpha_mode() == gltf::material::AlphaMode::Blend;
            let mut material = material;
            material.double_sided = gltf_material.double_sided();
            // Alpha entities are lit per entity from their lightmaps and do not read maps or
            // emit.
            if !blend {
                let strength = gltf_material.emissive_strength().unwrap_or(1.0);
                material.emissive = Vec3::from(gltf_material.emissive_factor()) * strength;
                material.maps = self.material_maps(&gltf_material, material.emits())?;
            }
            let mut texcoords = [false; 2];
            for map in material.maps.refs().into_iter().flatten() {
                if let Some(set) = texcoords.get_mut(map.texcoord as usize) {
                    *set = true;
                }
            }
            let needs = Needs {
                lightmap_uv: blend,
                texcoords,
                tangents_from: material.maps.normal.map(|n| n.texcoord),
            };
            let key = (mesh.index(), primitive.index(), mirrored);
            let (slot, fit) = match self.mesh_slots.get(&key) {
                Some(found) => *found,
                None => {
                    let (fitted, fit) = read_primitive(
                        self.buffers,
                        &primitive,
                        mirrored,
                        needs,
                        self.quantized,
                    )
                    .map_err(|p| mesh_error(format!("primitive {}: {p}", primitive.index())))?;
                    let slot = (self.scene.meshes.len() as u32, fit);
                    self.scene.meshes.push(fitted);
                    self.mesh_slots.insert(key, slot);
                    slot
                }
            };
            let name = format!(
                "{}#{}",
                mesh.name()
                    .map_or_else(|| format!("mesh{}", mesh.index()), str::to_owned),
                primitive.index()
            );
            let (shape, transform) = (Shape::Mesh(slot), world * fit);
            if blend {
                self.scene.alpha_objects.push(AlphaObject {
                    name,
                    shape,
                    transform,
                    material,
                    opacity: pbr.base_color_factor()[3].clamp(0.0, 1.0),
                });
            } else {
                self.scene.objects.push(Object {
                    name,
                    shape,
                    transform,
                    material,
                });
            }
        }
        Ok(())
    }
}

impl Importer<'_> {
    /// The material's texture maps, their images decoded into the scene on first use.
    /// The emissive map is read only where the material `emits` (the map multiplies its
    /// factor).
    fn material_maps(
        &mut self,
        m: &gltf::Material,
        emits: bool,
    ) -> Result<MaterialMaps, ImportError> {
        let images = &mut self.scene.images;
        let pbr = m.pbr_metallic_roughness();
        let mut maps = MaterialMaps {
            normal_scale: 1.0,
            ..MaterialMaps::default()
        };
        let mut info = |info: Option<gltf::texture::Info>| -> Result<_, ImportError> {
            info.map(|i| {
                let placement = match i.texture_transform() {
                    None => (UV_IDENTITY, i.tex_coord()),
                    Some(t) => (
                        uv_transform(t.offset(), t.rotation(), t.scale()),
                        t.tex_coord().unwrap_or(i.tex_coord()),
                    ),
                };
                self.images.texture_ref(images, &i.texture(), Ok(placement))
            })
            .transpose()
        };
        maps.base_color = info(pbr.base_color_texture())?;
        maps.metallic_roughness = info(pbr.metallic_roughness_texture())?;
        if m.alpha_mode() == gltf::material::AlphaMode::Mask {
            maps.alpha_cutoff = Some(mask_threshold(
                m.alpha_cutoff().unwrap_or(0.5),
                pbr.base_color_factor()[3],
            ));
        }
        if emits {
            maps.emissive = info(m.emissive_texture())?;
        }
        if let Some(normal) = m.normal_texture() {
            let set = normal.tex_coord();
            let placement = match normal.extension_value("KHR_texture_transform") {
                None => Ok((UV_IDENTITY, set)),
                Some(value) => images::parse_transform(value, set),
            };
            maps.normal = Some(
                self.images
                    .texture_ref(images, &normal.texture(), placement)?,
            );
            maps.normal_scale = normal.scale();
        }
        Ok(maps)
    }
}

/// What a primitive's vertices must carry beyond positions and normals.
#[derive(Clone, Copy, Debug)]
struct Needs {
    /// `TEXCOORD_0` as a lightmap layout (an alpha object's).
    lightmap_uv: bool,
    /// The texture coordinate sets the material's maps read.
    texcoords: [bool; 2],
    /// Tangents, generated from this texture coordinate set when the file has none (a
    /// normal-mapped material's).
    tangents_from: Option<u32>,
}

/// The primitive's triangles fitted into `[-1, 1]^3`, and the transform that undoes the fit.
fn read_primitive(
    buffers: &[Vec<u8>],
    primitive: &gltf::Primitive,
    mirrored: bool,
    needs: Needs,
    quantized: bool,
) -> Result<(Mesh, Mat4), String> {
    if primitive.mode() != gltf::mesh::Mode::Triangles {
        return Err(format!(
            "mode {:?}: only triangle lists are supported",
            primitive.mode()
        ));
    }
    let positions_accessor = primitive
        .get(&gltf::Semantic::Positions)
        .ok_or("has no POSITION attribute")?;
    let checked = [
        Some(positions_accessor.clone()),
        primitive.get(&gltf::Semantic::Normals),
        primitive.get(&gltf::Semantic::TexCoords(0)),
        primitive.get(&gltf::Semantic::TexCoords(1)),
        primitive.get(&gltf::Semantic::Tangents),
        primitive.get(&gltf::Semantic::Colors(0)),
        primitive.indices(),
    ];
    for accessor in checked.iter().flatten() {
        buffers::check_accessor(accessor, buffers)?;
    }
    use attributes::Attribute;
    let semantics = [
        (Attribute::Position, gltf::Semantic::Positions),
        (Attribute::Normal, gltf::Semantic::Normals),
        (Attribute::Tangent, gltf::Semantic::Tangents),
        (Attribute::TexCoord(0), gltf::Semantic::TexCoords(0)),
        (Attribute::TexCoord(1), gltf::Semantic::TexCoords(1)),
    ];
    for (attribute, semantic) in semantics {
        if let Some(accessor) = primitive.get(&semantic) {
            attributes::check_type(attribute, &accessor, quantized)?;
        }
    }
    let normalised = [DataType::F32, DataType::U8, DataType::U16];
    if let Some(colors) = primitive.get(&gltf::Semantic::Colors(0)) {
        let dimensions = match colors.dimensions() {
            Dimensions::Vec3 => Dimensions::Vec3,
            _ => Dimensions::Vec4,
        };
        check_attribute_type("COLOR_0", &colors, &normalised, dimensions)?;
    }
    if let Some(indices) = primitive.indices() {
        let types = [DataType::U8, DataType::U16, DataType::U32];
        check_attribute_type("indices", &indices, &types, Dimensions::Scalar)?;
    }
    let reader = primitive.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
    let read_vec2 = |set: u32| {
        primitive
            .get(&gltf::Semantic::TexCoords(set))
            .map(|a| attributes::read::<2>(&a, buffers))
            .transpose()
    };
    let positions: Vec<Vec3> = attributes::read::<3>(&positions_accessor, buffers)?
        .into_iter()
        .map(Vec3::from)
        .collect();
    if positions.is_empty() || !positions.iter().all(|p| p.is_finite()) {
        return Err("POSITION must be non-empty and finite".into());
    }
    let mut indices: Vec<u32> = match reader.read_indices() {
        Some(read) => read.into_u32().collect(),
        None => (0..positions.len() as u32).collect(),
    };
    if !indices.len().is_multiple_of(3) || indices.is_empty() {
        return Err(format!("{} indices do not make triangles", indices.len()));
    }
    if indices.iter().any(|&i| i as usize >= positions.len()) {
        return Err("an index is out of range".into());
    }
    let count = positions.len();
    let same_count = |name: &str, len: Option<usize>| match len {
        Some(len) if len != count => Err(format!("{name} and POSITION counts differ")),
        _ => Ok(()),
    };
    let uvs: Option<Vec<[f32; 2]>> = read_vec2(0)?;
    let uvs1: Option<Vec<[f32; 2]>> = read_vec2(1)?;
    let colors: Option<Vec<[f32; 4]>> = reader.read_colors(0).map(|c| c.into_rgba_f32().collect());
    let tangents: Option<Vec<[f32; 4]>> = primitive
        .get(&gltf::Semantic::Tangents)
        .map(|a| attributes::read::<4>(&a, buffers))
        .transpose()?;
    same_count("TEXCOORD_0", uvs.as_ref().map(Vec::len))?;
    same_count("TEXCOORD_1", uvs1.as_ref().map(Vec::len))?;
    same_count("COLOR_0", colors.as_ref().map(Vec::len))?;
    same_count("TANGENT", tangents.as_ref().map(Vec::len))?;
    if needs.lightmap_uv {
        let uvs = uvs
            .as_ref()
            .ok_or("an alphaMode BLEND primitive needs TEXCOORD_0 for its lightmap")?;
        let points: Vec<[f32; 3]> = positions.iter().map(|p| p.to_array()).collect();
        if let Some(problem) = uv_layout::layout_problem(&points, &indices, uvs) {
            return Err(format!("alphaMode BLEND: {problem}"));
        }
    }
    let normals: Option<Vec<Vec3>> = primitive
        .get(&gltf::Semantic::Normals)
        .map(|a| attributes::read::<3>(&a, buffers))
        .transpose()?
        .map(|n| {
            n.into_iter()
                .map(|n| Vec3::from(n).normalize_or(Vec3::Y))
                .collect()
        });
    for (set, has) in [uvs.is_some(), uvs1.is_some()].into_iter().enumerate() {
        if needs.texcoords[set] && !has {
            return Err(format!(
                "its material's textures read TEXCOORD_{set}, which it lacks"
            ));
        }
    }
    let (lo, hi) = positions
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(*p), hi.max(*p))
        });
    let centre = (lo + hi) * 0.5;
    // A flat mesh (a plane) keeps a sliver of thickness so the fit stays invertible.
    let half = ((hi - lo) * 0.5).max(Vec3::splat(((hi - lo).max_element() * 5e-4).max(1e-6)));
    let fit = |p: Vec3| ((p - centre) / half).clamp(Vec3::splat(-1.0), Vec3::splat(1.0));
    // Normals transform by the inverse transpose of the fit's `1 / half` scale, tangents (in
    // the surface) by the fit itself.
    let fit_normal = |n: Vec3| (n * half).normalize_or(Vec3::Y);
    let fit_tangent = |t: [f32; 4]| {
        let xyz = (Vec3::new(t[0], t[1], t[2]) / half).normalize_or_zero();
        xyz.extend(if t[3] < 0.0 { -1.0 } else { 1.0 }).to_array()
    };
    let vertex = |i: usize, normal: Vec3| Vertex {
        position: fit(positions[i]).to_array(),
        normal: normal.to_array(),
        uv: uvs.as_ref().map_or([0.0; 2], |u| u[i]),
        uv1: uvs1.as_ref().map_or([0.0; 2], |u| u[i]),
        tangent: tangents.as_ref().map_or([0.0; 4], |t| fit_tangent(t[i])),
        color: colors.as_ref().map_or([1.0; 4], |c| c[i]),
    };
    let mut mesh = Mesh::default();
    match normals {
        Some(normals) if normals.len() == positions.len() => {
            mesh.vertices = (0..positions.len())
                .map(|i| vertex(i, fit_normal(normals[i])))
                .collect();
            mesh.indices = std::mem::take(&mut indices);
        }
        Some(_) => return Err("NORMAL and POSITION counts differ".into()),
        None => {
            for t in indices.chunks_exact(3) {
                let [a, b, c] = [0, 1, 2].map(|k| positions[t[k] as usize]);
                let n = fit_normal((b - a).cross(c - a).normalize_or(Vec3::Y));
                for &i in t {
                    mesh.indices.push(mesh.vertices.len() as u32);
                    mesh.vertices.push(vertex(i as usize, n));
                }
            }
        }
    }
    if let (Some(set), None) = (needs.tangents_from, &tangents) {
        // In the file's own space and winding, as the normal map was baked.
        let unfit = tangents::Space {
            position: &|p: [f32; 3]| (Vec3::from(p) * half + centre).to_array(),
            normal: &|n: [f32; 3]| (Vec3::from(n) / half).normalize_or(Vec3::Y).to_array(),
            tangent: &fit_tangent,
        };
        tangents::generate(&mut mesh, set, &unfit)?;
    }
    if mirrored {
        // A mirroring transform flips the winding on screen; flipping it here restores it.
        for t in mesh.indices.chunks_exact_mut(3) {
            t.swap(1, 2);
        }
    }
    Ok((
        mesh,
        Mat4::from_translation(centre) * Mat4::from_scale(half),
    ))
}

/// Holds an attribute to the types glTF 2.0 allows it (without `KHR_mesh_quantization`, which
/// histencil does not take): the reader would otherwise read other bytes as floats. Integer
/// texture coordinates must be normalised.
fn check_attribute_type(
    semantic: &str,
    accessor: &gltf::Accessor,
    types: &[DataType],
    dimensions: Dimensions,
) -> Result<(), String> {
    let data_type = accessor.data_type();
    let integer_uv = semantic.starts_with("TEXCOORD") && data_type != DataType::F32;
    let normalised_ok = accessor.normalized() == integer_uv;
    if types.contains(&data_type) && accessor.dimensions() == dimensions && normalised_ok {
        return Ok(());
    }
    Err(format!(
        "{semantic} (accessor {}) is {:?} {:?}{}; glTF 2.0 allows {} {:?}{}",
        accessor.index(),
        accessor.dimensions(),
        data_type,
        if accessor.normalized() {
            " normalized"
        } else {
            ""
        },
        types
            .iter()
            .map(|t| format!("{t:?}"))
            .collect::<Vec<_>>()
            .join(" or "),
        dimensions,
        if semantic.starts_with("TEXCOORD") {
            " (integers normalized)"
        } else {
            ""
        }
    ))
}

fn import_light(
    light: &gltf::khr_lights_punctual::Light,
    world: Mat4,
) -> Result<Light, ImportError> {
    let bad = |problem: &str| ImportError::Light {
        index: light.index(),
        name: light.name().unwrap_or("").to_owned(),
        problem: problem.to_owned(),
    };
    let intensity = light.intensity();
    if !(intensity.is_finite() && intensity >= 0.0) {
        return Err(bad("intensity must be finite and non-negative"));
    }
    let color = Vec3::from(light.color()) * intensity;
    let position = world.transform_point3(Vec3::ZERO);
    let direction = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
    // glTF's falloff: windowed once within a `range`; without one glTF's light is unlimited,
    // so its volume ends where `color / d^2` falls to 1/255 and it is unwindowed up to there.
    let (radius, falloff) = match light.range() {
        Some(range) if range.is_finite() && range > 0.0 => (range, Falloff::Gltf),
        Some(_) => return Err(bad("range must be finite and positive")),
        None => (
            (255.0 * color.max_element()).sqrt().max(1e-3),
            Falloff::InverseSquare,
        ),
    };
    let kind = match light.kind() {
        Kind::Point => LightKind::Point,
        Kind::Directional => LightKind::Directional { direction },
        Kind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        } => {
            if outer_cone_angle > 80f32.to_radians() {
                return Err(bad(
                    "spot outer cone angle above 80 degrees (its volume would not be a cone)",
                ));
            }
            LightKind::Spot {
                direction,
                inner_angle: inner_cone_angle,
                outer_angle: outer_cone_angle,
            }
        }
    };
    Ok(Light {
        kind,
        position,
        radius,
        color,
        falloff,
    })
}

fn import_camera(camera: &gltf::Camera, world: Mat4) -> Result<Camera, ImportError> {
    let gltf::camera::Projection::Perspective(p) = camera.projection() else {
        return Err(ImportError::Camera {
            index: camera.index(),
            problem: "orthographic cameras are not supported".into(),
        });
    };
    let eye = world.transform_point3(Vec3::ZERO);
    Ok(Camera {
        eye,
        target: eye
            + world
                .transform_vector3(Vec3::NEG_Z)
                .normalize_or(Vec3::NEG_Z),
        up: world.transform_vector3(Vec3::Y).normalize_or(Vec3::Y),
        fov_y_radians: p.yfov(),
        near: p.znear(),
        // An infinite projection gets a far plane well beyond anything in a glTF scene.
        far: p.zfar().unwrap_or(p.znear() * 1e5),
    })
}

/// Replaced before the scene is returned.
fn placeholder_camera() -> Camera {
    Camera {
        eye: Vec3::Z,
        target: Vec3::ZERO,
        up: Vec3::Y,
        fov_y_radians: 1.0,
        near: 0.1,
        far: 100.0,
    }
}

/// A 50-degree camera looking at the centre of the objects' bounds from above and in front
/// (+Z, +Y), far enough to see all of it.
fn framing_camera(scene: &Scene) -> Camera {
    let bounds = scene
        .objects
        .iter()
        .map(|o| o.world_bounds())
        .chain(scene.alpha_objects.iter().map(|o| o.world_bounds()))
        .reduce(|(lo, hi), (l, h)| (lo.min(l), hi.max(h)));
    let (lo, hi) = bounds.unwrap_or((Vec3::splat(-1.0), Vec3::splat(1.0)));
    let centre = (lo + hi) * 0.5;
    let radius = ((hi - lo).length() * 0.5).max(1e-3);
    let fov_y_radians = 50f32.to_radians();
    let distance = radius / (fov_y_radians * 0.5).sin();
    Camera {
        eye: centre + Vec3::new(0.0, 0.35, 1.0).normalize() * distance,
        target: centre,
        up: Vec3::Y,
        fov_y_radians,
        near: distance * 0.01,
        far: distance + radius * 2.0,
    }
}
