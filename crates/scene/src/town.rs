//! `town`: a generated scene at the scale deferred renderers are judged at (a Sponza's worth):
//! about 250k triangles, 25 textured materials (base colour, normal and metallic-roughness
//! maps, three of them emissive) in four BRDFs, and 256 point and spot lights. Everything is made here, from fixed
//! seeds, so the scene is the same on every machine and needs no asset download.

use crate::split_mix::SplitMix;
use crate::tangents::{self, Space};
use crate::{
    uv_transform, Camera, Light, LightKind, Material, MaterialMaps, Mesh, Object, Scene, Shape,
    TextureImage, TextureRef, Vertex,
};
use glam::{Mat4, Quat, Vec3};
use histencil_brdf::Brdf;
use std::f32::consts::{PI, TAU};

/// Materials: the ground's and 24 for the objects.
pub const TOWN_MATERIALS: usize = 25;
/// Point lights plus spot lights.
pub const TOWN_LIGHTS: usize = 256;
const SPOT_LIGHTS: usize = 32;
/// Objects on the ground, two per object material.
const OBJECTS: usize = 48;
/// Texels per side of every generated map.
const TEXTURE_SIDE: u32 = 128;
/// Half the ground's side, in metres.
const HALF_GROUND: f32 = 20.0;

/// The town scene (see the module doc).
pub fn town(name: &str, description: String) -> Scene {
    let mut images = Vec::new();
    let materials: Vec<Material> = (0..TOWN_MATERIALS)
        .map(|m| textured_material(m, &mut images))
        .collect();
    let ground_index = 0;
    // Scenes keep meshes inside [-1, 1]^3 and their size in the transform, as the importer does.
    let mut extents = Vec::new();
    let mut meshes = Vec::new();
    for mut mesh in [ground_grid(160), rock(64, 32), torus(64, 32, 0.35)] {
        with_tangents(&mut mesh);
        extents.push(fit(&mut mesh));
        meshes.push(mesh);
    }
    let mut objects = vec![Object {
        name: "ground".into(),
        shape: Shape::Mesh(ground_index),
        transform: Mat4::from_scale(Vec3::splat(HALF_GROUND * extents[0])),
        material: ground_material(materials[0]),
    }];
    let mut rng = SplitMix(0x746f_776e);
    for i in 0..OBJECTS {
        let (gx, gz) = ((i % 8) as f32, (i / 8) as f32);
        let x = -15.75 + 4.5 * gx + rng.range(-0.8, 0.8);
        let z = -13.0 + 5.0 * gz + rng.range(-0.8, 0.8);
        let size = rng.range(0.9, 1.6);
        let (mesh, lift, tilt) = if i % 2 == 0 {
            (1, size, Quat::from_rotation_y(rng.range(0.0, TAU)))
        } else {
            let spin = Quat::from_rotation_y(rng.range(0.0, TAU));
            (
                2,
                0.35 * size,
                spin * Quat::from_rotation_x(rng.range(-0.3, 0.3)),
            )
        };
        objects.push(Object {
            name: format!("{}-{i}", if mesh == 1 { "rock" } else { "ring" }),
            shape: Shape::Mesh(mesh),
            transform: Mat4::from_scale_rotation_translation(
                Vec3::splat(size * extents[mesh as usize]),
                tilt,
                Vec3::new(x, lift, z),
            ),
            // Rocks and rings each take every object material once.
            material: materials[1 + (i / 2 + 12 * (i % 2)) % (TOWN_MATERIALS - 1)],
        });
    }
    Scene {
        name: name.to_owned(),
        description,
        camera: Camera {
            eye: Vec3::new(0.0, 17.0, 23.0),
            target: Vec3::new(0.0, 0.0, -5.0),
            up: Vec3::Y,
            fov_y_radians: 0.9,
            near: 0.5,
            far: 80.0,
        },
        objects,
        lights: lights(&mut rng),
        alpha_objects: Vec::new(),
        particle_systems: Vec::new(),
        meshes,
        images,
    }
}

/// The ground repeats its maps eight times a side.
fn ground_material(mut m: Material) -> Material {
    let repeat = uv_transform([0.0; 2], 0.0, [8.0, 8.0]);
    for map in [
        &mut m.maps.base_color,
        &mut m.maps.normal,
        &mut m.maps.metallic_roughness,
    ]
    .into_iter()
    .flatten()
    {
        map.transform = repeat;
    }
    m
}

/// Material `m`: its BRDF by `m % 4` (Lambert, Blinn-Phong, Oren-Nayar, GGX), a hue, and three
/// generated maps appended to `images`.
fn textured_material(m: usize, images: &mut Vec<TextureImage>) -> Material {
    let brdf = match m % 4 {
        0 => Brdf::Lambert { rho: 1.0 },
        1 => Brdf::BlinnPhong {
            exponent: [24.0, 64.0, 160.0][m % 3],
        },
        2 => Brdf::OrenNayarFull {
            rho: 0.9,
            sigma: [0.3, 0.6][m % 2],
        },
        _ => Brdf::Ggx {
            alpha: [0.2, 0.45][m % 2],
            f0: [0.04, 0.5][(m / 4) % 2],
            f90: 1.0,
        },
    };
    let h = m as f32 / TOWN_MATERIALS as f32;
    let tint = Vec3::new(
        0.55 + 0.4 * (TAU * h).cos(),
        0.55 + 0.4 * (TAU * (h + 0.33)).cos(),
        0.55 + 0.4 * (TAU * (h + 0.67)).cos(),
    )
    .clamp(Vec3::splat(0.1), Vec3::ONE);
    let height = |x: u32, y: u32| pattern(m % 5, x, y);
    let glows = m % 8 == 5;
    let first = images.len() as u32;
    images.push(map(m, "base", |x, y| {
        let v = 0.45 + 0.55 * height(x, y);
        let grain = 0.9 + 0.1 * hash(m as u32, x, y);
        [v * grain, v * grain, v * grain, 1.0]
    }));
    images.push(map(m, "normal", |x, y| {
        let s = TEXTURE_SIDE;
        let dx = height((x + 1) % s, y) - height((x + s - 1) % s, y);
        let dy = height(x, (y + 1) % s) - height(x, (y + s - 1) % s);
        // Height rises along +u and +v (image rows run down +v): the normal leans back.
        let n = Vec3::new(-2.0 * dx, -2.0 * dy, 1.0).normalize();
        [0.5 + 0.5 * n.x, 0.5 + 0.5 * n.y, 0.5 + 0.5 * n.z, 1.0]
    }));
    images.push(map(m, "metallic-roughness", |x, y| {
        let raised = height(x, y);
        let metal = if m % 8 == 3 && raised > 0.5 { 1.0 } else { 0.0 };
        [0.0, 0.5 + 0.5 * (1.0 - raised), metal, 1.0]
    }));
    Material {
        maps: MaterialMaps {
            base_color: Some(TextureRef::new(first)),
            normal: Some(TextureRef::new(first + 1)),
            normal_scale: 1.0,
            metallic_roughness: Some(TextureRef::new(first + 2)),
            // Every eighth material glows through its base colour pattern.
            emissive: glows.then(|| TextureRef::new(first)),
            alpha_cutoff: None,
        },
        emissive: if glows { tint * 0.8 } else { Vec3::ZERO },
        ..Material::new(brdf, tint)
    }
}

/// A map of material `m` from `texel(x, y)`'s RGBA in `[0, 1]`.
fn map(m: usize, what: &str, texel: impl Fn(u32, u32) -> [f32; 4]) -> TextureImage {
    let s = TEXTURE_SIDE;
    let rgba8 = (0..s * s)
        .flat_map(|i| texel(i % s, i / s).map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8))
        .collect();
    TextureImage {
        name: format!("town-{m}-{what}"),
        width: s,
        height: s,
        rgba8,
    }
}

/// A height in `[0, 1]` that tiles over the map: bricks, tiles, planks, cobbles or rings.
fn pattern(kind: usize, x: u32, y: u32) -> f32 {
    let s = TEXTURE_SIDE as f32;
    let (u, v) = (x as f32 / s, y as f32 / s);
    let edge = |t: f32, width: f32| {
        let d = (t - t.round()).abs();
        (d / width).min(1.0)
    };
    match kind {
        0 => {
            // Bricks: 8 rows, every other one offset by half a brick.
            let row = (v * 8.0).floor();
            let shift = if row as i32 % 2 == 0 { 0.0 } else { 0.5 };
            edge(v * 8.0, 0.12).min(edge(u * 4.0 + shift, 0.06))
        }
        1 => edge(u * 4.0, 0.08).min(edge(v * 4.0, 0.08)),
        2 => {
            let grain = 0.5 + 0.5 * (TAU * (v * 3.0 + 0.15 * (TAU * u * 2.0).sin())).sin();
            edge(u * 6.0, 0.1) * (0.6 + 0.4 * grain)
        }
        3 => {
            let (cu, cv) = ((u * 5.0).fract() - 0.5, (v * 5.0).fract() - 0.5);
            (1.0 - 2.2 * (cu * cu + cv * cv).sqrt())
                .clamp(0.0, 1.0)
                .sqrt()
        }
        _ => {
            let r = ((u - 0.5).powi(2) + (v - 0.5).powi(2)).sqrt();
            0.5 + 0.5 * (TAU * 6.0 * r).cos() * (PI * r).cos().max(0.0)
        }
    }
}

/// A deterministic value in `[0, 1)` per texel and material.
fn hash(m: u32, x: u32, y: u32) -> f32 {
    let mut rng = SplitMix(u64::from(m) << 40 | u64::from(x) << 20 | u64::from(y));
    rng.next_f32()
}

/// Scales `mesh` into `[-1, 1]^3`; the factor that scales it back.
fn fit(mesh: &mut Mesh) -> f32 {
    let extent = mesh
        .vertices
        .iter()
        .flat_map(|v| v.position)
        .fold(0.0f32, |m, c| m.max(c.abs()));
    for v in &mut mesh.vertices {
        v.position = v.position.map(|c| c / extent);
    }
    extent
}

/// The ground: a `cells` x `cells` grid over `[-1, 1]^2` at y = 0, facing +y, uv over
/// `[0, 1]^2`.
fn ground_grid(cells: u32) -> Mesh {
    let mut m = Mesh::default();
    let row = cells + 1;
    for j in 0..=cells {
        for i in 0..=cells {
            let (u, v) = (i as f32 / cells as f32, j as f32 / cells as f32);
            let p = [2.0 * u - 1.0, 0.0, 2.0 * v - 1.0];
            m.vertices.push(Vertex::new(p, [0.0, 1.0, 0.0], [u, v]));
        }
    }
    for j in 0..cells {
        for i in 0..cells {
            let (a, b) = (j * row + i, (j + 1) * row + i);
            // Counter-clockwise seen from +y.
            m.indices.extend_from_slice(&[a, b, a + 1, a + 1, b, b + 1]);
        }
    }
    m
}

/// A lumpy sphere of radius about 1: a UV sphere pushed in and out by a few low-frequency
/// waves, its normals from the displaced surface.
fn rock(segments: u32, rings: u32) -> Mesh {
    let radius = |theta: f32, phi: f32| {
        1.0 + 0.08 * (3.0 * phi).sin() * (2.0 * theta).sin() + 0.05 * (5.0 * theta + phi).cos()
    };
    parametric(segments, rings, |s, t| {
        let (theta, phi) = (PI * t, TAU * s);
        let r = radius(theta, phi);
        Vec3::new(
            r * theta.sin() * phi.cos(),
            r * theta.cos(),
            -r * theta.sin() * phi.sin(),
        )
    })
}

/// A torus in the xz plane, ring radius 1 and tube radius `tube`.
fn torus(segments: u32, rings: u32, tube: f32) -> Mesh {
    parametric(segments, rings, |s, t| {
        // The tube angle runs so that dv x du points out of the tube.
        let (a, b) = (TAU * s, -TAU * t);
        let r = 1.0 + tube * b.cos();
        Vec3::new(r * a.cos(), tube * b.sin(), -r * a.sin())
    })
}

/// A closed surface from `point(s, t)` over `[0, 1]^2`, `segments` x `rings` quads, uv `(2s, t)`
/// (the maps repeat twice around). Normals are `dv x du` from central differences (the
/// position's own direction where that vanishes, at a pole); a parametrisation for which it
/// points outward winds its triangles counter-clockwise seen from outside.
fn parametric(segments: u32, rings: u32, point: impl Fn(f32, f32) -> Vec3) -> Mesh {
    let mut m = Mesh::default();
    let e = 1e-3;
    for r in 0..=rings {
        for s in 0..=segments {
            let (u, v) = (s as f32 / segments as f32, r as f32 / rings as f32);
            let p = point(u, v);
            let du = point(u + e, v) - point(u - e, v);
            let dv = point(u, v + e) - point(u, v - e);
            let mut n = dv.cross(du).normalize_or_zero();
            if n == Vec3::ZERO {
                n = p.normalize_or(Vec3::Y);
            }
            m.vertices
                .push(Vertex::new(p.into(), n.into(), [2.0 * u, v]));
        }
    }
    let row = segments + 1;
    for r in 0..rings {
        for s in 0..segments {
            let (a, b) = (r * row + s, (r + 1) * row + s);
            m.indices.extend_from_slice(&[a, b, a + 1, a + 1, b, b + 1]);
        }
    }
    m
}

/// MikkTSpace tangents, as the importer makes them for a normal-mapped mesh without its own.
fn with_tangents(mesh: &mut Mesh) {
    let same3 = |p: [f32; 3]| p;
    let same4 = |t: [f32; 4]| t;
    let space = Space {
        position: &same3,
        normal: &same3,
        tangent: &same4,
    };
    tangents::generate(mesh, 0, &space).expect("the generated meshes have regular uvs");
}

/// 224 point lights of short to middling range in a jittered grid just above the ground and the
/// objects, and 32 spot lights looking down from above; colours from warm to cool.
fn lights(rng: &mut SplitMix) -> Vec<Light> {
    let points = TOWN_LIGHTS - SPOT_LIGHTS;
    let mut lights = Vec::with_capacity(TOWN_LIGHTS);
    let side = 16;
    for i in 0..points {
        let (gx, gz) = ((i % side) as f32, (i / side) as f32);
        let rows = points.div_ceil(side) as f32;
        let x = -HALF_GROUND + (gx + rng.range(0.1, 0.9)) * (2.0 * HALF_GROUND / side as f32);
        let z = -HALF_GROUND + (gz + rng.range(0.1, 0.9)) * (2.0 * HALF_GROUND / rows);
        let y = rng.range(0.3, 3.0);
        let radius = rng.range(1.0, 5.0);
        lights.push(Light::point(
            Vec3::new(x, y, z),
            radius,
            hue(rng.next_f32()) * rng.range(2.0, 6.0),
        ));
    }
    for i in 0..SPOT_LIGHTS {
        let (gx, gz) = ((i % 8) as f32, (i / 8) as f32);
        let position = Vec3::new(-17.5 + 5.0 * gx, rng.range(5.0, 7.0), -15.0 + 8.0 * gz);
        let aim = Vec3::new(rng.range(-0.4, 0.4), -1.0, rng.range(-0.4, 0.4)).normalize();
        lights.push(Light {
            kind: LightKind::Spot {
                direction: aim,
                inner_angle: 0.35,
                outer_angle: 0.55,
            },
            position,
            radius: 10.0,
            color: hue(rng.next_f32()) * 6.0,
            falloff: crate::Falloff::SquaredWindow,
        });
    }
    lights
}

/// A light colour from warm (0) to cool (1).
fn hue(t: f32) -> Vec3 {
    Vec3::new(1.0, 0.8, 0.6).lerp(Vec3::new(0.6, 0.8, 1.0), t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn town_has_the_scale_it_promises() {
        let scene = town("town", String::new());
        scene.validate().unwrap();
        let triangles: usize = scene
            .objects
            .iter()
            .map(|o| match o.shape {
                Shape::Mesh(i) => scene.meshes[i as usize].indices.len() / 3,
                _ => unreachable!("every town object is a mesh"),
            })
            .sum();
        assert!((240_000..270_000).contains(&triangles), "{triangles}");
        assert_eq!(scene.lights.len(), TOWN_LIGHTS);
        assert_eq!(scene.images.len(), 3 * TOWN_MATERIALS);
        assert_eq!(scene.brdfs_in_use().len(), 4);
        let distinct: std::collections::HashSet<String> = scene
            .objects
            .iter()
            .map(|o| format!("{:?}", o.material))
            .collect();
        assert_eq!(distinct.len(), TOWN_MATERIALS);
    }
}
