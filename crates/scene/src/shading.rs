//! The light code of `crates/vk/shaders/include/light.glsl` on the CPU, in f32: what arrives at a point
//! from a light, and what a material reflects of it towards the eye. For estimates that must
//! agree with what the GPU draws (the alpha lightmaps' parameter choice), not for references:
//! BRDF accuracy is held by `histencil-brdf`'s f64 reference.

use crate::{Falloff, Light, LightKind, Material};
use glam::Vec3;
use histencil_brdf::SHIPPING_PANELS;

/// Windowed inverse square: exactly zero at `d >= range` (light.glsl's `range_falloff` with
/// [`Falloff::SquaredWindow`]).
pub fn range_falloff(d: f32, range: f32) -> f32 {
    Falloff::SquaredWindow.at(d, range)
}

fn smoothstep(edge0: f32, edge1: f32, x: f32) -> f32 {
    let t = ((x - edge0) / (edge1 - edge0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

impl Falloff {
    /// The scale at distance `d` within `range` (light.glsl's `range_falloff`; the table of
    /// [`Falloff`]): 0 at and past the range.
    pub fn at(self, d: f32, range: f32) -> f32 {
        let x = d / range;
        let x2 = x * x;
        let window = (1.0 - x2 * x2).clamp(0.0, 1.0);
        let windowed = match self {
            Falloff::SquaredWindow => window * window,
            Falloff::Gltf => window,
            Falloff::InverseSquare if d < range => 1.0,
            Falloff::InverseSquare => 0.0,
        };
        windowed / (d * d).max(1e-4)
    }

    /// A spot's scale at cosine `c` to its axis, between the cosines of its outer and inner
    /// half-angles (light.glsl's `spot_cone`).
    pub fn cone(self, cos_outer: f32, cos_inner: f32, c: f32) -> f32 {
        match self {
            Falloff::SquaredWindow => smoothstep(cos_outer, cos_inner, c),
            Falloff::Gltf | Falloff::InverseSquare => {
                let t = ((c - cos_outer) / (cos_inner - cos_outer).max(1e-3)).clamp(0.0, 1.0);
                t * t
            }
        }
    }

    /// The code the shaders read (`LIGHT_FALLOFF_*`, GpuLight's `direction.w`).
    pub fn code(self) -> u32 {
        self as u32
    }
}

impl Light {
    /// The radiance scale arriving at `p` and the unit direction towards the light; `None`
    /// where nothing arrives (light.glsl's `light_incident`).
    pub fn incident(&self, p: Vec3) -> Option<(Vec3, Vec3)> {
        let (direction, spot) = match self.kind {
            LightKind::Directional { direction } => {
                return Some((self.color, -direction.normalize()));
            }
            LightKind::Point => (Vec3::Z, None),
            LightKind::Spot {
                direction,
                inner_angle,
                outer_angle,
            } => (
                direction.normalize(),
                Some((outer_angle.cos(), inner_angle.cos())),
            ),
        };
        let to_light = self.position - p;
        let d = to_light.length();
        if d >= self.radius || d <= 0.0 {
            return None;
        }
        let l = to_light / d;
        let mut a = self.falloff.at(d, self.radius);
        if let Some((outer, inner)) = spot {
            a *= self.falloff.cone(outer, inner, (-l).dot(direction));
        }
        (a > 0.0).then_some((self.color * a, l))
    }
}

/// Outgoing radiance at `p` with unit normal `n`, seen from `eye`, summed over `lights`, by
/// `material` (light.glsl's `shade_light` for each light).
pub fn shade(lights: &[Light], material: &Material, p: Vec3, n: Vec3, eye: Vec3) -> Vec3 {
    let v = (eye - p).normalize_or(Vec3::Z);
    let t = Vec3::Y - n * n.y;
    let mut sum = Vec3::ZERO;
    for light in lights {
        if let Some((incident, l)) = light.incident(p) {
            let f = material.brdf.eval_tinted(
                material.tint.to_array(),
                [n.to_array(), t.to_array(), v.to_array(), l.to_array()],
                SHIPPING_PANELS,
            );
            sum += incident * Vec3::from(f);
        }
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;
    use histencil_brdf::Brdf;

    #[test]
    fn falloff_ends_at_the_range_and_spots_at_their_cone() {
        assert_eq!(range_falloff(2.0, 2.0), 0.0);
        assert!(range_falloff(1.0, 2.0) > 0.0);
        let point = Light::point(Vec3::ZERO, 2.0, Vec3::ONE);
        assert!(point.incident(Vec3::new(0.0, 0.0, 2.0)).is_none());
        let (c, l) = point.incident(Vec3::new(0.0, 0.0, 1.0)).unwrap();
        assert_eq!(l, Vec3::new(0.0, 0.0, -1.0));
        assert!((c.x - range_falloff(1.0, 2.0)).abs() < 1e-6);
        let spot = Light {
            kind: LightKind::Spot {
                direction: Vec3::NEG_Z,
                inner_angle: 0.2,
                outer_angle: 0.4,
            },
            ..point
        };
        assert!(spot.incident(Vec3::new(0.0, 0.0, -1.0)).is_some());
        assert!(spot.incident(Vec3::new(1.0, 0.0, -1.0)).is_none());
    }

    /// The conventions' equations (the table of `Falloff`), at a third and two thirds of the
    /// range and past it, and the cones between their angles.
    #[test]
    fn each_falloff_is_its_equation() {
        let (r, d) = (6.0f32, [2.0f32, 4.0, 6.0, 7.0]);
        for d in d {
            let w = (1.0 - (d / r).powi(4)).clamp(0.0, 1.0);
            let inside = if d < r { 1.0 } else { 0.0 };
            let expected = [
                (Falloff::SquaredWindow, w * w / (d * d)),
                (Falloff::Gltf, w / (d * d)),
                (Falloff::InverseSquare, inside / (d * d)),
            ];
            for (falloff, e) in expected {
                let a = falloff.at(d, r);
                assert!(
                    (a - e).abs() <= 1e-6 * e.max(1e-3),
                    "{falloff:?} at {d}: {a} {e}"
                );
            }
        }
        let (outer, inner) = (0.7f32.cos(), 0.3f32.cos());
        let c = 0.5f32.cos();
        let t = (c - outer) / (inner - outer);
        assert!((Falloff::Gltf.cone(outer, inner, c) - t * t).abs() < 1e-6);
        assert!(
            (Falloff::SquaredWindow.cone(outer, inner, c) - t * t * (3.0 - 2.0 * t)).abs() < 1e-6
        );
        for falloff in [
            Falloff::SquaredWindow,
            Falloff::Gltf,
            Falloff::InverseSquare,
        ] {
            assert_eq!(falloff.cone(outer, inner, 0.9f32.cos()), 0.0);
            assert_eq!(falloff.cone(outer, inner, 1.0), 1.0);
        }
    }

    #[test]
    fn lambert_facing_a_light_reflects_rho_over_pi_times_what_arrives() {
        let light = Light::point(Vec3::new(0.0, 0.0, 1.0), 10.0, Vec3::ONE);
        let material = Material::new(Brdf::Lambert { rho: 1.0 }, Vec3::ONE);
        let out = shade(
            &[light],
            &material,
            Vec3::ZERO,
            Vec3::Z,
            Vec3::new(0.0, 0.0, 5.0),
        );
        let expected = range_falloff(1.0, 10.0) / std::f32::consts::PI;
        assert!(
            (out.x - expected).abs() < 1e-5 * expected,
            "{out} {expected}"
        );
    }
}
