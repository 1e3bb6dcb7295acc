//! Scene variants that the comparisons need: the same scene with 1, 2 or 3 BRDFs, and a wall lit
//! by lights of one screen coverage.

use glam::{Mat4, Vec3};
use histencil_brdf::Brdf;
use histencil_scene::{Camera, Light, Material, Object, Scene, Shape};

/// Models added after a scene's own when it has fewer distinct BRDFs than asked for.
fn extra_models() -> [Brdf; 3] {
    [
        Brdf::Lambert { rho: 1.0 },
        Brdf::BlinnPhong { exponent: 32.0 },
        Brdf::OrenNayarFull {
            rho: 0.9,
            sigma: 0.3,
        },
    ]
}

/// The first `count` distinct BRDFs of `scene` (the first material of each, in object order),
/// padded with Lambert, Blinn-Phong 32 and Oren-Nayar: the models [`with_brdf_count`] folds
/// the scene's objects onto.
pub fn brdf_palette(scene: &Scene, count: usize) -> Vec<Brdf> {
    let mut palette: Vec<Brdf> = Vec::new();
    for brdf in scene
        .objects
        .iter()
        .map(|o| o.material.brdf)
        .chain(extra_models())
    {
        if palette.len() < count && palette.iter().all(|b| b.id() != brdf.id()) {
            palette.push(brdf);
        }
    }
    palette
}

/// Refuses a palette of `count` models that `set` cannot shade: fewer engine BRDFs than the
/// widest column, and none of the padding built-ins kept (`builtins = []`, say). Said before
/// anything is measured, naming what the set offers.
pub fn check_palette(
    scene: &Scene,
    count: usize,
    set: &histencil_brdf::BrdfSet,
) -> Result<(), crate::LabError> {
    let palette = brdf_palette(scene, count);
    match palette.iter().find(|b| !set.contains(b.id())) {
        None => Ok(()),
        Some(b) => {
            let names: Vec<&str> = set.ids().iter().map(|id| id.name()).collect();
            Err(crate::LabError::Settings(format!(
                "the {count}-BRDF column needs {count} BRDFs, and its padding `{}` is not in the \
                 BRDF set ({}): declare more BRDFs, or keep lambert, blinn_phong and \
                 oren_nayar_full among the built-ins",
                b.name(),
                names.join(", ")
            )))
        }
    }
}

/// `scene` with its objects' BRDFs folded onto `count` models (`brdf_palette`): object `i`
/// takes model `i % count`. Tints are kept. Interleaving spreads every model over the scene,
/// so a huge light touches all `count`, as in the talk's figures.
pub fn with_brdf_count(scene: &Scene, count: usize) -> Scene {
    let palette = brdf_palette(scene, count);
    let mut out = scene.clone();
    if palette.is_empty() {
        return out;
    }
    for (i, object) in out.objects.iter_mut().enumerate() {
        object.material.brdf = palette[i % palette.len()];
    }
    out.name = format!("{}-{}brdf", scene.name, palette.len());
    out
}

/// `scene` with every object in `brdf` (tints kept): what each of a folded scene's models costs
/// alone, on the same pixels and lights.
pub fn with_one_brdf(scene: &Scene, brdf: Brdf) -> Scene {
    let mut out = scene.clone();
    for object in &mut out.objects {
        object.material.brdf = brdf;
    }
    out.name = format!("{}-only-{}", scene.name, brdf.id().name());
    out
}

/// The wall's distance from the eye and the vertical field of view it is seen with. A light's
/// coverage is the disc its range sphere cuts from the wall over the visible wall's area. The
/// adaptive technique's own estimate, the projected range sphere, is larger: the sphere's
/// radius is about 1.12x its disc's, so it sees at least 1.25x the coverage named.
const WALL_DISTANCE: f32 = 10.0;
const FOV_Y_DEGREES: f32 = 60.0;

/// A wall of vertical stripes in Lambert, Blinn-Phong and Oren-Nayar, filling the view, lit by
/// point lights in front of it whose range sphere each cuts a disc of `coverage` (0..=1) of the
/// screen from the wall. There are `2 / coverage` of them (at most 400), so the lit area stays
/// about two screens whatever the size, and only the per-light costs change. Lights at full
/// coverage reach every corner.
///
/// Each light stands half its disc's radius off the wall (at full coverage, half the visible
/// wall's height): a light centred on the wall's plane meets every point of it at a
/// grazing angle, so it would add exactly zero and the sweep would time an unlit wall.
pub fn light_size_scene(coverage: f64, aspect: f32) -> Scene {
    let coverage = coverage.clamp(1e-4, 1.0) as f32;
    let tan = (FOV_Y_DEGREES.to_radians() * 0.5).tan();
    let (half_h, half_w) = (WALL_DISTANCE * tan, WALL_DISTANCE * tan * aspect);
    let stripes = 36;
    let models = extra_models();
    let objects = (0..stripes)
        .map(|i| {
            let width = 2.0 * half_w * 1.1 / stripes as f32;
            let x = -half_w * 1.1 + width * (i as f32 + 0.5);
            Object {
                name: format!("stripe-{i}"),
                shape: Shape::Box,
                transform: Mat4::from_translation(Vec3::new(x, 0.0, -0.5))
                    * Mat4::from_scale(Vec3::new(width * 0.5, half_h * 1.1, 0.5)),
                material: Material::new(models[i % 3], Vec3::new(0.8, 0.75, 0.7)),
            }
        })
        .collect();
    // Disc radius whose area is `coverage` of the screen (2 half_w x 2 half_h at the wall).
    let disc = (4.0 * half_w * half_h * coverage / std::f32::consts::PI).sqrt();
    let (height, radius) = if coverage >= 1.0 {
        // Far enough and wide enough that the corners keep a visible share of the light.
        let height = half_h;
        let corner = half_w * half_w + half_h * half_h + height * height;
        (height, corner.sqrt() * 1.5)
    } else {
        let height = 0.5 * disc;
        (height, (disc * disc + height * height).sqrt())
    };
    let count = ((2.0 / coverage).round() as usize).clamp(1, 400);
    let lights = (0..count)
        .map(|i| {
            // A deterministic low-discrepancy spread over the visible wall.
            let u = fract(0.5 + i as f32 * 0.618_034);
            let v = fract(0.5 + i as f32 * 0.754_878);
            let at = Vec3::new((2.0 * u - 1.0) * half_w, (2.0 * v - 1.0) * half_h, 0.0);
            let foot = if coverage >= 1.0 { Vec3::ZERO } else { at };
            // About 0.6 of unit radiance at the foot of every light, whatever its size.
            let intensity = Vec3::splat(0.6 * height * height);
            Light::point(foot + Vec3::Z * height, radius, intensity)
        })
        .collect();
    Scene {
        name: format!("light-size-{coverage}"),
        description: format!("a striped wall under {count} lights covering {coverage} each"),
        camera: Camera {
            eye: Vec3::new(0.0, 0.0, WALL_DISTANCE),
            target: Vec3::ZERO,
            up: Vec3::Y,
            fov_y_radians: FOV_Y_DEGREES.to_radians(),
            near: 0.1,
            far: 2.0 * WALL_DISTANCE + radius,
        },
        objects,
        lights,
        alpha_objects: vec![],
        particle_systems: vec![],
        meshes: vec![],
        images: Vec::new(),
    }
}

fn fract(x: f32) -> f32 {
    x - x.floor()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn brdf_counts_fold_and_pad() {
        let scene = histencil_scene::embedded("huge-lights").unwrap();
        for count in 1..=3 {
            let v = with_brdf_count(&scene, count);
            assert_eq!(v.brdfs_in_use().len(), count);
            assert_eq!(v.objects.len(), scene.objects.len());
        }
        let one = histencil_scene::embedded("brdfs-1").unwrap();
        assert_eq!(with_brdf_count(&one, 3).brdfs_in_use().len(), 3);
    }

    #[test]
    fn light_size_scenes_are_valid_and_every_light_touches_three_brdfs() {
        for coverage in [0.001, 0.01, 0.1, 1.0] {
            let scene = light_size_scene(coverage, 16.0 / 9.0);
            scene.validate().unwrap();
            assert!(scene.lights.len() <= 400);
            if coverage >= 0.01 {
                // Lights at the wall's edge may miss one stripe model.
                let touching = |n| {
                    let lit = |l| scene.brdfs_lit_by(l).len() >= n;
                    scene.lights.iter().filter(|l| lit(l)).count() as f64
                };
                let all = scene.lights.len() as f64;
                assert_eq!(touching(2), all, "coverage {coverage}");
                assert!(touching(3) >= 0.8 * all, "coverage {coverage}");
            }
        }
    }

    /// Every light stands in front of the wall (one in its plane meets it edge-on and adds
    /// nothing), and its range sphere cuts a disc of `coverage` of the visible wall from it.
    #[test]
    fn light_size_lights_face_the_wall_and_cut_discs_of_their_coverage() {
        let aspect = 16.0 / 9.0;
        let tan = (FOV_Y_DEGREES.to_radians() * 0.5).tan();
        let wall_area = 4.0 * WALL_DISTANCE * tan * WALL_DISTANCE * tan * aspect;
        for coverage in [0.001, 0.01, 0.3] {
            for light in &light_size_scene(coverage, aspect).lights {
                let height = light.position.z;
                assert!(height > 0.0, "coverage {coverage}: light at {height}");
                let disc = light.radius * light.radius - height * height;
                let cut = std::f32::consts::PI * disc / wall_area;
                assert!(
                    (cut / coverage as f32 - 1.0).abs() < 1e-3,
                    "{cut} for {coverage}"
                );
            }
        }
        for light in &light_size_scene(1.0, aspect).lights {
            assert!(light.position.z > 0.0);
        }
    }
}
