//! The light volumes the lighting draws: a sphere circumscribing a point light's range, a cone
//! a spot light's, each a [`GpuMesh`] in host-visible memory.

use crate::gpu::device::context::Context;
use crate::gpu::device::error::Result;
use crate::gpu::device::teardown::Owned;
use crate::gpu::encoder::meshes::GpuMesh;
use crate::gpu::encoder::recording::Recording;
use histencil_scene::{light_cone, light_sphere, LightKind};

/// Light-volume tessellation: enough that the circumscribed mesh stays close to the sphere / cone.
pub const SPHERE_SEGMENTS: u32 = 24;
pub const SPHERE_RINGS: u32 = 12;
pub const CONE_SIDES: u32 = 24;

/// The light volumes: a sphere circumscribing a point light's range, a cone a spot light's.
///
/// They live in host-visible memory, written through its mapping rather than uploaded, so that
/// making a [`crate::DeferredLighting`] on an engine's device submits nothing to the engine's
/// queue (a few hundred vertices: what a draw reads of them stays in the GPU's caches).
pub struct LightVolumes {
    pub sphere: GpuMesh,
    pub cone: GpuMesh,
}

impl LightVolumes {
    pub fn new(ctx: &Context) -> Result<Self> {
        let sphere = light_sphere(SPHERE_SEGMENTS, SPHERE_RINGS);
        let cone = light_cone(CONE_SIDES);
        // The sphere is freed if the cone fails.
        let sphere = Owned::new(
            ctx,
            GpuMesh::host_visible(ctx, "light-sphere-mesh", &sphere)?,
        );
        let cone = GpuMesh::host_visible(ctx, "light-cone-mesh", &cone)?;
        Ok(Self {
            sphere: sphere.keep(),
            cone,
        })
    }

    /// Draws the volume of a light of `kind` (the vertex shader places it).
    pub(crate) fn draw(&self, rec: &Recording, kind: &LightKind) {
        match kind {
            LightKind::Spot { .. } => self.cone.draw(rec),
            _ => self.sphere.draw(rec),
        }
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.sphere.destroy(ctx);
        self.cone.destroy(ctx);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use histencil_model::VOLUME_OVERSHOOT;
    use histencil_scene::Mesh;

    fn farthest(m: &Mesh, f: fn([f32; 3]) -> f32) -> f64 {
        m.vertices
            .iter()
            .map(|v| f64::from(f(v.position)))
            .fold(0.0, f64::max)
    }

    /// The planner bounds light volumes by `VOLUME_OVERSHOOT` times their range: the meshes
    /// drawn must stay inside that.
    #[test]
    fn light_volumes_stay_within_the_planners_bound() {
        let sphere = light_sphere(SPHERE_SEGMENTS, SPHERE_RINGS);
        let reach = farthest(&sphere, |p| glam::Vec3::from(p).length());
        assert!(reach > 1.0 && reach <= VOLUME_OVERSHOOT, "{reach}");
        let cone = light_cone(CONE_SIDES);
        let radial = farthest(&cone, |p| glam::Vec2::new(p[0], p[1]).length());
        let axial = farthest(&cone, |p| p[2]);
        assert!(radial > 1.0 && radial <= VOLUME_OVERSHOOT, "{radial}");
        assert!(axial > 1.0 && axial <= VOLUME_OVERSHOOT, "{axial}");
    }

    /// Every vertex of a light's volume, placed as `light_volume.vert` places it, lies in the
    /// planner's sphere for that light: the hi-stencil emulation looks for the pixels a volume
    /// rasterised only inside that sphere's screen rectangle.
    #[test]
    fn placed_volumes_lie_in_the_planners_sphere() {
        use histencil_model::{LightShape, MAX_SPOT_ANGLE};
        let (position, range) = ([1.0, -2.0, 3.0], 2.5f32);
        let inside = |shape: LightShape, placed: &dyn Fn([f32; 3]) -> [f64; 3], mesh: &Mesh| {
            let (centre, radius) = shape.volume_sphere().expect("a volume");
            for v in &mesh.vertices {
                let p = glam::DVec3::from(placed(v.position));
                let d = p.distance(glam::DVec3::from(centre));
                assert!(d <= radius * (1.0 + 1e-9), "{shape:?}: {d} > {radius}");
            }
        };
        let origin = glam::DVec3::from(position.map(f64::from));
        let sphere = light_sphere(SPHERE_SEGMENTS, SPHERE_RINGS);
        let point = LightShape::Point { position, range };
        let scaled =
            |p: [f32; 3]| (origin + glam::Vec3::from(p).as_dvec3() * f64::from(range)).into();
        inside(point, &scaled, &sphere);
        let cone = light_cone(CONE_SIDES);
        for degrees in [0.5f32, 5.0, 20.0, 45.0, 60.0, 70.0, 79.9] {
            let outer_angle = degrees.to_radians().min(MAX_SPOT_ANGLE);
            // Along +Z, as the shader places a cone on its light's axis.
            let shape = LightShape::Spot {
                position,
                direction: [0.0, 0.0, 1.0],
                range,
                outer_angle,
            };
            let r = range * outer_angle.tan();
            let placed = |p: [f32; 3]| {
                let local = glam::Vec3::new(p[0] * r, p[1] * r, p[2] * range);
                (origin + local.as_dvec3()).into()
            };
            inside(shape, &placed, &cone);
        }
    }
}
