//! The alpha passes' GPU records (include/alpha_entity.glsl, alpha.glsl) and how a frame's
//! entities fill them.

use crate::shader_consts::ALPHA_KINDS;
use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};
use histencil_alpha::{bake_probes, fit_frame, EntityRegion, Probe, ProbeFrame, Viewer};
use histencil_alpha::{AlphaEntity, AlphaEntityKind};
use histencil_scene::{Light, Material, ParticleLayout};

/// One entity's lightmap record: `AlphaEntity` in `crates/vk/shaders/include/alpha_entity.glsl` (std430,
/// 208 bytes), which an engine's alpha shader reads to sample the atlas.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct AlphaEntityRecord {
    /// Object to world; identity for a particle system, whose points are in world space.
    pub model: [[f32; 4]; 4],
    /// rgb: the material's tint; w: the entity's opacity.
    pub tint_opacity: [f32; 4],
    /// xyz: the BRDF's packed parameters; w: its model index.
    pub params: [f32; 4],
    /// xy: the region's first texel in the atlas; zw: one tile's size.
    pub region: [u32; 4],
    /// x: kind, y: tiles, z: first point or probe (a sliced system: tiles to a row), w: point
    /// count.
    pub shape: [u32; 4],
    /// The probe frame's centre (the single probe's point) and radius.
    pub centre_radius: [f32; 4],
    /// xyz: the probe frame's unit right axis; w: half the depth of a slice stack.
    pub right_depth: [f32; 4],
    /// xyz: the probe frame's unit up axis.
    pub up: [f32; 4],
    /// xyz: the probe frame's unit view direction.
    pub forward: [f32; 4],
    /// First index into the entity light list, and count.
    pub light_range: [u32; 4],
}

/// `AlphaDraw` push constants in alpha.glsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct AlphaDrawPush {
    pub entity: u32,
    pub light: u32,
    pub pad: [u32; 2],
}

fn kind_code(name: &str) -> u32 {
    ALPHA_KINDS
        .iter()
        .find(|(n, _)| *n == name)
        .expect("known alpha kind")
        .1
}

/// What a frame's lightmap pass reads: every entity's record (in entity order), the dust and
/// ribbon points and object probes they index, and their light lists flattened (each record's
/// `light_range` points into it).
#[derive(Default)]
pub(crate) struct FrameRecords {
    pub records: Vec<AlphaEntityRecord>,
    pub points: Vec<[f32; 4]>,
    pub probes: Vec<Probe>,
    pub light_list: Vec<u32>,
    /// Per entity, the lights whose range reaches its bounds.
    pub entity_lights: Vec<Vec<u32>>,
}

/// The records of `entities` in their `regions`, seen by `viewer`, lit by the `lights` that
/// reach each one's bounds.
pub(crate) fn frame_records(
    entities: &[AlphaEntity],
    regions: &[EntityRegion],
    viewer: &Viewer,
    lights: &[Light],
) -> FrameRecords {
    let mut out = FrameRecords::default();
    for (entity, r) in entities.iter().zip(regions) {
        let reaching = entity.lights_reaching(lights);
        let region = [
            r.region.x,
            r.region.y,
            r.shape.tile_width,
            r.shape.tile_height,
        ];
        let mut record = match entity.kind {
            AlphaEntityKind::Object {
                probe_mesh,
                transform,
                ..
            } => {
                let baked = bake_probes(probe_mesh, r.shape.tile_width, r.shape.tile_height);
                let first = out.probes.len() as u32;
                out.probes.extend(baked.probes);
                let frame = ProbeFrame {
                    centre: transform.w_axis.truncate(),
                    radius: 1.0,
                    half_depth: 0.0,
                    right: Vec3::X,
                    up: Vec3::Y,
                    forward: Vec3::Z,
                };
                let shape = [kind_code("ALPHA_OBJECT"), 1, first, 0];
                record(transform, entity, region, shape, &frame)
            }
            AlphaEntityKind::Particles { layout, particles } => {
                // Centred on the system's bounds: also its single probe's point.
                let frame = fit_frame(viewer, particles);
                let first = out.points.len() as u32;
                let kind = match layout {
                    ParticleLayout::Billboard
                    | ParticleLayout::Slices { .. }
                    | ParticleLayout::Auto => "ALPHA_SLICES",
                    ParticleLayout::Dust => "ALPHA_DUST",
                    ParticleLayout::Ribbon => "ALPHA_RIBBON",
                };
                if matches!(layout, ParticleLayout::Dust | ParticleLayout::Ribbon) {
                    out.points.extend(
                        particles
                            .iter()
                            .map(|p| p.position.extend(p.size).to_array()),
                    );
                }
                let count = particles.len() as u32;
                // Sliced systems index no points: z holds their tiles' columns instead.
                let z = if kind == "ALPHA_SLICES" {
                    r.shape.columns
                } else {
                    first
                };
                let shape = [kind_code(kind), r.shape.tiles, z, count];
                record(Mat4::IDENTITY, entity, region, shape, &frame)
            }
        };
        record.light_range = [out.light_list.len() as u32, reaching.len() as u32, 0, 0];
        out.light_list.extend(&reaching);
        out.entity_lights.push(reaching);
        out.records.push(record);
    }
    out
}

fn record(
    model: Mat4,
    entity: &AlphaEntity,
    region: [u32; 4],
    shape: [u32; 4],
    frame: &ProbeFrame,
) -> AlphaEntityRecord {
    let Material { brdf, tint, .. } = entity.material;
    let p = brdf.packed_params();
    AlphaEntityRecord {
        model: model.to_cols_array_2d(),
        tint_opacity: tint.extend(entity.opacity).to_array(),
        params: [
            p[0] as f32,
            p[1] as f32,
            p[2] as f32,
            brdf.model_index() as f32,
        ],
        region,
        shape,
        centre_radius: frame.centre.extend(frame.radius).to_array(),
        right_depth: frame.right.extend(frame.half_depth).to_array(),
        up: frame.up.extend(0.0).to_array(),
        forward: frame.forward.extend(0.0).to_array(),
        light_range: [0; 4],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use histencil_alpha::scene_alpha_entities;

    #[test]
    fn records_match_the_glsl_block() {
        assert_eq!(std::mem::size_of::<AlphaEntityRecord>(), 64 + 9 * 16);
        assert_eq!(std::mem::size_of::<AlphaDrawPush>(), 16);
        assert_eq!(std::mem::size_of::<Probe>(), 32);
    }

    #[test]
    fn dust_ribbons_and_objects_index_their_points_and_probes() {
        let mut scene = histencil_scene::embedded("dust").unwrap();
        let other = histencil_scene::embedded("ribbon").unwrap();
        scene
            .particle_systems
            .push(other.particle_systems[0].clone());
        let glass = histencil_scene::embedded("alpha").unwrap();
        scene.alpha_objects.push(glass.alpha_objects[0].clone());
        let layout = histencil_alpha::plan_layout(&scene, 256, None, 4096)
            .unwrap()
            .layout;
        let meshes = histencil_alpha::ProbeMeshes::new(&scene);
        let entities = scene_alpha_entities(&scene, &meshes);
        let viewer = Viewer::from_camera(&scene.camera);
        let out = frame_records(&entities, &layout.regions, &viewer, &scene.lights);
        let lights = &out.entity_lights;
        assert_eq!(
            out.light_list.len(),
            lights.iter().map(Vec::len).sum::<usize>()
        );
        assert_eq!(out.records[1].light_range[0] as usize, lights[0].len());
        // The object first: its probes fill its region.
        let object = layout.regions[0].shape;
        assert_eq!(out.records[0].shape[2], 0);
        assert_eq!(
            out.probes.len() as u32,
            object.tile_width * object.tile_height
        );
        assert_eq!(out.records[1].shape[2..], [0, 600]);
        assert_eq!(out.records[2].shape[2..], [600, 64]);
        assert_eq!(out.points.len(), 664);
    }
}
