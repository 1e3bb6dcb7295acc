//! The embedded alpha scenes: the default room with translucent objects and particle systems next
//! to point lights of their own, one scene per layout of the talk.

use crate::{AlphaObject, Light, Material, Particle, ParticleLayout, ParticleSystem, Scene, Shape};
use glam::{Mat4, Vec3};
use histencil_brdf::Brdf;

/// Deterministic points in `[0, 1)` (the R2 low-discrepancy sequence in 3D): spreads particles
/// evenly without a random-number crate, the same on every machine.
fn r3(i: usize) -> Vec3 {
    const G: f64 = 1.220_744_084_605_759_5; // the plastic number's 3D generalisation
    let a = [1.0 / G, 1.0 / (G * G), 1.0 / (G * G * G)];
    let f = |k: usize| ((0.5 + a[k] * (i as f64 + 1.0)) % 1.0) as f32;
    Vec3::new(f(0), f(1), f(2))
}

/// A point inside the unit ball from a point of the unit cube (uniform in volume).
fn in_ball(u: Vec3) -> Vec3 {
    let theta = u.x * std::f32::consts::TAU;
    let z = u.y * 2.0 - 1.0;
    let r = u.z.cbrt();
    let s = (1.0 - z * z).sqrt();
    Vec3::new(s * theta.cos(), z, s * theta.sin()) * r
}

fn system(
    name: &str,
    layout: ParticleLayout,
    particles: Vec<Particle>,
    m: Material,
) -> ParticleSystem {
    ParticleSystem {
        name: name.to_owned(),
        layout,
        particles,
        material: m,
        opacity: 0.5,
    }
}

/// A glass sphere of radius `r` at `centre`.
pub fn glass_sphere(centre: Vec3, r: f32) -> AlphaObject {
    AlphaObject {
        name: "glass-sphere".into(),
        shape: Shape::Sphere,
        transform: Mat4::from_translation(centre) * Mat4::from_scale(Vec3::splat(r)),
        material: Material::new(
            Brdf::BlinnPhong { exponent: 32.0 },
            Vec3::new(0.75, 0.88, 1.0),
        ),
        opacity: 0.4,
    }
}

/// A column of smoke puffs rising from `base`.
fn smoke_column(base: Vec3, puffs: usize) -> ParticleSystem {
    let particles = (0..puffs)
        .map(|i| {
            let u = r3(i);
            let h = 3.0 * i as f32 / puffs as f32;
            let spread = 0.15 + 0.12 * h;
            Particle {
                position: base + Vec3::new((u.x - 0.5) * spread, h, (u.z - 0.5) * spread),
                size: 0.3 + 0.1 * h,
            }
        })
        .collect();
    system(
        "smoke-column",
        ParticleLayout::Auto,
        particles,
        Material::lambert(Vec3::splat(0.8)),
    )
}

/// `count` dust motes in the box `lo..hi`.
fn dust_cloud(lo: Vec3, hi: Vec3, count: usize) -> ParticleSystem {
    let particles = (0..count)
        .map(|i| Particle {
            position: lo + (hi - lo) * r3(i),
            size: 0.03,
        })
        .collect();
    let mut s = system(
        "dust-cloud",
        ParticleLayout::Dust,
        particles,
        Material::lambert(Vec3::new(1.0, 0.95, 0.85)),
    );
    s.opacity = 0.9;
    s
}

/// A helical trail of `points` control points around `axis_base`, rising 2.5 units.
fn ribbon_trail(axis_base: Vec3, points: usize) -> ParticleSystem {
    let particles = (0..points)
        .map(|i| {
            let t = i as f32 / (points - 1) as f32;
            let a = t * 3.0 * std::f32::consts::TAU;
            Particle {
                position: axis_base + Vec3::new(1.2 * a.cos(), 0.3 + 2.5 * t, 1.2 * a.sin()),
                size: 0.06 + 0.06 * t,
            }
        })
        .collect();
    let mut s = system(
        "ribbon-trail",
        ParticleLayout::Ribbon,
        particles,
        Material::lambert(Vec3::new(0.9, 0.6, 1.0)),
    );
    s.opacity = 0.8;
    s
}

/// A thick ball of smoke of radius `r` at `centre`, lit as `layout`.
pub fn smoke_volume(centre: Vec3, r: f32, count: usize, layout: ParticleLayout) -> ParticleSystem {
    let particles = (0..count)
        .map(|i| Particle {
            position: centre + in_ball(r3(i)) * r,
            size: 0.25 * r,
        })
        .collect();
    let mut s = system(
        "smoke-volume",
        layout,
        particles,
        Material::lambert(Vec3::splat(0.85)),
    );
    s.opacity = 0.25;
    s
}

/// Adds scene `name`'s alpha entities and their lights to the room; false when `name` is not an
/// alpha scene.
pub(crate) fn add_alpha_entities(name: &str, scene: &mut Scene) -> bool {
    let warm = Vec3::new(2.4, 1.5, 0.8);
    let cool = Vec3::new(0.6, 1.1, 2.4);
    match name {
        "alpha" => {
            scene
                .alpha_objects
                .push(glass_sphere(Vec3::new(-1.6, 1.6, 3.0), 0.9));
            scene
                .particle_systems
                .push(smoke_column(Vec3::new(2.0, 0.2, 3.0), 48));
            scene
                .lights
                .push(Light::point(Vec3::new(-0.4, 2.2, 3.8), 2.5, warm));
            scene
                .lights
                .push(Light::point(Vec3::new(2.9, 1.2, 3.5), 2.5, cool));
        }
        "dust" => {
            let (lo, hi) = (Vec3::new(-3.0, 0.3, 0.5), Vec3::new(3.0, 3.5, 4.5));
            scene.particle_systems.push(dust_cloud(lo, hi, 600));
            scene
                .lights
                .push(Light::point(Vec3::new(-1.5, 1.8, 2.5), 2.5, warm));
            scene
                .lights
                .push(Light::point(Vec3::new(1.5, 2.2, 3.0), 2.5, cool));
        }
        "ribbon" => {
            scene
                .particle_systems
                .push(ribbon_trail(Vec3::new(0.0, 0.0, 3.0), 64));
            scene
                .lights
                .push(Light::point(Vec3::new(0.0, 1.5, 3.0), 2.5, warm));
        }
        "volume" => {
            let centre = Vec3::new(0.0, 1.8, 3.0);
            scene
                .particle_systems
                .push(smoke_volume(centre, 1.6, 400, ParticleLayout::Auto));
            scene
                .lights
                .push(Light::point(centre + Vec3::new(0.3, 0.0, 0.5), 2.2, warm));
        }
        "alpha-many" => {
            for i in 0..8 {
                let base = Vec3::new(-5.25 + 1.5 * i as f32, 1.8, 2.0 + (i % 2) as f32);
                let mut s = smoke_volume(base, 0.7, 256, ParticleLayout::Auto);
                s.name = format!("smoke-{i}");
                scene.particle_systems.push(s);
                let color = if i % 2 == 0 { warm } else { cool };
                scene
                    .lights
                    .push(Light::point(base + Vec3::new(0.4, 0.6, 0.3), 1.8, color));
            }
        }
        _ => return false,
    }
    true
}
