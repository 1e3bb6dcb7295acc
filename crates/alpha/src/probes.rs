//! Where a particle system's probes are: the camera-facing frame fitted around the system (the
//! talk's quad, and the stack of slices through its depth), and the order in which entities are
//! blended.

use crate::layout::{bounding_sphere, EntityKey, Viewer};
use glam::Vec3;
use histencil_scene::{Camera, Particle, Scene};

/// A camera-facing frame around a particle system. Probe `(u, v)` of slice `k` of `n` sits at
/// `centre + right * radius * (2u - 1) - up * radius * (2v - 1) + forward * depth_k`, with
/// `depth_k` from `-half_depth` (nearest the camera) to `+half_depth`; one slice (the billboard)
/// sits at depth 0. The quad is parallel to the image plane, so a particle's texel is its
/// position projected orthogonally onto it: the nearest probe on the quad.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeFrame {
    /// World centre of the quad (of the middle slice).
    pub centre: Vec3,
    /// Half the quad's side: every sprite lies within it.
    pub radius: f32,
    /// Half the system's extent along the view: where the first and last slices sit.
    pub half_depth: f32,
    /// Unit camera axis along the quad's rows (+u).
    pub right: Vec3,
    /// Unit camera axis up the screen (towards -v).
    pub up: Vec3,
    /// Unit view direction (away from the camera).
    pub forward: Vec3,
}

/// The camera's unit right, up and forward axes.
pub fn camera_axes(camera: &Camera) -> (Vec3, Vec3, Vec3) {
    let v = Viewer::from_camera(camera);
    (v.right, v.up, v.forward)
}

/// The box around `particles`' sprites (each a sphere of its size).
pub fn particle_bounds(particles: &[Particle]) -> (Vec3, Vec3) {
    particles.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(p.position - p.size), hi.max(p.position + p.size)),
    )
}

/// The frame that `viewer` sees fitted around a system of `particles`: centred on their bounds,
/// its radius the farthest sprite edge from that centre, its axes the viewer's.
pub fn fit_frame(viewer: &Viewer, particles: &[Particle]) -> ProbeFrame {
    let (centre, _) = bounding_sphere(particle_bounds(particles));
    let radius = particles
        .iter()
        .map(|p| (p.position - centre).length() + p.size)
        .fold(0.0, f32::max);
    ProbeFrame {
        centre,
        radius,
        half_depth: radius,
        right: viewer.right,
        up: viewer.up,
        forward: viewer.forward,
    }
}

impl ProbeFrame {
    /// The probe position at `(u, v)` of slice `k` of `n`.
    pub fn probe(&self, u: f32, v: f32, k: u32, n: u32) -> Vec3 {
        let depth = if n > 1 {
            -self.half_depth + 2.0 * self.half_depth * k as f32 / (n - 1) as f32
        } else {
            0.0
        };
        self.centre + self.right * self.radius * (2.0 * u - 1.0)
            - self.up * self.radius * (2.0 * v - 1.0)
            + self.forward * depth
    }

    /// `(u, v)` of the probe nearest `p` on a slice, and `p`'s slice coordinate in `0..=n-1`.
    pub fn locate(&self, p: Vec3, n: u32) -> (f32, f32, f32) {
        let d = p - self.centre;
        let u = 0.5 + 0.5 * d.dot(self.right) / self.radius;
        let v = 0.5 - 0.5 * d.dot(self.up) / self.radius;
        let s = if n > 1 {
            ((d.dot(self.forward) + self.half_depth) / (2.0 * self.half_depth) * (n - 1) as f32)
                .clamp(0.0, (n - 1) as f32)
        } else {
            0.0
        };
        (u, v, s)
    }
}

/// The point whose lighting stands for the whole entity in the single-probe reference: an
/// object's origin, a system's bounds centre.
pub fn probe_point(scene: &Scene, entity: EntityKey) -> Vec3 {
    match entity {
        EntityKey::Object(i) => scene.alpha_objects[i].transform.w_axis.truncate(),
        EntityKey::System(_) => bounding_sphere(entity.world_bounds(scene)).0,
    }
}

/// The scene's alpha entities in blending order: farthest centre (along the view direction)
/// first; ties keep objects before systems, then scene order.
pub fn back_to_front(scene: &Scene) -> Vec<EntityKey> {
    let (_, _, forward) = camera_axes(&scene.camera);
    let depth = |e: EntityKey| (probe_point(scene, e) - scene.camera.eye).dot(forward);
    let mut order: Vec<EntityKey> = crate::layout::entities(scene).collect();
    order.sort_by(|a, b| depth(*b).total_cmp(&depth(*a)));
    order
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn probes_and_locate_are_inverse() {
        let scene = histencil_scene::embedded("volume").unwrap();
        let viewer = Viewer::from_camera(&scene.camera);
        let frame = fit_frame(&viewer, &scene.particle_systems[0].particles);
        // The GPU records use the frame's centre as the system's single probe point.
        assert_eq!(frame.centre, probe_point(&scene, EntityKey::System(0)));
        for (u, v, k) in [(0.25, 0.75, 0), (0.5, 0.5, 3), (0.9, 0.1, 7)] {
            let p = frame.probe(u, v, k, 8);
            let (lu, lv, s) = frame.locate(p, 8);
            assert!((lu - u).abs() < 1e-5 && (lv - v).abs() < 1e-5 && (s - k as f32).abs() < 1e-4);
        }
        // Every sprite lies within the quad's extent.
        for p in &scene.particle_systems[0].particles {
            let (u, v, _) = frame.locate(p.position, 1);
            assert!((0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v));
        }
        let (right, up, forward) = camera_axes(&scene.camera);
        assert!(right.dot(up).abs() < 1e-6 && up.dot(forward).abs() < 1e-6);
    }

    #[test]
    fn entities_blend_far_to_near() {
        let mut scene = histencil_scene::embedded("alpha").unwrap();
        let near =
            histencil_scene::glass_sphere(scene.camera.eye + Vec3::new(0.0, -1.0, -3.0), 0.3);
        scene.alpha_objects.push(near);
        let order = back_to_front(&scene);
        assert_eq!(order.len(), 3);
        assert_eq!(*order.last().unwrap(), EntityKey::Object(1));
    }
}
