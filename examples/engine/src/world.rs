//! The engine's world: a floor and eight boxes in six BRDFs (two of them the engine's own, from
//! `../brdfs`; three BRDFs in two materials each, with their own parameters), a glass sphere and a smoke cloud
//! (translucent), 64 point lights and a camera, all animated by frame number. Its own types;
//! `histencil_scene` for its procedural meshes and particles and for the forward reference.

use glam::{Mat4, Quat, Vec3};
use histencil::brdf::{Brdf, BrdfId, BrdfSet};
use histencil::model::Aabb;
use histencil::scene::{
    uv_sphere, AlphaObject, Camera, Light, Material, Mesh, Object as SceneObject, ParticleLayout,
    ParticleSystem, Scene, Shape,
};

pub const LIGHTS: usize = 64;
/// The spot light the engine shadows, after the point lights: the last of the frame's lights.
pub const SHADOWED_LIGHT: usize = LIGHTS;

/// The engine's own stencil data: what it keeps in its two bits.
pub const WALKABLE: u8 = 0x80;
pub const DYNAMIC: u8 = 0x40;

pub struct Object {
    /// Places the unit cube `[-1, 1]^3`.
    pub transform: Mat4,
    pub brdf: Brdf,
    pub tint: Vec3,
    /// The engine's bits for this object's pixels.
    pub stencil: u8,
}

pub struct World {
    pub objects: Vec<Object>,
    /// The BRDFs in use; an index here is a stencil slot.
    pub brdfs: Vec<BrdfId>,
}

/// Materials carry their own parameters, not their BRDF's: the boxes past the first round of
/// BRDFs are a second material of the same BRDF (a rougher GGX, a rougher Oren-Nayar, a
/// sharper Blinn-Phong), one stencil id and one light shader with the first. The compact
/// G-buffer stores each pixel's parameters, so nothing else changes.
fn second_material(brdf: Brdf, round: usize) -> Brdf {
    match (brdf, round) {
        (Brdf::Ggx { f0, f90, .. }, 1) => Brdf::Ggx {
            alpha: 0.6,
            f0,
            f90,
        },
        (Brdf::OrenNayarFull { rho, .. }, 1) => Brdf::OrenNayarFull { rho, sigma: 0.15 },
        (Brdf::BlinnPhong { .. }, 1) => Brdf::BlinnPhong { exponent: 200.0 },
        _ => brdf,
    }
}

impl World {
    /// The world, its engine BRDFs (`toon`, `charlie_sheen`) from `set`: the third parameter
    /// of each is 1, which the compact G-buffer does not store.
    pub fn new(set: &BrdfSet) -> Self {
        let own = |name: &str, given: &[(&str, f64)]| {
            set.engine_brdf(name, given)
                .expect("a BRDF of the engine's set")
        };
        let mut objects = vec![Object {
            transform: Mat4::from_scale_rotation_translation(
                Vec3::new(8.0, 0.1, 8.0),
                Quat::IDENTITY,
                Vec3::new(0.0, -0.1, 0.0),
            ),
            brdf: Brdf::Lambert { rho: 0.8 },
            tint: Vec3::new(0.8, 0.78, 0.74),
            stencil: WALKABLE,
        }];
        let brdfs = [
            Brdf::Ggx {
                alpha: 0.3,
                f0: 0.04,
                f90: 1.0,
            },
            Brdf::OrenNayarFull {
                rho: 0.7,
                sigma: 0.5,
            },
            Brdf::BlinnPhong { exponent: 40.0 },
            own("toon", &[("bands", 3.0), ("softness", 0.25), ("rho", 1.0)]),
            own(
                "charlie_sheen",
                &[("rho", 0.5), ("roughness", 0.4), ("sheen", 1.0)],
            ),
        ];
        for i in 0..8 {
            let angle = i as f32 * std::f32::consts::TAU / 8.0;
            let height = 0.4 + 0.15 * (i % 3) as f32;
            objects.push(Object {
                transform: Mat4::from_scale_rotation_translation(
                    Vec3::new(0.45, height, 0.45),
                    Quat::from_rotation_y(angle * 0.7),
                    Vec3::new(3.0 * angle.cos(), height, 3.0 * angle.sin()),
                ),
                brdf: second_material(brdfs[i % brdfs.len()], i / brdfs.len()),
                tint: Vec3::new(0.9, 0.5 + 0.05 * i as f32, 0.3 + 0.08 * i as f32),
                stencil: DYNAMIC,
            });
        }
        let mut ids: Vec<BrdfId> = Vec::new();
        for o in &objects {
            if !ids.contains(&o.brdf.id()) {
                ids.push(o.brdf.id());
            }
        }
        Self {
            objects,
            brdfs: ids,
        }
    }

    /// How many distinct materials (a BRDF with its parameters) the objects have: more than
    /// BRDFs, since materials of one BRDF keep their own parameters.
    pub fn material_count(&self) -> usize {
        let mut seen: Vec<Brdf> = Vec::new();
        for o in &self.objects {
            if !seen.contains(&o.brdf) {
                seen.push(o.brdf);
            }
        }
        seen.len()
    }

    pub fn slot(&self, object: &Object) -> u32 {
        self.brdfs
            .iter()
            .position(|b| *b == object.brdf.id())
            .unwrap() as u32
    }

    /// Each BRDF slot's object bounds, as the planner takes them.
    pub fn brdf_bounds(&self) -> Vec<Vec<Aabb>> {
        let mut bounds = vec![Vec::new(); self.brdfs.len()];
        for o in &self.objects {
            let corners = (0..8).map(|c| {
                let unit = Vec3::new(
                    if c & 1 == 0 { -1.0 } else { 1.0 },
                    if c & 2 == 0 { -1.0 } else { 1.0 },
                    if c & 4 == 0 { -1.0 } else { 1.0 },
                );
                o.transform.transform_point3(unit)
            });
            let (min, max) = corners.fold(
                (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
                |(lo, hi), p| (lo.min(p), hi.max(p)),
            );
            bounds[self.slot(o) as usize].push(Aabb {
                min: min.to_array(),
                max: max.to_array(),
            });
        }
        bounds
    }
}

/// The heights the lights circle at: clear of the floor (y = 0) and of the box tops (0.8, 1.1
/// and 1.4) by 0.15 or more. A point light in a lit surface's plane makes `N.L` rounding noise
/// over `1 / d^2` beside it: with lights at 0.8 (the old `0.3 + 0.25 k`), one passed over a GGX
/// box's top, and on an NVIDIA H100 forward and every deferred technique differed by 9/255 on
/// one pixel next to it (the position each reconstructs differs by an ulp).
const LIGHT_HEIGHTS: [f32; 5] = [0.3, 0.55, 0.95, 1.25, 1.6];

/// 64 point lights circling the room at frame `frame`, each on its own orbit, and a shadowed
/// spot light swinging over the boxes ([`SHADOWED_LIGHT`]).
pub fn lights(frame: usize) -> Vec<Light> {
    let mut lights = point_lights(frame);
    lights.push(spot_light(frame));
    lights
}

/// The shadowed spot light: high above the room, aimed past the boxes so their shadows fall
/// across the floor.
pub fn spot_light(frame: usize) -> Light {
    let t = frame as f32 * 0.02;
    let position = Vec3::new(2.5 * t.cos(), 4.5, 2.5 * t.sin());
    let target = Vec3::new(-0.5 * t.cos(), 0.0, -0.5 * t.sin());
    Light {
        kind: histencil::scene::LightKind::Spot {
            direction: (target - position).normalize(),
            inner_angle: 0.6,
            outer_angle: 0.75,
        },
        position,
        radius: 12.0,
        color: Vec3::new(60.0, 56.0, 48.0),
        falloff: histencil::scene::Falloff::SquaredWindow,
    }
}

/// World to the shadow map's clip space for `light` (a spot): a perspective projection along
/// its direction covering its cone, depth 0 at `near` to 1 at its range.
pub fn shadow_view_proj(light: &Light) -> Mat4 {
    let histencil::scene::LightKind::Spot {
        direction,
        outer_angle,
        ..
    } = light.kind
    else {
        panic!("the shadowed light is a spot");
    };
    let up = if direction.y.abs() > 0.99 {
        Vec3::X
    } else {
        Vec3::Y
    };
    let view = glam::camera::rh::view::look_to_mat4(light.position, direction, up);
    let fov = 2.0 * outer_angle + 0.05;
    glam::camera::rh::proj::vulkan::perspective(fov, 1.0, 0.5, light.radius) * view
}

fn point_lights(frame: usize) -> Vec<Light> {
    (0..LIGHTS)
        .map(|i| {
            let t = frame as f32 * 0.05;
            let ring = 1.0 + (i % 4) as f32 * 1.1;
            let phase = i as f32 * 2.399 + t * (1.0 + (i % 3) as f32 * 0.5);
            let position = Vec3::new(
                ring * phase.cos(),
                LIGHT_HEIGHTS[i % LIGHT_HEIGHTS.len()],
                ring * phase.sin(),
            );
            let hue = i as f32 * 0.37;
            let color = Vec3::new(
                0.6 + 0.4 * hue.sin(),
                0.6 + 0.4 * (hue + 2.1).sin(),
                0.6 + 0.4 * (hue + 4.2).sin(),
            ) * 0.6;
            Light::point(position, 1.2 + 0.4 * (i % 4) as f32, color)
        })
        .collect()
}

/// The camera at frame `frame`, orbiting the room.
pub fn camera(frame: usize) -> Camera {
    let angle = 0.4 + frame as f32 * 0.01;
    Camera {
        eye: Vec3::new(7.0 * angle.cos(), 3.5, 7.0 * angle.sin()),
        target: Vec3::new(0.0, 0.3, 0.0),
        up: Vec3::Y,
        fov_y_radians: 0.9,
        near: 0.1,
        // The engine's own projection has no far plane; everything lies well within this one.
        far: 100.0,
    }
}

/// The translucent part of the world at one frame: a glass sphere bobbing among the lights and a
/// cloud of smoke drifting up through them, lit per entity by histencil's lightmaps.
pub struct AlphaWorld {
    pub camera: Camera,
    pub glass_transform: Mat4,
    pub glass_material: Material,
    pub glass_opacity: f32,
    pub smoke: ParticleSystem,
}

/// The glass sphere's mesh: drawn by the engine's alpha pass, and its UV layout holds the
/// sphere's light probes.
pub fn sphere_mesh() -> Mesh {
    uv_sphere(48, 24)
}

impl AlphaWorld {
    pub fn at(frame: usize) -> Self {
        let t = frame as f32 * 0.05;
        let glass = histencil::scene::glass_sphere(Vec3::new(0.4, 1.1 + 0.2 * t.sin(), 0.3), 0.55);
        let mut smoke = histencil::scene::smoke_volume(
            Vec3::new(-1.6, 0.9 + 0.1 * t, 1.4),
            0.8,
            48,
            ParticleLayout::Auto,
        );
        smoke.opacity = 0.35;
        Self {
            camera: camera(frame),
            glass_transform: glass.transform,
            glass_material: glass.material,
            glass_opacity: glass.opacity,
            smoke,
        }
    }

    /// Entity 0 (the sphere) and 1 (the smoke), farthest from the camera first.
    pub fn back_to_front(&self) -> [u32; 2] {
        let forward = (self.camera.target - self.camera.eye).normalize();
        let depth = |p: Vec3| (p - self.camera.eye).dot(forward);
        let (lo, hi) = self.smoke.world_bounds();
        if depth(self.glass_transform.w_axis.truncate()) >= depth((lo + hi) * 0.5) {
            [0, 1]
        } else {
            [1, 0]
        }
    }

    fn glass(&self) -> AlphaObject {
        AlphaObject {
            name: "glass".into(),
            shape: Shape::Sphere,
            transform: self.glass_transform,
            material: self.glass_material,
            opacity: self.glass_opacity,
        }
    }
}

/// The same state as a histencil scene, for histencil's forward reference.
pub fn scene(world: &World, frame: usize) -> Scene {
    Scene {
        name: "engine-example".into(),
        description: "the example engine's world".into(),
        camera: camera(frame),
        objects: world
            .objects
            .iter()
            .enumerate()
            .map(|(i, o)| SceneObject {
                name: format!("object-{i}"),
                shape: Shape::Box,
                transform: o.transform,
                material: Material::new(o.brdf, o.tint),
            })
            .collect(),
        lights: lights(frame),
        alpha_objects: vec![AlphaWorld::at(frame).glass()],
        particle_systems: vec![AlphaWorld::at(frame).smoke],
        meshes: Vec::new(),
        images: Vec::new(),
    }
}
