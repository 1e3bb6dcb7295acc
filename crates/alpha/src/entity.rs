//! An engine's alpha entities as plain values, borrowed for a frame: what histencil-vk's
//! `AlphaLightmaps` lights and what the parameter estimate ([`crate::choose_parameters`]) reads.
//! A translucent object brings the mesh whose lightmap UV layout holds its probes; a particle
//! system brings its particles. [`ProbeMeshes`] and [`scene_alpha_entities`] give a histencil
//! scene's entities the same way.

use crate::{particle_bounds, EntityDesc, EntityKind};
use glam::{Mat4, Vec3};
use histencil_scene::{
    unit_box_bake, uv_sphere, Light, Material, Mesh, Particle, ParticleLayout, Scene, Shape,
    SPHERE_DETAIL,
};

/// One translucent object or particle system, as lit this frame.
#[derive(Clone, Copy, Debug)]
pub struct AlphaEntity<'a> {
    /// A translucent mesh or a particle system, with what its probes are made from.
    pub kind: AlphaEntityKind<'a>,
    /// The BRDF and tint its probes are lit with.
    pub material: Material,
    /// Coverage in `[0, 1]`, carried to the record for the alpha shader.
    pub opacity: f32,
}

/// What the entity is.
#[derive(Clone, Copy, Debug)]
pub enum AlphaEntityKind<'a> {
    /// A translucent mesh. `probe_mesh` is the mesh in its lightmap UV layout (object space;
    /// `uv` in `[0, 1]^2`, the layout the alpha shader samples with): one probe per texel it
    /// covers, baked on the CPU at the region's size ([`crate::bake_probes`]).
    /// `local_bounds` is the object-space box of what is drawn (lights reaching it light the
    /// entity), `transform` object to world.
    Object {
        /// The mesh in its lightmap UV layout.
        probe_mesh: &'a Mesh,
        /// Object to world.
        transform: Mat4,
        /// `(min, max)` of what is drawn, in object space.
        local_bounds: (Vec3, Vec3),
    },
    /// A particle system: `particles` are world-space sprites (position, size).
    Particles {
        /// How the system's probes are laid out.
        layout: ParticleLayout,
        /// The sprites, in world space.
        particles: &'a [Particle],
    },
}

/// The object-space box around `mesh`'s vertices (an empty mesh: the origin).
pub fn mesh_bounds(mesh: &Mesh) -> (Vec3, Vec3) {
    let points = mesh.vertices.iter().map(|v| Vec3::from(v.position));
    let bounds = points.fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(p), hi.max(p)),
    );
    if bounds.0.cmple(bounds.1).all() {
        bounds
    } else {
        (Vec3::ZERO, Vec3::ZERO)
    }
}

impl AlphaEntity<'_> {
    /// The world-space box around what the entity draws.
    pub fn world_bounds(&self) -> (Vec3, Vec3) {
        match self.kind {
            AlphaEntityKind::Object {
                transform,
                local_bounds: (lo, hi),
                ..
            } => {
                let corners = (0..8).map(|i| {
                    let pick = |bit: u32, a: f32, b: f32| if i & bit == 0 { a } else { b };
                    transform.transform_point3(Vec3::new(
                        pick(1, lo.x, hi.x),
                        pick(2, lo.y, hi.y),
                        pick(4, lo.z, hi.z),
                    ))
                });
                corners.fold(
                    (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
                    |(lo, hi), p| (lo.min(p), hi.max(p)),
                )
            }
            AlphaEntityKind::Particles { particles, .. } => particle_bounds(particles),
        }
    }

    /// The indices of the `lights` whose range reaches the entity's bounds: the only ones that
    /// light it (one lightmap draw each).
    pub fn lights_reaching(&self, lights: &[Light]) -> Vec<u32> {
        let (lo, hi) = self.world_bounds();
        (0..lights.len() as u32)
            .filter(|&l| lights[l as usize].reaches_box(lo, hi))
            .collect()
    }

    /// The entity's description for [`crate::plan_regions`]: its kind and world bounds,
    /// coverage and side from those.
    pub fn desc(&self) -> EntityDesc {
        let kind = match self.kind {
            AlphaEntityKind::Object { .. } => EntityKind::Surface,
            AlphaEntityKind::Particles { layout, particles } => EntityKind::Particles {
                layout,
                count: u32::try_from(particles.len()).unwrap_or(u32::MAX),
            },
        };
        EntityDesc {
            kind,
            bounds: self.world_bounds(),
            coverage_px: None,
            side: None,
        }
    }

    /// What is wrong with the entity, if anything: an opacity outside `[0, 1]`, a material its
    /// BRDF refuses, a transform or bounds that are not finite, a probe mesh that is not a
    /// triangle list of its vertices ([`histencil_scene::Mesh::problem`]), particles that are
    /// not finite or not of positive size, or a layout its particles cannot fill.
    pub fn problem(&self) -> Option<String> {
        if !(0.0..=1.0).contains(&self.opacity) {
            return Some(format!("opacity {} is outside [0, 1]", self.opacity));
        }
        if let Some(p) = self.material.problem() {
            return Some(p);
        }
        match self.kind {
            AlphaEntityKind::Object {
                transform,
                local_bounds: (lo, hi),
                probe_mesh,
            } => {
                if !transform.is_finite() || transform.determinant() == 0.0 {
                    return Some("its transform must be finite and invertible".into());
                }
                // The bake reads its triangles: one past the vertices would leave texels
                // unbaked (unlit) with no word.
                if let Some(p) = probe_mesh.problem() {
                    return Some(format!("its probe mesh: {p}"));
                }
                if !(lo.is_finite() && hi.is_finite()) || lo.cmpgt(hi).any() {
                    return Some("its bounds must be finite with min <= max".into());
                }
            }
            AlphaEntityKind::Particles { particles, .. } => {
                if particles
                    .iter()
                    .any(|p| !p.position.is_finite() || !p.size.is_finite() || p.size <= 0.0)
                {
                    return Some(
                        "particle positions must be finite and sizes finite and positive".into(),
                    );
                }
            }
        }
        crate::entity_problem(&self.desc()).map(str::to_owned)
    }
}

/// The CPU meshes whose UV layouts hold a scene's object probes: the box's bake layout (faces
/// extended into their gutters), the sphere, the imported meshes.
pub struct ProbeMeshes {
    unit_box: Mesh,
    sphere: Mesh,
    imported: Vec<Mesh>,
}

impl ProbeMeshes {
    /// The built-in shapes' bake meshes, and a copy of the scene's imported meshes.
    pub fn new(scene: &Scene) -> Self {
        Self {
            unit_box: unit_box_bake(),
            sphere: uv_sphere(SPHERE_DETAIL.0, SPHERE_DETAIL.1),
            imported: scene.meshes.clone(),
        }
    }

    /// The probe mesh of `shape`.
    pub fn get(&self, shape: Shape) -> &Mesh {
        match shape {
            Shape::Box => &self.unit_box,
            Shape::Sphere => &self.sphere,
            Shape::Mesh(i) => &self.imported[i as usize],
        }
    }
}

/// `scene`'s alpha entities as an engine would hand them over, in [`crate::entities`] order.
/// Scene shapes fill `[-1, 1]^3`.
pub fn scene_alpha_entities<'a>(scene: &'a Scene, meshes: &'a ProbeMeshes) -> Vec<AlphaEntity<'a>> {
    let objects = scene.alpha_objects.iter().map(|o| AlphaEntity {
        kind: AlphaEntityKind::Object {
            probe_mesh: meshes.get(o.shape),
            transform: o.transform,
            local_bounds: (Vec3::NEG_ONE, Vec3::ONE),
        },
        material: o.material,
        opacity: o.opacity,
    });
    let systems = scene.particle_systems.iter().map(|s| AlphaEntity {
        kind: AlphaEntityKind::Particles {
            layout: s.layout,
            particles: &s.particles,
        },
        material: s.material,
        opacity: s.opacity,
    });
    objects.chain(systems).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use histencil_scene::uv_sphere;

    /// A probe mesh whose index runs past its vertices is refused, not baked with texels left
    /// unlit in silence.
    #[test]
    fn an_object_whose_probe_mesh_indexes_past_its_vertices_is_refused() {
        fn entity(mesh: &Mesh) -> AlphaEntity<'_> {
            AlphaEntity {
                kind: AlphaEntityKind::Object {
                    probe_mesh: mesh,
                    transform: Mat4::IDENTITY,
                    local_bounds: (Vec3::splat(-1.0), Vec3::ONE),
                },
                material: Material::lambert(Vec3::splat(0.8)),
                opacity: 0.5,
            }
        }
        let mut mesh = uv_sphere(8, 4);
        assert_eq!(entity(&mesh).problem(), None);
        mesh.indices[7] = 10_000;
        let problem = entity(&mesh).problem().expect("refused");
        assert!(
            problem.contains("probe mesh: index 7 is 10000"),
            "{problem}"
        );
    }
}
