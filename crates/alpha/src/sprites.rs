//! The alpha pass's particle geometry, built on the CPU for a camera because it faces it: one
//! quad per sprite (billboard, slices, dust) or a strip through a ribbon's control points. (The
//! renderer's camera is fixed per scene, so it builds them once; a moving camera rebuilds them.)

use crate::probes::camera_axes;
use glam::Vec3;
use histencil_scene::{Camera, ParticleLayout, ParticleSystem};

/// One vertex of the particle pass (`crates/vk/shaders/particle.vert`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct SpriteVertex {
    /// World position of the vertex: a corner of the sprite (or an edge point of the ribbon's
    /// strip), already facing the camera.
    pub position: [f32; 3],
    /// `(-1..1, -1..1)` across the sprite (a ribbon's strip: `(0, -1..1)`); coverage falls to
    /// zero at radius 1.
    pub corner: [f32; 2],
    /// The entity's index in the frame's entity records.
    pub entity: u32,
    /// Dust: the mote's index (its texel). Ribbon: the position along the ribbon in `0..=1`.
    pub param: f32,
}

/// The triangles (a list, 6 vertices per quad) of `system`'s sprites for `camera`, far to near.
pub fn sprite_vertices(camera: &Camera, system: &ParticleSystem, entity: u32) -> Vec<SpriteVertex> {
    let (right, up, forward) = camera_axes(camera);
    let vertex = |p: Vec3, corner: [f32; 2], param: f32| SpriteVertex {
        position: p.to_array(),
        corner,
        entity,
        param,
    };
    let quad = |out: &mut Vec<SpriteVertex>, c: [(Vec3, [f32; 2]); 4], param: f32| {
        for i in [0, 1, 2, 0, 2, 3] {
            out.push(vertex(c[i].0, c[i].1, param));
        }
    };
    let mut out = Vec::new();
    if system.layout == ParticleLayout::Ribbon {
        let points = &system.particles;
        let n = points.len();
        let side = |j: usize| {
            let tangent =
                points[(j + 1).min(n - 1)].position - points[j.saturating_sub(1)].position;
            let to_eye = camera.eye - points[j].position;
            tangent.cross(to_eye).normalize_or(right) * points[j].size
        };
        for j in 0..n - 1 {
            let (a, b) = (points[j].position, points[j + 1].position);
            let (sa, sb) = (side(j), side(j + 1));
            let (ta, tb) = (j as f32 / (n - 1) as f32, (j + 1) as f32 / (n - 1) as f32);
            // The strip's parameter varies along it, so the quad is two triangles with their own
            // per-vertex t rather than one constant param.
            for (p, corner, t) in [
                (a - sa, [0.0, -1.0], ta),
                (b - sb, [0.0, -1.0], tb),
                (b + sb, [0.0, 1.0], tb),
                (a - sa, [0.0, -1.0], ta),
                (b + sb, [0.0, 1.0], tb),
                (a + sa, [0.0, 1.0], ta),
            ] {
                out.push(vertex(p, corner, t));
            }
        }
        return out;
    }
    let mut order: Vec<usize> = (0..system.particles.len()).collect();
    let depth = |i: usize| (system.particles[i].position - camera.eye).dot(forward);
    order.sort_by(|a, b| depth(*b).total_cmp(&depth(*a)).then(a.cmp(b)));
    for i in order {
        let p = system.particles[i];
        let (r, u) = (right * p.size, up * p.size);
        let corners = [
            (p.position - r - u, [-1.0, -1.0]),
            (p.position + r - u, [1.0, -1.0]),
            (p.position + r + u, [1.0, 1.0]),
            (p.position - r + u, [-1.0, 1.0]),
        ];
        quad(&mut out, corners, i as f32);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sprites_are_sorted_far_to_near_and_ribbons_are_strips() {
        let scene = histencil_scene::embedded("volume").unwrap();
        let system = &scene.particle_systems[0];
        let v = sprite_vertices(&scene.camera, system, 3);
        assert_eq!(v.len(), 6 * system.particles.len());
        let (_, _, forward) = camera_axes(&scene.camera);
        let depth =
            |q: &[SpriteVertex]| (Vec3::from(q[0].position) - scene.camera.eye).dot(forward);
        let quads: Vec<&[SpriteVertex]> = v.chunks_exact(6).collect();
        assert!(quads.windows(2).all(|w| depth(w[0]) >= depth(w[1]) - 1e-3));
        assert!(v.iter().all(|x| x.entity == 3));

        let scene = histencil_scene::embedded("ribbon").unwrap();
        let ribbon = &scene.particle_systems[0];
        let v = sprite_vertices(&scene.camera, ribbon, 0);
        assert_eq!(v.len(), 6 * (ribbon.particles.len() - 1));
        assert_eq!(v[0].param, 0.0);
        assert_eq!(v.iter().map(|x| x.param).fold(0.0, f32::max), 1.0);
        assert!(v.iter().all(|x| x.position.iter().all(|c| c.is_finite())));
    }
}
