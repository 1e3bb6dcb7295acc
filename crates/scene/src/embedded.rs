//! The embedded scenes: a procedural room and its variants. Deterministic: the same name always
//! gives the same scene (a fixed-seed generator, no system randomness).

use crate::split_mix::SplitMix;
use crate::{Camera, Light, LightKind, Material, Object, Scene, SceneError, Shape};
use glam::{Mat4, Quat, Vec3};
use histencil_brdf::{Brdf, BrdfId};

/// The room's material of model `id`; `variant` varies its parameters between objects.
fn material(id: BrdfId, variant: usize, tint: Vec3) -> Material {
    let brdf = match id {
        BrdfId::Lambert => Brdf::Lambert { rho: 1.0 },
        BrdfId::BlinnPhong => Brdf::BlinnPhong {
            exponent: [16.0, 64.0, 256.0][variant % 3],
        },
        BrdfId::OrenNayarFull => Brdf::OrenNayarFull {
            rho: 0.9,
            sigma: [0.3, 0.6][variant % 2],
        },
        BrdfId::OrenNayarQualitative => Brdf::OrenNayarQualitative {
            rho: 0.9,
            sigma: [0.3, 0.6][variant % 2],
        },
        BrdfId::Ggx => Brdf::Ggx {
            alpha: [0.15, 0.4][variant % 2],
            f0: [0.04, 0.6][variant % 2],
            f90: 1.0,
        },
        BrdfId::KajiyaKay => Brdf::KajiyaKay {
            kd: 0.35,
            ks: 0.5,
            p: 40.0,
        },
        BrdfId::PennerSkin => Brdf::PennerSkin {
            rho: 0.85,
            curvature_per_mm: [0.3, 1.0][variant % 2],
        },
        // A rough dielectric and a polished metal.
        BrdfId::GltfMetalRough => Brdf::GltfMetalRough {
            alpha: [0.36, 0.04][variant % 2],
            metallic: [0.0, 1.0][variant % 2],
        },
        // Every caller here names one of BrdfId::ALL.
        BrdfId::Engine(e) => unreachable!("an embedded scene names engine BRDF `{}`", e.name()),
    };
    Material::new(brdf, tint)
}

/// `(name, description)` of every embedded scene.
pub const EMBEDDED: [(&str, &str); 14] = [
    (
        "default",
        "procedural room: 2 BRDFs, 36 point lights from tiny to huge, 3 spots, 1 directional",
    ),
    (
        "brdfs-1",
        "the default room with Lambert only: the plain deferred path, no BRDF passes",
    ),
    (
        "brdfs-3",
        "the default room with Lambert, Oren-Nayar (full) and GGX",
    ),
    (
        "brdfs-6",
        "the default room with all six BRDFs: Lambert, Blinn-Phong, Oren-Nayar, GGX, \
         Kajiya-Kay, Penner skin",
    ),
    (
        "pbr-mixed",
        "the default room with glTF's metallic-roughness BRDF (a rough dielectric, a polished \
         metal) beside Penner skin, Kajiya-Kay hair and Oren-Nayar cloth",
    ),
    (
        "huge-lights",
        "the room with Lambert, Blinn-Phong and Oren-Nayar under 8 huge point lights, each \
         covering the whole screen, as in the talk's measurements",
    ),
    (
        "inside",
        "the default room with the camera inside a huge point light's volume",
    ),
    (
        "near-far",
        "the default room with light volumes crossing the near and the far plane",
    ),
    (
        "alpha",
        "the default room with a glass sphere and a smoke column, each next to a point light",
    ),
    (
        "dust",
        "the default room with a cloud of 600 dust motes (one lightmap texel each) around two lights",
    ),
    (
        "ribbon",
        "the default room with a helical ribbon trail (a line of lightmap texels) round a light",
    ),
    (
        "volume",
        "the default room with a thick ball of smoke (slices chosen by the error estimate), a point light inside it",
    ),
    (
        "alpha-many",
        "the default room with 8 smoke systems x 256 particles, each with a light of its own",
    ),
    (
        "town",
        "a generated town at a real scene's scale: 248k triangles, 25 textured materials (base colour, normal, metallic-roughness) in 4 BRDFs, 224 point and 32 spot lights",
    ),
];

/// The names [`embedded`] accepts, in [`EMBEDDED`]'s order.
pub fn embedded_names() -> impl Iterator<Item = &'static str> {
    EMBEDDED.iter().map(|(n, _)| *n)
}

/// The embedded scene called `name`.
pub fn embedded(name: &str) -> Result<Scene, SceneError> {
    let description = EMBEDDED
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, d)| d.to_string())
        .ok_or_else(|| SceneError::UnknownScene {
            name: name.to_owned(),
            known: embedded_names().collect::<Vec<_>>().join(", "),
        })?;
    if name == "town" {
        return Ok(crate::town::town(name, description));
    }
    let models: &[BrdfId] = match name {
        "brdfs-1" => &[BrdfId::Lambert],
        "brdfs-3" => &[BrdfId::Lambert, BrdfId::OrenNayarFull, BrdfId::Ggx],
        "huge-lights" => &[BrdfId::Lambert, BrdfId::BlinnPhong, BrdfId::OrenNayarFull],
        "pbr-mixed" => &[
            BrdfId::GltfMetalRough,
            BrdfId::PennerSkin,
            BrdfId::KajiyaKay,
            BrdfId::OrenNayarFull,
        ],
        "brdfs-6" => &[
            BrdfId::Lambert,
            BrdfId::BlinnPhong,
            BrdfId::OrenNayarFull,
            BrdfId::Ggx,
            BrdfId::KajiyaKay,
            BrdfId::PennerSkin,
        ],
        _ => &[BrdfId::Lambert, BrdfId::BlinnPhong],
    };
    let mut scene = room(name, description, models);
    crate::alpha_scenes::add_alpha_entities(name, &mut scene);
    match name {
        "huge-lights" => scene.lights = huge_lights(),
        "inside" => {
            scene.camera.eye = Vec3::new(1.5, 2.2, 5.0);
            scene.lights.push(Light::point(
                Vec3::new(2.5, 2.5, 4.0),
                6.0,
                Vec3::new(2.0, 1.6, 1.2),
            ));
        }
        "near-far" => {
            scene.camera.near = 0.5;
            scene.camera.far = 15.0;
            // Crosses the near plane while the eye stays outside it.
            let forward = (scene.camera.target - scene.camera.eye).normalize();
            scene.lights.push(Light::point(
                scene.camera.eye + forward * 0.9 + Vec3::new(0.3, -0.2, 0.0),
                0.7,
                Vec3::new(0.3, 0.6, 1.0),
            ));
            // Crosses the far plane over the back of the room.
            scene.lights.push(Light::point(
                scene.camera.eye + forward * 14.5,
                4.0,
                Vec3::new(6.0, 3.0, 1.5),
            ));
        }
        _ => {}
    }
    Ok(scene)
}

/// Eight point lights of range 40 spread over the room: the camera is inside every volume, so
/// each covers the whole screen, and each reaches every object.
fn huge_lights() -> Vec<Light> {
    (0..8)
        .map(|i| {
            let (x, z) = ((i % 4) as f32 * 4.0 - 6.0, (i / 4) as f32 * 6.0 - 7.0);
            let hue = [
                Vec3::new(1.0, 0.85, 0.7),
                Vec3::new(0.7, 0.8, 1.0),
                Vec3::new(0.9, 1.0, 0.8),
            ][i % 3];
            Light::point(Vec3::new(x, 3.5, z), 40.0, hue * 10.0)
        })
        .collect()
}

fn object(name: &str, shape: Shape, transform: Mat4, material: Material) -> Object {
    Object {
        name: name.to_owned(),
        shape,
        transform,
        material,
    }
}

fn slab(name: &str, center: Vec3, half: Vec3, material: Material) -> Object {
    object(
        name,
        Shape::Box,
        Mat4::from_scale_rotation_translation(half, Quat::IDENTITY, center),
        material,
    )
}

/// The procedural room; objects take the models of `models` in turn (walls and floor the first,
/// the others in turn), so every model in the list is in use.
fn room(name: &str, description: String, models: &[BrdfId]) -> Scene {
    let wall = material(models[0], 0, Vec3::new(0.75, 0.72, 0.68));
    let floor = material(models[0], 1, Vec3::new(0.5, 0.45, 0.4));
    let mut objects = vec![
        slab(
            "floor",
            Vec3::new(0.0, -0.1, 0.0),
            Vec3::new(8.0, 0.1, 10.0),
            floor,
        ),
        slab(
            "wall-back",
            Vec3::new(0.0, 3.0, -10.1),
            Vec3::new(8.0, 3.0, 0.1),
            wall,
        ),
        slab(
            "wall-left",
            Vec3::new(-8.1, 3.0, 0.0),
            Vec3::new(0.1, 3.0, 10.0),
            wall,
        ),
        slab(
            "wall-right",
            Vec3::new(8.1, 3.0, 0.0),
            Vec3::new(0.1, 3.0, 10.0),
            wall,
        ),
    ];
    let mut rng = SplitMix(0x6869_7374_656e_6369);
    for i in 0..6 {
        let x = -5.0 + 2.0 * i as f32;
        let z = -3.0 - (i % 2) as f32 * 2.5;
        let r = 0.6 + 0.1 * (i % 3) as f32;
        let albedo = Vec3::new(
            rng.range(0.2, 0.9),
            rng.range(0.2, 0.9),
            rng.range(0.2, 0.9),
        );
        let material = material(models[(i + 1) % models.len()], i / 2, albedo);
        let t = Mat4::from_scale_rotation_translation(
            Vec3::splat(r),
            Quat::IDENTITY,
            Vec3::new(x, r, z),
        );
        objects.push(object(&format!("sphere-{i}"), Shape::Sphere, t, material));
    }
    for i in 0..4 {
        let x = -4.5 + 3.0 * i as f32;
        let h = 0.4 + 0.3 * i as f32;
        let rot = Quat::from_rotation_y(0.4 * i as f32 + 0.2);
        let albedo = Vec3::new(
            rng.range(0.3, 0.9),
            rng.range(0.3, 0.9),
            rng.range(0.3, 0.9),
        );
        let material = material(models[i % models.len()], i, albedo);
        let t = Mat4::from_scale_rotation_translation(
            Vec3::new(0.5, h, 0.5),
            rot,
            Vec3::new(x, h, 1.0),
        );
        objects.push(object(&format!("box-{i}"), Shape::Box, t, material));
    }

    let mut lights = Vec::new();
    // 36 point lights on a jittered grid; radii from tiny (0.25) to huge (12).
    for i in 0..36 {
        let gx = (i % 6) as f32;
        let gz = (i / 6) as f32;
        let radius = 0.25 * 48f32.powf(rng.next_f32().powi(2));
        let position = Vec3::new(
            -6.5 + 2.6 * gx + rng.range(-0.5, 0.5),
            rng.range(0.2, 4.5),
            -9.0 + 3.0 * gz + rng.range(-0.5, 0.5),
        );
        let hue = Vec3::new(
            rng.range(0.3, 1.0),
            rng.range(0.3, 1.0),
            rng.range(0.3, 1.0),
        );
        // Brightness grows with the radius (falloff is ~1/d^2) so huge lights stay visible.
        let color = hue * (0.4 + 0.3 * radius * radius);
        lights.push(Light::point(position, radius, color));
    }
    for (i, (pos, target)) in [
        (Vec3::new(-5.0, 5.5, 2.0), Vec3::new(-4.0, 0.0, -1.0)),
        (Vec3::new(0.0, 5.8, -2.0), Vec3::new(0.5, 0.0, -4.0)),
        (Vec3::new(5.0, 5.0, 3.0), Vec3::new(3.0, 0.0, 1.0)),
    ]
    .into_iter()
    .enumerate()
    {
        lights.push(Light {
            kind: LightKind::Spot {
                direction: target - pos,
                inner_angle: (15.0 + 5.0 * i as f32).to_radians(),
                outer_angle: (25.0 + 8.0 * i as f32).to_radians(),
            },
            position: pos,
            radius: 9.0,
            color: Vec3::new(14.0, 12.0, 9.0),
            falloff: crate::Falloff::SquaredWindow,
        });
    }
    lights.push(Light {
        kind: LightKind::Directional {
            direction: Vec3::new(0.3, -1.0, -0.4),
        },
        position: Vec3::ZERO,
        radius: 0.0,
        color: Vec3::new(0.08, 0.09, 0.12),
        falloff: crate::Falloff::SquaredWindow,
    });

    Scene {
        name: name.to_owned(),
        description,
        camera: Camera {
            eye: Vec3::new(0.0, 3.2, 9.0),
            target: Vec3::new(0.0, 1.0, -3.0),
            up: Vec3::Y,
            fov_y_radians: 60f32.to_radians(),
            near: 0.1,
            far: 40.0,
        },
        objects,
        lights,
        alpha_objects: vec![],
        particle_systems: vec![],
        meshes: vec![],
        images: Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_embedded_scene_is_valid_and_deterministic() {
        for name in embedded_names() {
            let a = embedded(name).unwrap();
            a.validate().unwrap();
            let b = embedded(name).unwrap();
            assert_eq!(format!("{a:?}"), format!("{b:?}"));
            let points = a
                .lights
                .iter()
                .filter(|l| l.kind == LightKind::Point)
                .count();
            // Every room keeps its 36 point lights, except the one built to have only huge ones.
            let expected = match name {
                "huge-lights" => 8,
                "town" => 224,
                _ => 32,
            };
            assert!(points >= expected, "{name}: {points} point lights");
        }
    }

    #[test]
    fn default_scene_has_tiny_and_huge_lights() {
        let s = embedded("default").unwrap();
        let radii: Vec<f32> = s
            .lights
            .iter()
            .filter(|l| l.is_local())
            .map(|l| l.radius)
            .collect();
        let min = radii.iter().cloned().fold(f32::INFINITY, f32::min);
        let max = radii.iter().cloned().fold(0.0, f32::max);
        assert!(min < 0.5 && max > 6.0, "radii {min}..{max}");
    }

    #[test]
    fn variants_put_the_camera_where_they_say() {
        let s = embedded("inside").unwrap();
        let eye = s.camera.eye;
        assert!(s
            .lights
            .iter()
            .any(|l| l.is_local() && (l.position - eye).length() < l.radius));

        let s = embedded("near-far").unwrap();
        let c = s.camera;
        let fwd = (c.target - c.eye).normalize();
        let crosses = |plane: f32| {
            s.lights.iter().any(|l| {
                let d = (l.position - c.eye).dot(fwd);
                l.is_local()
                    && (d - plane).abs() < l.radius
                    && (l.position - c.eye).length() > l.radius
            })
        };
        assert!(crosses(c.near), "no light crosses the near plane");
        assert!(crosses(c.far), "no light crosses the far plane");
    }

    #[test]
    fn brdf_scenes_use_what_their_names_say() {
        for (name, count) in [
            ("default", 2),
            ("brdfs-1", 1),
            ("brdfs-3", 3),
            ("brdfs-6", 6),
        ] {
            assert_eq!(
                embedded(name).unwrap().brdfs_in_use().len(),
                count,
                "{name}"
            );
        }
    }

    #[test]
    fn unknown_scene_is_a_clear_error() {
        let err = embedded("kitchen").unwrap_err();
        assert!(err.to_string().contains("unknown scene `kitchen`"));
        assert!(err.to_string().contains("default"));
    }
}
