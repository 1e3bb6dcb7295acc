//! The deferred lighting pass with the talk's stencil depth culling of light volumes.
//!
//! Viewer outside a volume (the talk's case), three draws per light:
//! 1. *setup*: back faces, depth LESS: where the volume's back face is in front of the surface the
//!    surface lies behind the volume, so the culling bit is set; no colour.
//! 2. *shade*: front faces, depth LESS, stencil "culling bit clear": the light shader runs exactly
//!    on surfaces between the front and back faces.
//! 3. *cleanup*: back faces, no depth test: the culling bit goes back to 0 wherever the volume
//!    projects (a superset of where setup set it).
//!
//! Viewer inside the volume, or the volume touching the near plane (front faces clipped): one
//! draw of the back faces with depth GREATER (surface in front of the exit point) and no stencil.
//! Volumes crossing the far plane need no special case: the volume pipelines clamp depth, so back
//! faces beyond the far plane sit at depth 1, behind every surface.
//!
//! Volumes circumscribe the light's range and the falloff is exactly zero outside it, so any
//! over-coverage adds nothing: the stencil and depth tests are culling, never correctness.

use super::{begin_rendering, color_attachment, depth_stencil_attachment, Load, CLEAR_BLACK};
use crate::access::{transition, Contents, ImageAccess};
use crate::context::Context;
use crate::meshes::Meshes;
use crate::pipelines::Pipelines;
use crate::state::{DrawState, StencilState};
use crate::targets::Targets;
use ash::vk;
use glam::Vec3;
use histencil_model::StencilLayout;
use histencil_scene::{Camera, Light, LightKind};

/// How a light is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VolumeCase {
    /// The talk's three passes.
    Outside,
    /// Back faces with depth GREATER.
    Inside,
    /// Directional: a full-screen triangle at the far plane, depth GREATER.
    FullScreen,
}

/// A sphere containing the light's volume mesh.
pub fn volume_bound(
    light: &Light,
    meshes_sphere_bound: f32,
    cone_bound: (f32, f32),
) -> (Vec3, f32) {
    match light.kind {
        LightKind::Point => (light.position, light.radius * meshes_sphere_bound),
        LightKind::Spot { outer_angle, .. } => {
            let radial = cone_bound.0 * outer_angle.tan();
            (
                light.position,
                light.radius * (radial * radial + cone_bound.1 * cone_bound.1).sqrt(),
            )
        }
        LightKind::Directional { .. } => (Vec3::ZERO, f32::INFINITY),
    }
}

/// Chooses the passes for a light. Conservative: a volume whose bounding sphere could touch the
/// near plane (or contain the eye) is drawn as [`VolumeCase::Inside`].
pub fn classify(light: &Light, bound: (Vec3, f32), camera: &Camera, aspect: f32) -> VolumeCase {
    if !light.is_local() {
        return VolumeCase::FullScreen;
    }
    let (center, radius) = bound;
    if (center - camera.eye).length() <= radius + camera.near_corner_distance(aspect) {
        VolumeCase::Inside
    } else {
        VolumeCase::Outside
    }
}

/// Which pipeline a light draw uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightPipeline {
    /// Volume mesh, no colour writes.
    Stencil,
    /// Volume mesh, light shader.
    Volume,
    /// Full-screen triangle, light shader.
    FullScreen,
}

/// One draw of a light: a label, a pipeline and its full state.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LightDraw {
    pub label: &'static str,
    pub pipeline: LightPipeline,
    pub state: DrawState,
}

const NO_DEPTH_WRITE: bool = false;

/// The ordered draws of a light. Pure: the stencil logic of the pass lives here.
pub fn light_draws(case: VolumeCase, layout: &StencilLayout) -> Vec<LightDraw> {
    let culling = layout.culling_mask();
    match case {
        VolumeCase::Outside => vec![
            LightDraw {
                label: "setup",
                pipeline: LightPipeline::Stencil,
                state: DrawState {
                    cull: vk::CullModeFlags::FRONT,
                    depth_compare: Some(vk::CompareOp::LESS),
                    depth_write: NO_DEPTH_WRITE,
                    stencil: Some(StencilState::replace(culling, culling)),
                },
            },
            LightDraw {
                label: "shade",
                pipeline: LightPipeline::Volume,
                state: DrawState {
                    cull: vk::CullModeFlags::BACK,
                    depth_compare: Some(vk::CompareOp::LESS),
                    depth_write: NO_DEPTH_WRITE,
                    stencil: Some(StencilState::test_equal(0, culling)),
                },
            },
            LightDraw {
                label: "cleanup",
                pipeline: LightPipeline::Stencil,
                state: DrawState {
                    cull: vk::CullModeFlags::FRONT,
                    depth_compare: None,
                    depth_write: NO_DEPTH_WRITE,
                    stencil: Some(StencilState::replace(0, culling)),
                },
            },
        ],
        VolumeCase::Inside => vec![LightDraw {
            label: "shade-inside",
            pipeline: LightPipeline::Volume,
            state: DrawState {
                cull: vk::CullModeFlags::FRONT,
                depth_compare: Some(vk::CompareOp::GREATER),
                depth_write: NO_DEPTH_WRITE,
                stencil: None,
            },
        }],
        VolumeCase::FullScreen => vec![LightDraw {
            label: "shade-fullscreen",
            pipeline: LightPipeline::FullScreen,
            state: DrawState {
                cull: vk::CullModeFlags::NONE,
                depth_compare: Some(vk::CompareOp::GREATER),
                depth_write: NO_DEPTH_WRITE,
                stencil: None,
            },
        }],
    }
}

pub struct LightingPass<'a> {
    pub ctx: &'a Context,
    pub cmd: vk::CommandBuffer,
    pub lights: &'a [Light],
    pub camera: &'a Camera,
    pub meshes: &'a Meshes,
    pub pipelines: &'a Pipelines,
    pub pipeline_layout: vk::PipelineLayout,
    pub sets: [vk::DescriptorSet; 2],
    pub layout: &'a StencilLayout,
    pub extent: vk::Extent2D,
}

impl LightingPass<'_> {
    pub fn record(&self, targets: &mut Targets) {
        let (ctx, cmd) = (self.ctx, self.cmd);
        let d = &ctx.device;
        ctx.begin_label(cmd, "lighting");
        for image in targets.gbuffer.iter_mut() {
            transition(
                ctx,
                cmd,
                image,
                ImageAccess::FragmentSampled,
                Contents::Keep,
            );
        }
        transition(
            ctx,
            cmd,
            &mut targets.hdr,
            ImageAccess::ColorAttachment,
            Contents::Discard,
        );
        transition(
            ctx,
            cmd,
            &mut targets.depth_stencil,
            ImageAccess::DepthStencilAttachment,
            Contents::Keep,
        );
        let colors = [color_attachment(&targets.hdr, Load::Clear(CLEAR_BLACK))];
        let ds = depth_stencil_attachment(&targets.depth_stencil, Load::Keep);
        begin_rendering(ctx, cmd, self.extent, &colors, Some(&ds));
        unsafe {
            d.cmd_bind_descriptor_sets(
                cmd,
                vk::PipelineBindPoint::GRAPHICS,
                self.pipeline_layout,
                0,
                &self.sets,
                &[],
            );
        }
        let aspect = self.extent.width as f32 / self.extent.height as f32;
        for (index, light) in self.lights.iter().enumerate() {
            let bound = volume_bound(
                light,
                self.meshes.light_sphere_bound,
                self.meshes.light_cone_bound,
            );
            let case = classify(light, bound, self.camera, aspect);
            let mesh = match light.kind {
                LightKind::Spot { .. } => &self.meshes.light_cone,
                _ => &self.meshes.light_sphere,
            };
            ctx.begin_label(cmd, &format!("light-{index}-{case:?}"));
            let index = index as u32;
            unsafe {
                d.cmd_push_constants(
                    cmd,
                    self.pipeline_layout,
                    vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                    0,
                    &index.to_ne_bytes(),
                );
            }
            for draw in light_draws(case, self.layout) {
                ctx.begin_label(cmd, draw.label);
                let pipeline = match draw.pipeline {
                    LightPipeline::Stencil => self.pipelines.light_stencil,
                    LightPipeline::Volume => self.pipelines.light_volume,
                    LightPipeline::FullScreen => self.pipelines.light_fullscreen,
                };
                unsafe { d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, pipeline) };
                draw.state.apply(ctx, cmd);
                match draw.pipeline {
                    LightPipeline::FullScreen => unsafe { d.cmd_draw(cmd, 3, 1, 0, 0) },
                    _ => mesh.draw(ctx, cmd),
                }
                ctx.end_label(cmd);
            }
            ctx.end_label(cmd);
        }
        unsafe { d.cmd_end_rendering(cmd) };
        ctx.end_label(cmd);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn layout() -> StencilLayout {
        StencilLayout::new(2, 0).unwrap()
    }

    #[test]
    fn outside_passes_touch_only_the_culling_bit() {
        let draws = light_draws(VolumeCase::Outside, &layout());
        assert_eq!(
            draws.iter().map(|d| d.label).collect::<Vec<_>>(),
            ["setup", "shade", "cleanup"]
        );
        for d in &draws {
            let s = d.state.stencil.unwrap();
            assert_eq!(
                s.write_mask & !0x01,
                0,
                "{} writes more than the culling bit",
                d.label
            );
            assert!(!d.state.depth_write);
        }
        assert_eq!(
            draws[0].state.cull,
            vk::CullModeFlags::FRONT,
            "setup draws back faces"
        );
        assert_eq!(
            draws[1].state.cull,
            vk::CullModeFlags::BACK,
            "shade draws front faces"
        );
        assert_eq!(draws[1].state.stencil.unwrap().compare_mask, 0x01);
        assert_eq!(
            draws[2].state.stencil.unwrap().reference,
            0,
            "cleanup clears the bit"
        );
        assert_eq!(
            draws[2].state.depth_compare, None,
            "cleanup clears wherever setup could mark"
        );
    }

    #[test]
    fn inside_and_fullscreen_do_not_touch_stencil() {
        for case in [VolumeCase::Inside, VolumeCase::FullScreen] {
            for d in light_draws(case, &layout()) {
                assert_eq!(d.state.stencil, None);
                assert_eq!(d.state.depth_compare, Some(vk::CompareOp::GREATER));
            }
        }
    }

    #[test]
    fn classification_is_conservative_near_the_eye() {
        let scene = histencil_scene::embedded("default").unwrap();
        let camera = scene.camera;
        let mut light = Light::point(camera.eye + Vec3::new(0.0, 0.0, -5.0), 1.0, Vec3::ONE);
        assert_eq!(
            classify(&light, (light.position, 1.01), &camera, 1.0),
            VolumeCase::Outside
        );
        light.radius = 5.0;
        assert_eq!(
            classify(&light, (light.position, 5.05), &camera, 1.0),
            VolumeCase::Inside
        );
        // Eye outside by less than the near-plane corner distance: still drawn as inside.
        assert_eq!(
            classify(&light, (light.position, 4.95), &camera, 1.0),
            VolumeCase::Inside
        );
    }
}
