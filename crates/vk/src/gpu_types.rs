//! The CPU side of the GPU data blocks. Each mirrors a GLSL block in `shaders/include` field for
//! field (std140 / std430 / push constants); the sizes are asserted in tests.

use crate::shader_consts::LIGHT_KINDS;
use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};
use histencil_scene::{Camera, Light, LightKind, Material};

/// `Frame` in frame.glsl (std140).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub struct FrameUniforms {
    pub view: [[f32; 4]; 4],
    pub proj: [[f32; 4]; 4],
    pub view_proj: [[f32; 4]; 4],
    pub inv_view: [[f32; 4]; 4],
    pub eye: [f32; 4],
    pub viewport: [f32; 4],
    pub projection: [f32; 4],
    pub tonemap: [f32; 4],
    pub counts: [u32; 4],
}

/// Exposure applied before tonemapping.
pub const EXPOSURE: f32 = 1.0;

impl FrameUniforms {
    pub fn new(camera: &Camera, width: u32, height: u32, light_count: u32) -> Self {
        let aspect = width as f32 / height as f32;
        let view = camera.view();
        let proj = camera.projection(aspect);
        let tan_y = (camera.fov_y_radians * 0.5).tan();
        Self {
            view: view.to_cols_array_2d(),
            proj: proj.to_cols_array_2d(),
            view_proj: (proj * view).to_cols_array_2d(),
            inv_view: view.inverse().to_cols_array_2d(),
            eye: camera.eye.extend(1.0).to_array(),
            viewport: [
                width as f32,
                height as f32,
                1.0 / width as f32,
                1.0 / height as f32,
            ],
            projection: [tan_y * aspect, tan_y, camera.near, camera.far],
            tonemap: [EXPOSURE, 0.0, 0.0, 0.0],
            counts: [light_count, 0, 0, 0],
        }
    }
}

/// `Light` in frame.glsl (std430).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub struct GpuLight {
    pub position_radius: [f32; 4],
    pub color_kind: [f32; 4],
    pub direction: [f32; 4],
    pub spot: [f32; 4],
}

fn kind_code(name: &str) -> f32 {
    LIGHT_KINDS
        .iter()
        .find(|(n, _)| *n == name)
        .expect("known light kind")
        .1 as f32
}

impl GpuLight {
    pub fn new(light: &Light) -> Self {
        let (kind, direction, spot) = match light.kind {
            LightKind::Point => ("LIGHT_POINT", Vec3::Z, [0.0; 4]),
            LightKind::Spot {
                direction,
                inner_angle,
                outer_angle,
            } => (
                "LIGHT_SPOT",
                direction.normalize(),
                [outer_angle.cos(), inner_angle.cos(), outer_angle.tan(), 0.0],
            ),
            LightKind::Directional { direction } => {
                ("LIGHT_DIRECTIONAL", direction.normalize(), [0.0; 4])
            }
        };
        Self {
            position_radius: light.position.extend(light.radius).to_array(),
            color_kind: light.color.extend(kind_code(kind)).to_array(),
            direction: direction.extend(0.0).to_array(),
            spot,
        }
    }
}

/// `Draw` push constants in draw.glsl.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub struct DrawPush {
    pub model: [[f32; 4]; 4],
    pub tint: [f32; 4],
    pub params: [f32; 4],
}

impl DrawPush {
    /// `material_index` is the material's LUT table (the G-buffer stores it for the LUT
    /// technique).
    pub fn new(model: Mat4, material: &Material, material_index: u32) -> Self {
        let p = material.brdf.packed_params();
        Self {
            model: model.to_cols_array_2d(),
            tint: material.tint.extend(material_index as f32).to_array(),
            params: [
                p[0] as f32,
                p[1] as f32,
                p[2] as f32,
                material.brdf.model_index() as f32,
            ],
        }
    }
}

/// Push constants of the light passes (include/light_draw.glsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LightDrawPush {
    pub light_index: u32,
    /// Unique per draw of a frame: the hi-stencil emulation marks covered tiles with it.
    pub stamp: u32,
    /// `LIGHT_DRAW_*` bits (`shader_consts::LIGHT_DRAW_FLAGS`).
    pub flags: u32,
    /// The stencil bit a restore draw writes.
    pub bit: u32,
}

/// Bytes of push-constant space every pipeline layout declares (the largest block, `Draw`).
pub const PUSH_CONSTANT_BYTES: u32 = std::mem::size_of::<DrawPush>() as u32;

// 128 bytes is the push-constant space every Vulkan device guarantees.
const _: () = assert!(PUSH_CONSTANT_BYTES <= 128);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn block_sizes_match_the_glsl() {
        assert_eq!(std::mem::size_of::<FrameUniforms>(), 4 * 64 + 5 * 16);
        assert_eq!(std::mem::size_of::<GpuLight>(), 64);
        assert_eq!(PUSH_CONSTANT_BYTES, 96);
    }
}
