//! The CPU side of the GPU data blocks. Each mirrors a GLSL block in `crates/vk/shaders/include` field for
//! field (std140 / std430 / push constants); the sizes are asserted in tests.

use crate::shader_consts::LIGHT_KINDS;
use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};
use histencil_model::ViewDesc;
use histencil_scene::{Camera, Light, LightKind};

/// `Frame` in frame.glsl (std140).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub struct FrameUniforms {
    /// World to view (column-major, as every matrix here).
    pub view: [[f32; 4]; 4],
    /// View to clip.
    pub proj: [[f32; 4]; 4],
    /// World to clip: `proj * view`.
    pub view_proj: [[f32; 4]; 4],
    /// View to world, for rebuilding a pixel's world position from its depth.
    pub inv_view: [[f32; 4]; 4],
    /// The camera's world position; w is 1.
    pub eye: [f32; 4],
    /// `(width, height, 1 / width, 1 / height)` in pixels.
    pub viewport: [f32; 4],
    /// How a pixel's view ray is rebuilt from its NDC: `(1 / P00, 1 / P11, P20, P21)` of the
    /// projection `P` (`m[column][row]`), so `view.xy / -view.z = (ndc.xy + zw) * xy`; off-centre
    /// (jittered) projections included.
    pub projection: [f32; 4],
    /// x: exposure; y: the far plane's depth (1, or 0 with reversed Z), where full-screen light
    /// passes are drawn.
    pub settings: [f32; 4],
    /// x: the number of lights in the light buffer (the forward pass and tile lists loop to it).
    pub counts: [u32; 4],
}

/// A view the light shaders cannot rebuild positions in.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "the view-to-clip matrix is not a perspective projection with clip w = -view z (a \
     right-handed view space looking down -Z, as glam's look_at_rh and perspective_rh make): {0}"
)]
pub struct ProjectionError(pub &'static str);

/// Exposure applied before tonemapping.
pub const EXPOSURE: f32 = 1.0;

impl FrameUniforms {
    /// The uniforms of a scene's camera at `width` x `height` (histencil's own renderer; an
    /// engine's view goes through [`Self::from_view`]).
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
            // The camera's projection is glam's Vulkan one: P11 = -1 / tan_y (y down), centred.
            projection: [tan_y * aspect, -tan_y, 0.0, 0.0],
            settings: [EXPOSURE, 1.0, 0.0, 0.0],
            counts: [light_count, 0, 0, 0],
        }
    }

    /// The uniforms of an engine's view at `width` x `height`: the matrices as given, the eye
    /// from the inverse view, the ray reconstruction from the projection.
    ///
    /// # Errors
    /// [`ProjectionError`] for an orthographic projection or one whose clip w is not `-z`; the
    /// matrices' other checks are [`histencil_model::View::new`]'s.
    pub fn from_view(
        desc: &ViewDesc,
        width: u32,
        height: u32,
        light_count: u32,
    ) -> Result<Self, ProjectionError> {
        let view = Mat4::from_cols_array_2d(&desc.world_to_view);
        let proj = Mat4::from_cols_array_2d(&desc.view_to_clip);
        // Clip w must be -z: row 3 of P is (0, 0, -1, 0).
        let w_row = proj.row(3);
        if w_row != glam::Vec4::new(0.0, 0.0, -1.0, 0.0) {
            return Err(ProjectionError("its last row is not (0, 0, -1, 0)"));
        }
        let (p00, p11) = (proj.x_axis.x, proj.y_axis.y);
        if !(p00.is_normal() && p11.is_normal()) || proj.x_axis.y != 0.0 || proj.y_axis.x != 0.0 {
            return Err(ProjectionError(
                "x and y do not scale independently by finite non-zero factors",
            ));
        }
        let inv_view = view.inverse();
        Ok(Self {
            view: desc.world_to_view,
            proj: desc.view_to_clip,
            view_proj: (proj * view).to_cols_array_2d(),
            inv_view: inv_view.to_cols_array_2d(),
            eye: inv_view.w_axis.to_array(),
            viewport: [
                width as f32,
                height as f32,
                1.0 / width as f32,
                1.0 / height as f32,
            ],
            projection: [1.0 / p00, 1.0 / p11, proj.z_axis.x, proj.z_axis.y],
            settings: [EXPOSURE, desc.depth.far(), 0.0, 0.0],
            counts: [light_count, 0, 0, 0],
        })
    }
}

/// `Light` in frame.glsl (std430).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub struct GpuLight {
    /// xyz: position; w: range, at and beyond which the light contributes nothing.
    pub position_radius: [f32; 4],
    /// rgb: radiance scale; w: the `LIGHT_*` kind code, as a float.
    pub color_kind: [f32; 4],
    /// xyz: the normalised direction the light travels (spot and directional); w: the
    /// `LIGHT_FALLOFF_*` code of its [`histencil_scene::Falloff`], as a float.
    pub direction: [f32; 4],
    /// Spot cone: `(cos outer, cos inner, tan outer, 0)`; zero for other kinds.
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
    /// The shader's record of a scene light.
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
            direction: direction.extend(light.falloff.code() as f32).to_array(),
            spot,
        }
    }
}

pub use crate::gpu::device::descriptors::PUSH_CONSTANT_BYTES;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shaders_falloff_codes_are_the_scenes() {
        use histencil_scene::Falloff;
        let all = [
            Falloff::SquaredWindow,
            Falloff::Gltf,
            Falloff::InverseSquare,
        ];
        for (falloff, (_, code)) in all.into_iter().zip(crate::shader_consts::LIGHT_FALLOFFS) {
            assert_eq!(falloff.code(), code, "{falloff:?}");
        }
    }

    /// The camera's own uniforms and those rebuilt from its matrices agree: the engine path and
    /// histencil's reconstruct the same rays.
    #[test]
    fn uniforms_from_the_cameras_matrices_match_the_camera() {
        let camera = Camera {
            eye: Vec3::new(1.0, 2.0, 5.0),
            target: Vec3::new(0.0, 0.5, 0.0),
            up: Vec3::Y,
            fov_y_radians: 0.9,
            near: 0.1,
            far: 50.0,
        };
        let from_camera = FrameUniforms::new(&camera, 320, 200, 3);
        let desc = camera.view_desc(320.0 / 200.0);
        let from_view = FrameUniforms::from_view(&desc, 320, 200, 3).unwrap();
        for (a, b) in from_camera.projection.iter().zip(from_view.projection) {
            assert!((a - b).abs() <= 1e-6 * a.abs().max(1.0), "{a} vs {b}");
        }
        for (a, b) in from_camera.eye.iter().zip(from_view.eye) {
            assert!((a - b).abs() <= 1e-5, "{a} vs {b}");
        }
        assert_eq!(from_view.settings[1], 1.0);
        let reversed = ViewDesc {
            depth: histencil_model::DepthConvention::Reversed,
            ..desc
        };
        let r = FrameUniforms::from_view(&reversed, 320, 200, 3).unwrap();
        assert_eq!(r.settings[1], 0.0);
    }

    #[test]
    fn orthographic_and_left_handed_projections_are_refused() {
        use glam::Vec4;
        let rows = |w: Vec4| {
            Mat4::from_rows(
                Vec4::new(1.0, 0.0, 0.0, 0.0),
                Vec4::new(0.0, -1.0, 0.0, 0.0),
                Vec4::new(0.0, 0.0, 0.01, 0.1),
                w,
            )
        };
        let ortho = rows(Vec4::new(0.0, 0.0, 0.0, 1.0));
        let left_handed = rows(Vec4::new(0.0, 0.0, 1.0, 0.0));
        let sheared = Mat4 {
            x_axis: Vec4::new(1.0, 0.5, 0.0, 0.0),
            ..rows(Vec4::new(0.0, 0.0, -1.0, 0.0))
        };
        assert!(FrameUniforms::from_view(
            &ViewDesc {
                world_to_view: Mat4::IDENTITY.to_cols_array_2d(),
                view_to_clip: rows(Vec4::new(0.0, 0.0, -1.0, 0.0)).to_cols_array_2d(),
                depth: histencil_model::DepthConvention::Standard,
            },
            8,
            8,
            0
        )
        .is_ok());
        for proj in [ortho, left_handed, sheared] {
            let desc = ViewDesc {
                world_to_view: Mat4::IDENTITY.to_cols_array_2d(),
                view_to_clip: proj.to_cols_array_2d(),
                depth: histencil_model::DepthConvention::Standard,
            };
            assert!(FrameUniforms::from_view(&desc, 8, 8, 0).is_err());
        }
    }

    #[test]
    fn block_sizes_match_the_glsl() {
        assert_eq!(std::mem::size_of::<FrameUniforms>(), 4 * 64 + 5 * 16);
        assert_eq!(std::mem::size_of::<GpuLight>(), 64);
    }
}
