//! The alpha passes' GPU records (include/alpha.glsl) and how a scene fills them.

use crate::shader_consts::ALPHA_KINDS;
use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};
use histencil_alpha::{fit_frame, probe_point, EntityKey, EntityRegion, ProbeFrame};
use histencil_scene::{Material, ParticleLayout, Scene};

/// `AlphaEntity` in alpha.glsl (std430).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuAlphaEntity {
    pub model: [[f32; 4]; 4],
    pub tint_opacity: [f32; 4],
    pub params: [f32; 4],
    pub region: [u32; 4],
    pub shape: [u32; 4],
    pub centre_radius: [f32; 4],
    pub right_depth: [f32; 4],
    pub up: [f32; 4],
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
    pub mode: u32,
    pub pad: u32,
}

fn kind_code(name: &str) -> u32 {
    ALPHA_KINDS
        .iter()
        .find(|(n, _)| *n == name)
        .expect("known alpha kind")
        .1
}

/// Per entity (in `regions` order), the lights whose range reaches its bounds.
pub fn entity_lights(scene: &Scene, regions: &[EntityRegion]) -> Vec<Vec<u32>> {
    regions
        .iter()
        .map(|r| {
            let (lo, hi) = r.entity.world_bounds(scene);
            (0..scene.lights.len() as u32)
                .filter(|l| scene.lights[*l as usize].reaches_box(lo, hi))
                .collect()
        })
        .collect()
}

/// The records of every entity (in `regions` order, which is `histencil_alpha::entities`
/// order), the dust and ribbon points they index, and their light lists flattened (each
/// record's `light_range` points into it).
pub fn entity_records(
    scene: &Scene,
    regions: &[EntityRegion],
    lights: &[Vec<u32>],
) -> (Vec<GpuAlphaEntity>, Vec<[f32; 4]>, Vec<u32>) {
    let mut light_list: Vec<u32> = Vec::new();
    let mut points: Vec<[f32; 4]> = Vec::new();
    let records = regions
        .iter()
        .map(|r| {
            let region = [
                r.region.x,
                r.region.y,
                r.shape.tile_width,
                r.shape.tile_height,
            ];
            match r.entity {
                EntityKey::Object(i) => {
                    let o = &scene.alpha_objects[i];
                    let frame = ProbeFrame {
                        centre: probe_point(scene, r.entity),
                        radius: 1.0,
                        half_depth: 0.0,
                        right: Vec3::X,
                        up: Vec3::Y,
                        forward: Vec3::Z,
                    };
                    record(
                        o.transform,
                        &o.material,
                        o.opacity,
                        region,
                        [kind_code("ALPHA_OBJECT"), 1, 0, 0],
                        &frame,
                    )
                }
                EntityKey::System(i) => {
                    let s = &scene.particle_systems[i];
                    // Centred on the system's bounds: also its single probe's point.
                    let frame = fit_frame(&scene.camera, s);
                    let first = points.len() as u32;
                    let count = s.particles.len() as u32;
                    let kind = match s.layout {
                        ParticleLayout::Billboard | ParticleLayout::Slices { .. } => "ALPHA_SLICES",
                        ParticleLayout::Dust => "ALPHA_DUST",
                        ParticleLayout::Ribbon => "ALPHA_RIBBON",
                    };
                    if matches!(s.layout, ParticleLayout::Dust | ParticleLayout::Ribbon) {
                        points.extend(
                            s.particles
                                .iter()
                                .map(|p| p.position.extend(p.size).to_array()),
                        );
                    }
                    let shape = [kind_code(kind), r.shape.tiles, first, count];
                    record(
                        Mat4::IDENTITY,
                        &s.material,
                        s.opacity,
                        region,
                        shape,
                        &frame,
                    )
                }
            }
        })
        .zip(lights)
        .map(|(mut record, lights): (GpuAlphaEntity, &Vec<u32>)| {
            record.light_range = [light_list.len() as u32, lights.len() as u32, 0, 0];
            light_list.extend(lights);
            record
        })
        .collect();
    (records, points, light_list)
}

fn record(
    model: Mat4,
    material: &Material,
    opacity: f32,
    region: [u32; 4],
    shape: [u32; 4],
    frame: &ProbeFrame,
) -> GpuAlphaEntity {
    let p = material.brdf.packed_params();
    GpuAlphaEntity {
        model: model.to_cols_array_2d(),
        tint_opacity: material.tint.extend(opacity).to_array(),
        params: [
            p[0] as f32,
            p[1] as f32,
            p[2] as f32,
            material.brdf.model_index() as f32,
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

    #[test]
    fn records_match_the_glsl_block() {
        assert_eq!(std::mem::size_of::<GpuAlphaEntity>(), 64 + 9 * 16);
        assert_eq!(std::mem::size_of::<AlphaDrawPush>(), 16);
    }

    #[test]
    fn dust_and_ribbons_index_their_points() {
        let mut scene = histencil_scene::embedded("dust").unwrap();
        let ribbon = histencil_scene::embedded("ribbon")
            .unwrap()
            .particle_systems[0]
            .clone();
        scene.particle_systems.push(ribbon);
        let layout = histencil_alpha::plan_layout(&scene, 256, None, 4096).unwrap();
        let lights = entity_lights(&scene, &layout.regions);
        let (records, points, list) = entity_records(&scene, &layout.regions, &lights);
        assert_eq!(list.len(), lights.iter().map(Vec::len).sum::<usize>());
        assert_eq!(records[1].light_range[0] as usize, lights[0].len());
        assert_eq!(records[0].shape[2..], [0, 600]);
        assert_eq!(records[1].shape[2..], [600, 64]);
        assert_eq!(points.len(), 664);
    }
}
