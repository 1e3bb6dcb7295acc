use crate::alpha::{alpha_problem, transformed_unit_cube};
use crate::texture::{MaterialMaps, TextureImage, TextureRef};
use crate::{AlphaObject, Mesh, ParticleSystem};
use glam::{Mat4, Vec3};
use histencil_brdf::{Brdf, BrdfId};
use histencil_model::{Aabb, DepthConvention, LightShape, ViewDesc};

/// A scene: a camera, opaque objects, lights, and alpha entities (translucent objects and particle
/// systems, drawn after lighting). Plain data; [`Scene::validate`] says whether a renderer can take
/// it.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The scene's name (an embedded scene's, or the glTF file's stem).
    pub name: String,
    /// One line on what the scene shows.
    pub description: String,
    /// The viewpoint the scene is rendered from.
    pub camera: Camera,
    /// The opaque objects: what the G-buffer holds.
    pub objects: Vec<Object>,
    /// Every light, in the order plans and reports number them.
    pub lights: Vec<Light>,
    /// Translucent objects, lit through lightmaps after the deferred pass.
    pub alpha_objects: Vec<AlphaObject>,
    /// Particle systems, lit through lightmaps after the deferred pass.
    pub particle_systems: Vec<ParticleSystem>,
    /// Imported triangle meshes, referenced by [`Shape::Mesh`]; empty for the embedded scenes.
    pub meshes: Vec<Mesh>,
    /// Decoded images, referenced by the materials' maps ([`TextureRef::image`]).
    pub images: Vec<TextureImage>,
}

/// A perspective camera. The aspect ratio comes from the render target.
#[derive(Clone, Copy, Debug)]
pub struct Camera {
    /// World position of the eye.
    pub eye: Vec3,
    /// World point looked at.
    pub target: Vec3,
    /// World direction that is up on screen.
    pub up: Vec3,
    /// Vertical field of view, radians.
    pub fov_y_radians: f32,
    /// Distance to the near plane, above 0.
    pub near: f32,
    /// Distance to the far plane: depth 1 there ([`Camera::projection`]).
    pub far: f32,
}

impl Camera {
    /// World to view (right-handed, looking down -Z).
    pub fn view(&self) -> Mat4 {
        glam::camera::rh::view::look_at_mat4(self.eye, self.target, self.up)
    }

    /// Vulkan clip space: depth 0 at `near`, 1 at `far`, y down.
    pub fn projection(&self, aspect: f32) -> Mat4 {
        glam::camera::rh::proj::vulkan::perspective(self.fov_y_radians, aspect, self.near, self.far)
    }

    /// The view as the frame planner takes it (standard depth, finite far plane).
    pub fn view_desc(&self, aspect: f32) -> ViewDesc {
        ViewDesc {
            world_to_view: self.view().to_cols_array_2d(),
            view_to_clip: self.projection(aspect).to_cols_array_2d(),
            depth: DepthConvention::Standard,
        }
    }
}

/// The shape of an object, in object space.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Shape {
    /// The cube `[-1, 1]^3`.
    Box,
    /// The unit sphere.
    Sphere,
    /// `Scene::meshes[i]`, an imported mesh fitted into `[-1, 1]^3` (the importer folds the
    /// mesh's own bounds into the object's transform), so the transformed unit cube bounds it as
    /// it bounds the built-in shapes. Its `uv` is its lightmap layout when it is an alpha object.
    Mesh(u32),
}

/// An opaque object.
#[derive(Clone, Debug)]
pub struct Object {
    /// Names the object in reports and errors.
    pub name: String,
    /// The object's shape in object space.
    pub shape: Shape,
    /// Object to world.
    pub transform: Mat4,
    /// Its BRDF, tint and maps.
    pub material: Material,
}

impl Object {
    /// The world-space axis-aligned box containing the object: the transformed corners of the
    /// unit cube (which contains the unit sphere too).
    pub fn world_bounds(&self) -> (Vec3, Vec3) {
        transformed_unit_cube(self.transform)
    }
}

/// A surface: a BRDF model with its parameters (as `histencil-brdf` defines them), a tint, and
/// optionally texture maps that vary both over the surface ([`MaterialMaps`]). The outgoing
/// radiance is `brdf.eval_tinted(tint, N, T, V, L) * incident`: `tint * brdf(N, T, V, L)` for
/// the talk's models, and for glTF's metallic-roughness `tint` is the base colour, with a white
/// dielectric specular ([`histencil_brdf::Parts`]); Kajiya-Kay's fibre tangent is the world +Y
/// axis projected onto the surface (see `crates/vk/shaders/include/light.glsl`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// The model and its parameters.
    pub brdf: Brdf,
    /// Linear RGB multiplier in `[0, 1]` per channel: the surface's colour.
    pub tint: Vec3,
    /// Texture maps; opaque objects read them, alpha entities do not (yet).
    pub maps: MaterialMaps,
    /// Linear RGB radiance the surface emits (glTF's `emissiveFactor` times
    /// `KHR_materials_emissive_strength`), times the emissive map where there is one. It is
    /// added once per pixel, whatever the lights; alpha entities do not emit (yet).
    pub emissive: Vec3,
    /// Drawn without back-face culling, its back faces lit with the normal flipped toward the
    /// viewer (glTF's `doubleSided`), in forward and the G-buffer alike. Opaque surfaces only:
    /// alpha entities are lit from their lightmaps and ignore it.
    pub double_sided: bool,
}

impl Material {
    /// An untextured, single-sided material that emits nothing.
    pub fn new(brdf: Brdf, tint: Vec3) -> Self {
        Self {
            brdf,
            tint,
            maps: MaterialMaps::default(),
            emissive: Vec3::ZERO,
            double_sided: false,
        }
    }

    /// Whether the surface emits anything.
    pub fn emits(&self) -> bool {
        self.emissive != Vec3::ZERO
    }

    /// A Lambertian surface of diffuse albedo `albedo`.
    pub fn lambert(albedo: Vec3) -> Self {
        Self::new(Brdf::Lambert { rho: 1.0 }, albedo)
    }

    /// Whether the BRDF's parameters change from texel to texel: a metallic-roughness map on a
    /// model [`crate::textured_brdf`] scales (GGX, Blinn-Phong, Oren-Nayar). A table per
    /// material (the LUT technique's) cannot follow such a surface.
    pub fn parameters_vary(&self) -> bool {
        self.maps.metallic_roughness.is_some()
            && [(0.5, 0.0), (1.0, 0.5)]
                .iter()
                .any(|&(g, b)| crate::textured_brdf(self.brdf, g, b) != self.brdf)
    }
}

/// The kind of a light and its kind-specific parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightKind {
    /// Omnidirectional; its volume is a sphere of the light's radius.
    Point,
    /// A cone along `direction`; full intensity inside `inner_angle`, zero outside `outer_angle`
    /// (half-angles, radians, `outer_angle` below 80 degrees so the cone volume stays a cone).
    Spot {
        /// The cone's axis, from the light outwards.
        direction: Vec3,
        /// Half-angle of full intensity, radians.
        inner_angle: f32,
        /// Half-angle past which the light gives nothing, radians, below 80 degrees.
        outer_angle: f32,
    },
    /// Infinitely far, lighting along `direction`; drawn as a full-screen pass.
    Directional {
        /// The direction the light travels in.
        direction: Vec3,
    },
}

/// How a point or spot light's intensity falls with distance `d` within its range `r`, and
/// across a spot's cone. Every convention is exactly zero at and beyond `r`, which the light's
/// volume encloses. With `x = d / r` and `w = clamp(1 - x^4, 0, 1)`, the radiance scale reaching
/// a point is `color * falloff(d) * cone`:
///
/// | convention | `falloff(d)` | spot `cone`, with `c` the cosine to the axis |
/// |---|---|---|
/// | [`Falloff::SquaredWindow`] | `w^2 / d^2` | `smoothstep(cos outer, cos inner, c)` |
/// | [`Falloff::Gltf`] | `w / d^2` | `t^2`, `t = clamp((c - cos outer) / (cos inner - cos outer), 0, 1)` |
/// | [`Falloff::InverseSquare`] | `1 / d^2` | as [`Falloff::Gltf`] |
///
/// `d^2` is floored at `1e-4` (1 cm at a metre per unit), so a light on a surface stays finite.
/// Lengths are in the scene's units (glTF's are metres); `color` is then in candela (point,
/// spot) or lux (directional), and so is what arrives: `color / d^2` is illuminance in lux.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Falloff {
    /// histencil's own, and Unreal's and Frostbite's: the window squared, so the light fades
    /// smoothly (zero slope) into its range. Every embedded scene's lights.
    #[default]
    SquaredWindow,
    /// `KHR_lights_punctual`'s recommended falloff and cone, as Khronos' glTF Sample Viewer
    /// implements them (`punctual.glsl`): a glTF light with a `range`.
    Gltf,
    /// Inverse square unwindowed, cut at the range: a glTF light without `range`, which glTF
    /// calls unlimited. The volume needs an end; the importer puts it where `color / d^2`
    /// falls to 1/255 (the brightest channel), so what the cut drops is at most that, per unit
    /// of the BRDF's `f * N.L`.
    InverseSquare,
}

/// A light. `color` is linear RGB radiance scale (intensity folded in).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    /// Point, spot or directional, with what each needs.
    pub kind: LightKind,
    /// World position (unused by a directional light).
    pub position: Vec3,
    /// Range: the light's contribution is exactly zero at and beyond this distance.
    pub radius: f32,
    /// Linear RGB radiance scale, the light's intensity folded in.
    pub color: Vec3,
    /// How it falls off with distance and across a spot's cone (unused by a directional light).
    pub falloff: Falloff,
}

impl Light {
    /// A point light at `position`, reaching `radius`, with histencil's falloff
    /// ([`Falloff::SquaredWindow`]).
    pub fn point(position: Vec3, radius: f32, color: Vec3) -> Self {
        Self {
            kind: LightKind::Point,
            position,
            radius,
            color,
            falloff: Falloff::SquaredWindow,
        }
    }

    /// What the frame planner needs of the light: where its volume is.
    pub fn shape(&self) -> LightShape {
        match self.kind {
            LightKind::Point => LightShape::Point {
                position: self.position.into(),
                range: self.radius,
            },
            LightKind::Spot {
                direction,
                outer_angle,
                ..
            } => LightShape::Spot {
                position: self.position.into(),
                direction: direction.into(),
                range: self.radius,
                outer_angle,
            },
            LightKind::Directional { .. } => LightShape::Directional,
        }
    }

    /// True when the light has a bounded volume (point, spot).
    pub fn is_local(&self) -> bool {
        !matches!(self.kind, LightKind::Directional { .. })
    }

    /// Whether the light can add anything inside the box `lo..=hi`: its range sphere reaches the
    /// box (always, for a directional light). Exact culling: the light's falloff is zero at and
    /// beyond its range.
    pub fn reaches_box(&self, lo: Vec3, hi: Vec3) -> bool {
        // The planner's test, so that what a scene reports and what a frame draws agree.
        self.shape().reaches(&Aabb {
            min: lo.into(),
            max: hi.into(),
        })
    }
}

/// A scene that a renderer cannot take, or a name that is not a scene.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SceneError {
    /// No embedded scene has the name.
    #[error("unknown scene `{name}` (embedded scenes: {known})")]
    UnknownScene {
        /// The name asked for.
        name: String,
        /// The embedded scenes' names, comma-separated.
        known: String,
    },
    /// A light a renderer cannot draw (not finite, a range or cone out of bounds, ...).
    #[error("light {index}: {problem}")]
    BadLight {
        /// Its index in [`Scene::lights`].
        index: usize,
        /// What is wrong with it.
        problem: String,
    },
    /// An opaque object a renderer cannot draw (its transform, its material, its mesh).
    #[error("object {index} (`{name}`): {problem}")]
    BadObject {
        /// Its index in [`Scene::objects`].
        index: usize,
        /// Its name.
        name: String,
        /// What is wrong with it.
        problem: String,
    },
    /// A mesh that is not a valid triangle list.
    #[error("mesh {index}: {problem}")]
    BadMesh {
        /// Its index in [`Scene::meshes`].
        index: usize,
        /// What is wrong with it.
        problem: &'static str,
    },
    /// An image whose size or data a renderer cannot upload.
    #[error("image {index} (`{name}`) {problem}")]
    BadImage {
        /// Its index in [`Scene::images`].
        index: usize,
        /// Its name.
        name: String,
        /// What is wrong with it.
        problem: String,
    },
    /// A camera that cannot be projected (not finite, far not beyond near, a field of view out
    /// of bounds).
    #[error("camera: {0}")]
    BadCamera(String),
    /// A translucent object or particle system a renderer cannot light.
    #[error("{kind} {index} (`{name}`): {problem}")]
    BadAlphaEntity {
        /// `alpha object` or `particle system`.
        kind: &'static str,
        /// Its index in [`Scene::alpha_objects`] or [`Scene::particle_systems`].
        index: usize,
        /// Its name.
        name: String,
        /// What is wrong with it.
        problem: String,
    },
}

/// The largest magnitude of a world coordinate (object bounds, particles, lights, the camera).
/// Beyond it f32 cannot place a light volume against the G-buffer (its spacing there is a whole
/// unit), and squared distances in the light code approach f32's range.
pub const MAX_WORLD_COORDINATE: f32 = 1e7;

/// The largest far / near ratio: beyond it an f32 depth buffer maps most of the view to the
/// same depth, and light volumes can no longer be depth-tested against the G-buffer.
pub const MAX_FAR_OVER_NEAR: f32 = 1e6;

/// The narrowest vertical field of view (radians): narrower, the projection's scale (one over
/// the tangent) pushes clip coordinates toward f32's range.
pub const MIN_FOV_Y: f32 = 1e-3;

/// The largest tint component. Base colours are in `[0, 1]`; the slack keeps artistic
/// over-brightening while `tint * brdf * light` stays finite in f32.
pub const MAX_TINT: f32 = 1e3;

/// The largest light colour component (radiance scale, intensity folded in): glTF suns reach
/// 1e5 lux. With [`MAX_TINT`] and the steepest accepted BRDF the light code stays finite in f32
/// (what exceeds the f16 HDR target saturates to white in the tonemap).
pub const MAX_LIGHT_COLOR: f32 = 1e12;

/// A light's range is capped at this many times the scene's extent (see
/// [`Scene::normalise_lights`]): there the range window `(1 - (d/r)^4)^2` is exactly 1 in f32 at
/// every distance the scene holds, so the cap changes no pixel, and the volume stays finite.
pub const RANGE_CAP_PER_EXTENT: f32 = 1e3;

impl Material {
    /// What is wrong with the material, if anything: a tint outside `[0, MAX_TINT]` or not
    /// finite, or BRDF parameters its model refuses.
    pub fn problem(&self) -> Option<String> {
        material_problem(self)
    }
}

/// What is wrong with a material, if anything.
pub(crate) fn material_problem(m: &Material) -> Option<String> {
    if !finite3(m.tint) || m.tint.min_element() < 0.0 || m.tint.max_element() > MAX_TINT {
        Some(format!(
            "tint must be finite, in [0, {MAX_TINT}] per channel, got {}",
            m.tint
        ))
    } else if !finite3(m.emissive)
        || m.emissive.min_element() < 0.0
        || m.emissive.max_element() > MAX_LIGHT_COLOR
    {
        Some(format!(
            "emissive must be finite, in [0, {MAX_LIGHT_COLOR:e}] per channel, got {}",
            m.emissive
        ))
    } else {
        m.brdf.check().err().map(|e| e.to_string())
    }
}

/// What is wrong with a material's maps given the scene's `images`, if anything: an image index
/// out of range, a texture coordinate set other than 0 or 1, a transform or normal scale that
/// is not finite.
fn maps_problem(maps: &MaterialMaps, images: &[TextureImage]) -> Option<String> {
    if !maps.normal_scale.is_finite() {
        return Some("normal map scale must be finite".into());
    }
    let names = ["base colour", "normal", "metallic-roughness", "emissive"];
    maps.refs().iter().zip(names).find_map(|(map, name)| {
        map.and_then(|m| texture_ref_problem(&m, images.len()))
            .map(|p| format!("{name} map: {p}"))
    })
}

fn texture_ref_problem(map: &TextureRef, images: usize) -> Option<String> {
    if map.image as usize >= images {
        Some(format!(
            "image {} does not exist ({images} images)",
            map.image
        ))
    } else if map.texcoord > 1 {
        Some(format!(
            "TEXCOORD_{} is not read (0 and 1 are)",
            map.texcoord
        ))
    } else if !map.transform.iter().flatten().all(|x| x.is_finite()) {
        Some("texture transform must be finite".into())
    } else {
        None
    }
}

/// Whether every coordinate of the box lies within [`MAX_WORLD_COORDINATE`].
fn inside_world((lo, hi): (Vec3, Vec3)) -> bool {
    let limit = Vec3::splat(MAX_WORLD_COORDINATE);
    lo.is_finite() && hi.is_finite() && lo.abs().cmple(limit).all() && hi.abs().cmple(limit).all()
}

fn outside_world_problem(bounds: (Vec3, Vec3)) -> Option<String> {
    (!inside_world(bounds)).then(|| {
        format!(
            "lies outside the supported world range (coordinates within +-{MAX_WORLD_COORDINATE:e}): \
             bounds {} to {}",
            bounds.0, bounds.1
        )
    })
}

/// `v` scaled to unit length, computed in f64 after dividing by the largest component, so
/// vectors of any finite non-zero length (1e-40 or 1e38) normalise; `None` for zero or
/// non-finite ones.
pub fn unit_direction(v: Vec3) -> Option<Vec3> {
    histencil_brdf::normalize(v.to_array().map(f64::from))
        .map(|u| Vec3::from_array(u.map(|x| x as f32)))
}

/// What is wrong with an imported mesh, if anything: it must be a non-empty triangle list with
/// finite vertices inside `[-1, 1]^3` (with a little slack for rounding) and unit normals.
fn mesh_problem(mesh: &Mesh) -> Option<&'static str> {
    const SLACK: f32 = 1e-4;
    if mesh.indices.is_empty() || !mesh.indices.len().is_multiple_of(3) {
        return Some("needs a non-empty triangle list");
    }
    if mesh
        .indices
        .iter()
        .any(|&i| i as usize >= mesh.vertices.len())
    {
        return Some("an index is out of range");
    }
    let inside = |v: &crate::Vertex| {
        v.position
            .iter()
            .all(|p| p.is_finite() && p.abs() <= 1.0 + SLACK)
    };
    let unit = |v: &crate::Vertex| (Vec3::from(v.normal).length() - 1.0).abs() < 1e-3;
    if !mesh.vertices.iter().all(inside) {
        return Some("vertices must be finite and inside [-1, 1]^3");
    }
    if !mesh.vertices.iter().all(unit) {
        return Some("normals must be unit length");
    }
    let attributes = |v: &crate::Vertex| {
        let mut all = v.uv.into_iter().chain(v.uv1).chain(v.tangent);
        all.all(f32::is_finite)
    };
    if !mesh.vertices.iter().all(attributes) {
        return Some("texture coordinates and tangents must be finite");
    }
    let colour = |v: &crate::Vertex| {
        v.color
            .iter()
            .all(|c| c.is_finite() && (0.0..=MAX_TINT).contains(c))
    };
    if !mesh.vertices.iter().all(colour) {
        return Some("vertex colours must be finite and in [0, MAX_TINT]");
    }
    None
}

fn transform_problem(transform: &Mat4) -> Option<String> {
    (!transform.is_finite() || transform.determinant() == 0.0)
        .then(|| "transform must be finite and invertible".to_owned())
}

fn camera_problem(c: &Camera) -> Option<String> {
    let inside = |p: Vec3| inside_world((p, p));
    let ok = inside(c.eye)
        && inside(c.target)
        && finite3(c.up)
        && c.fov_y_radians >= MIN_FOV_Y
        && c.fov_y_radians < 3.0
        && c.near > 0.0
        && c.far > c.near
        && c.far.is_finite()
        && c.far / c.near <= MAX_FAR_OVER_NEAR
        && unit_direction(c.target - c.eye)
            .zip(unit_direction(c.up))
            .is_some_and(|(forward, up)| forward.cross(up).length() > 1e-6);
    (!ok).then(|| {
        format!(
            "needs eye and target within +-{MAX_WORLD_COORDINATE:e}, a finite up not parallel to \
             the view, {MIN_FOV_Y} <= fov < 3 rad, 0 < near < far <= {MAX_FAR_OVER_NEAR:e} * \
             near: {c:?}"
        )
    })
}

impl Light {
    /// Why this light cannot be lit with (a NaN or infinity, a colour out of range, a position
    /// outside the world, a bad spot cone...), as a scene's validation says it; `None` when it
    /// can. A renderer holds every frame's lights to it, whatever technique records them.
    pub fn problem(&self) -> Option<String> {
        light_problem(self)
    }
}

fn light_problem(l: &Light) -> Option<String> {
    let problem = |p: &str| Some(p.to_owned());
    if !finite3(l.position) || !finite3(l.color) || !l.radius.is_finite() {
        return problem("position, colour and radius must be finite (no NaN or Inf)");
    }
    if l.color.min_element() < 0.0 || l.color.max_element() > MAX_LIGHT_COLOR {
        return Some(format!(
            "colour must be in [0, {MAX_LIGHT_COLOR:e}] per channel, got {}",
            l.color
        ));
    }
    if l.is_local() && !inside_world((l.position, l.position)) {
        return Some(format!(
            "position {} lies outside the supported world range (+-{MAX_WORLD_COORDINATE:e})",
            l.position
        ));
    }
    match l.kind {
        LightKind::Point => {}
        LightKind::Spot {
            direction,
            inner_angle,
            outer_angle,
        } => {
            if unit_direction(direction).is_none() {
                return problem("spot direction must be a finite non-zero vector");
            }
            let max = 80f32.to_radians();
            if !(inner_angle >= 0.0 && inner_angle < outer_angle && outer_angle <= max) {
                return problem("spot angles need 0 <= inner < outer <= 80 degrees");
            }
        }
        LightKind::Directional { direction } => {
            if unit_direction(direction).is_none() {
                return problem("directional direction must be a finite non-zero vector");
            }
        }
    }
    if l.is_local() && l.radius <= 0.0 {
        return problem("radius must be positive (zero-size lights light nothing)");
    }
    None
}

fn finite3(v: Vec3) -> bool {
    v.is_finite()
}

impl Scene {
    /// Checks everything a renderer relies on: finite numbers, positive light ranges, spot angles,
    /// a sane camera. Returns the first problem found.
    pub fn validate(&self) -> Result<(), SceneError> {
        for (index, l) in self.lights.iter().enumerate() {
            if let Some(problem) = light_problem(l) {
                return Err(SceneError::BadLight { index, problem });
            }
        }
        for (index, mesh) in self.meshes.iter().enumerate() {
            if let Some(problem) = mesh_problem(mesh) {
                return Err(SceneError::BadMesh { index, problem });
            }
        }
        for (index, image) in self.images.iter().enumerate() {
            if let Some(problem) = image.problem() {
                return Err(SceneError::BadImage {
                    index,
                    name: image.name.clone(),
                    problem,
                });
            }
        }
        for (index, o) in self.objects.iter().enumerate() {
            let problem = self
                .shape_problem(o.shape)
                .or_else(|| transform_problem(&o.transform))
                .or_else(|| outside_world_problem(o.world_bounds()))
                .or_else(|| material_problem(&o.material))
                .or_else(|| maps_problem(&o.material.maps, &self.images));
            if let Some(problem) = problem {
                return Err(SceneError::BadObject {
                    index,
                    name: o.name.clone(),
                    problem,
                });
            }
        }
        let bad_alpha = |kind, index, name: &str, problem: String| SceneError::BadAlphaEntity {
            kind,
            index,
            name: name.to_owned(),
            problem,
        };
        for (index, o) in self.alpha_objects.iter().enumerate() {
            let problem = self
                .shape_problem(o.shape)
                .or_else(|| transform_problem(&o.transform))
                .or_else(|| outside_world_problem(o.world_bounds()))
                .or_else(|| alpha_problem(o.opacity, &o.material));
            if let Some(problem) = problem {
                return Err(bad_alpha("alpha object", index, &o.name, problem));
            }
        }
        for (index, p) in self.particle_systems.iter().enumerate() {
            let problem = p
                .problem()
                .map(str::to_owned)
                .or_else(|| outside_world_problem(p.world_bounds()))
                .or_else(|| alpha_problem(p.opacity, &p.material));
            if let Some(problem) = problem {
                return Err(bad_alpha("particle system", index, &p.name, problem));
            }
        }
        // Last: a camera computed from bad content (a glTF without one is framed on its
        // bounds) would otherwise take the blame for it.
        camera_problem(&self.camera).map_or(Ok(()), |p| Err(SceneError::BadCamera(p)))
    }

    /// The box holding every object, alpha entity, local light and the eye.
    pub fn extent_bounds(&self) -> (Vec3, Vec3) {
        let boxes = self
            .objects
            .iter()
            .map(Object::world_bounds)
            .chain(self.alpha_objects.iter().map(|o| o.world_bounds()))
            .chain(self.particle_systems.iter().map(|p| p.world_bounds()))
            .chain(
                self.lights
                    .iter()
                    .filter(|l| l.is_local())
                    .map(|l| (l.position, l.position)),
            )
            .chain(std::iter::once((self.camera.eye, self.camera.eye)));
        boxes
            .reduce(|(lo, hi), (l, h)| (lo.min(l), hi.max(h)))
            .expect("the eye is always there")
    }

    /// Brings every light into the form the GPU evaluates exactly as the CPU does, changing no
    /// pixel: directions become unit vectors (computed in f64, so any finite non-zero length
    /// works), and a local light's range is capped at [`RANGE_CAP_PER_EXTENT`] times the
    /// scene's extent (a range of 1e38 would overflow its volume's f32 transform; at the cap its
    /// window is already exactly 1 everywhere in the scene). [`Scene::validate`] first.
    pub fn normalise_lights(&mut self) {
        let (lo, hi) = self.extent_bounds();
        let cap = (hi - lo).length().max(1e-3) * RANGE_CAP_PER_EXTENT;
        for light in &mut self.lights {
            if light.is_local() {
                light.radius = light.radius.min(cap);
            }
            match &mut light.kind {
                LightKind::Point => {}
                LightKind::Spot { direction, .. } | LightKind::Directional { direction } => {
                    *direction = unit_direction(*direction).unwrap_or(*direction);
                }
            }
        }
    }

    fn shape_problem(&self, shape: Shape) -> Option<String> {
        match shape {
            Shape::Mesh(i) if i as usize >= self.meshes.len() => {
                Some("mesh index out of range".to_owned())
            }
            _ => None,
        }
    }

    /// The scene without its alpha entities: what the alpha pass draws over, the background
    /// of an alpha error figure.
    pub fn without_alpha(&self) -> Scene {
        Scene {
            alpha_objects: vec![],
            particle_systems: vec![],
            ..self.clone()
        }
    }

    /// How many alpha entities (translucent objects and particle systems) the scene has.
    pub fn alpha_entity_count(&self) -> usize {
        self.alpha_objects.len() + self.particle_systems.len()
    }

    /// The alpha entities' names, objects first (the order their lightmaps are planned in).
    pub fn alpha_entity_names(&self) -> Vec<&str> {
        let objects = self.alpha_objects.iter().map(|o| o.name.as_str());
        let systems = self.particle_systems.iter().map(|s| s.name.as_str());
        objects.chain(systems).collect()
    }

    /// The distinct BRDFs the objects use, sorted by id. Their position in this list is their
    /// stencil slot.
    pub fn brdfs_in_use(&self) -> Vec<BrdfId> {
        distinct_brdfs(self.objects.iter())
    }

    /// The frame planner's BRDF bounds: for each BRDF of `brdfs` (a slot each), the world boxes
    /// of its objects.
    pub fn brdf_bounds(&self, brdfs: &[BrdfId]) -> Vec<Vec<Aabb>> {
        let mut bounds = vec![Vec::new(); brdfs.len()];
        for object in &self.objects {
            if let Some(slot) = brdfs.iter().position(|b| *b == object.material.brdf.id()) {
                let (lo, hi) = object.world_bounds();
                bounds[slot].push(Aabb {
                    min: lo.into(),
                    max: hi.into(),
                });
            }
        }
        bounds
    }

    /// The BRDFs of the objects that `light` can reach (world bounds against its range sphere;
    /// every BRDF in use for a directional light), sorted by id. A light volume is drawn once per
    /// BRDF in this list, so a BRDF the light cannot touch costs nothing.
    pub fn brdfs_lit_by(&self, light: &Light) -> Vec<BrdfId> {
        distinct_brdfs(self.objects.iter().filter(|o| {
            let (lo, hi) = o.world_bounds();
            light.reaches_box(lo, hi)
        }))
    }
}

/// The distinct BRDFs of `objects`, sorted by id.
fn distinct_brdfs<'a>(objects: impl Iterator<Item = &'a Object>) -> Vec<BrdfId> {
    let mut v: Vec<BrdfId> = objects.map(|o| o.material.brdf.id()).collect();
    v.sort();
    v.dedup();
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nan_and_zero_size_lights_are_rejected() {
        let mut s = crate::embedded("default").unwrap();
        s.lights[0].radius = 0.0;
        assert!(matches!(
            s.validate(),
            Err(SceneError::BadLight { index: 0, .. })
        ));
        s.lights[0].radius = 1.0;
        s.lights[1].position.x = f32::NAN;
        let err = s.validate().unwrap_err();
        assert!(err.to_string().contains("light 1"), "{err}");
    }

    #[test]
    fn brdfs_in_use_are_sorted_and_distinct() {
        let s = crate::embedded("default").unwrap();
        assert_eq!(s.brdfs_in_use(), vec![BrdfId::Lambert, BrdfId::BlinnPhong]);
    }

    #[test]
    fn lights_touch_only_the_brdfs_in_their_range() {
        let s = crate::embedded("brdfs-6").unwrap();
        let far_away = Light::point(Vec3::new(0.0, 100.0, 0.0), 1.0, Vec3::ONE);
        assert!(s.brdfs_lit_by(&far_away).is_empty());
        // Over the first sphere, small: only that sphere's BRDF (and nothing else nearby).
        let sphere = &s.objects[4];
        let (lo, hi) = sphere.world_bounds();
        let top = Vec3::new((lo.x + hi.x) * 0.5, hi.y + 0.5, (lo.z + hi.z) * 0.5);
        let close = Light::point(top, 0.6, Vec3::ONE);
        assert_eq!(s.brdfs_lit_by(&close), vec![sphere.material.brdf.id()]);
        let sun = s.lights.iter().find(|l| !l.is_local()).unwrap();
        assert_eq!(s.brdfs_lit_by(sun), s.brdfs_in_use());
    }
}
