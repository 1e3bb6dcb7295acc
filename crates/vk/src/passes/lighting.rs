//! The deferred lighting pass, driven by histencil-model's frame plan: every light's passes
//! (setup, per-BRDF mask and shade, cleanup, as `plan_light` derives them for the platform
//! backend), with the state of each draw translated by [`crate::state::apply`].
//!
//! This module only decides how each light is classified and which BRDFs it touches, and records
//! the plan; the stencil logic lives in the model, where the CPU simulator checks it.
//!
//! Hi-stencil steps (the tile surface written by mask passes and its flushes) are recorded as
//! labelled no-ops for now: the per-pixel stencil test alone is exact, so images are correct,
//! and the tile emulation only adds culling statistics.

use super::{begin_hdr_rendering, Load};
use crate::access::{transition, Contents, ImageAccess};
use crate::context::Context;
use crate::error::{Error, Result};
use crate::meshes::Meshes;
use crate::pipelines::{create_pipeline, PipelineDesc, VertexInput};
use crate::shaders;
use crate::state::apply;
use crate::targets::Targets;
use crate::timing::StepTimer;
use ash::vk;
use histencil_brdf::BrdfId;
use histencil_model::{FramePlan, Geometry, LightCase, PassKind, Shader, Step};
use histencil_scene::{Camera, Light, LightKind};
use std::collections::HashMap;

/// The radius of a sphere containing `light`'s volume mesh, as a multiple of its range.
pub fn mesh_bound(light: &Light, meshes: &Meshes) -> f32 {
    match light.kind {
        LightKind::Spot { outer_angle, .. } => {
            let (radial, axial) = meshes.light_cone_bound;
            let radial = radial * outer_angle.tan();
            (radial * radial + axial * axial).sqrt()
        }
        _ => meshes.light_sphere_bound,
    }
}

/// How a light is drawn (see `histencil_model::LightCase`). Conservative where it cannot be
/// sure: [`LightCase::CrossesNear`]'s plan is correct for any volume, the others are faster
/// special cases taken only when they certainly apply.
pub fn classify(light: &Light, mesh_bound: f32, camera: &Camera, aspect: f32) -> LightCase {
    if !light.is_local() {
        return LightCase::FullScreen;
    }
    let near = camera.near_corner_distance(aspect);
    let distance = (light.position - camera.eye).length();
    let viewer_inside_sphere = distance + near < light.radius;
    match light.kind {
        // The sphere mesh contains the range sphere: eye and near plane are inside the mesh.
        LightKind::Point if viewer_inside_sphere => LightCase::ViewerInside,
        _ if distance <= light.radius * mesh_bound + near => LightCase::CrossesNear,
        _ => LightCase::Outside,
    }
}

/// The shader of a light pipeline: none (stencil and hi-stencil only), one BRDF, or the
/// branching uber shader.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LightShader {
    None,
    Brdf(BrdfId),
    Branching,
}

/// Light pipelines, created the first time a plan needs them: a scene pays only for the BRDFs it
/// uses, and a technique only for its own shaders.
pub struct LightPipelines {
    layout: vk::PipelineLayout,
    hdr_format: vk::Format,
    depth_stencil_format: vk::Format,
    pipelines: HashMap<(Geometry, LightShader), vk::Pipeline>,
}

/// `SHADED_BRDF` of `deferred_light.frag` for the branching shader.
const BRANCH_ON_GBUFFER: u32 = u32::MAX;

impl LightPipelines {
    pub fn new(
        layout: vk::PipelineLayout,
        hdr_format: vk::Format,
        depth_stencil_format: vk::Format,
    ) -> Self {
        Self {
            layout,
            hdr_format,
            depth_stencil_format,
            pipelines: HashMap::new(),
        }
    }

    /// Creates the pipeline for `key` unless it exists.
    pub fn prepare(&mut self, ctx: &Context, key: (Geometry, LightShader)) -> Result<()> {
        if self.pipelines.contains_key(&key) {
            return Ok(());
        }
        let (geometry, shader) = key;
        let (vertex, vertex_input) = match geometry {
            Geometry::Volume => (
                ("light_volume.vert", shaders::LIGHT_VOLUME_VERT),
                VertexInput::Position,
            ),
            Geometry::FullScreen => (
                ("fullscreen.vert", shaders::FULLSCREEN_VERT),
                VertexInput::None,
            ),
        };
        let specialization = match shader {
            LightShader::None => None,
            LightShader::Brdf(id) => Some(id.index()),
            LightShader::Branching => Some(BRANCH_ON_GBUFFER),
        };
        let shader_name = match shader {
            LightShader::None => "stencil".to_owned(),
            LightShader::Brdf(id) => id.name().to_owned(),
            LightShader::Branching => "branching".to_owned(),
        };
        let geometry_name = match geometry {
            Geometry::Volume => "volume",
            Geometry::FullScreen => "fullscreen",
        };
        let hdr = [self.hdr_format];
        let pipeline = create_pipeline(
            ctx,
            &PipelineDesc {
                name: &format!("light-{geometry_name}-{shader_name}-pipeline"),
                vertex,
                fragment: specialization
                    .map(|_| ("deferred_light.frag", shaders::DEFERRED_LIGHT_FRAG)),
                layout: self.layout,
                vertex_input,
                color_formats: &hdr,
                color_writes: shader != LightShader::None,
                additive_blend: shader != LightShader::None,
                depth_stencil_format: self.depth_stencil_format,
                // Back faces beyond the far plane clamp to depth 1, behind every surface.
                depth_clamp: geometry == Geometry::Volume,
                specialization,
            },
        )?;
        self.pipelines.insert(key, pipeline);
        Ok(())
    }

    fn get(&self, key: (Geometry, LightShader)) -> vk::Pipeline {
        self.pipelines[&key]
    }

    /// How many pipelines exist: what the scene and the techniques used so far cost.
    pub fn count(&self) -> usize {
        self.pipelines.len()
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for (_, p) in self.pipelines.drain() {
            unsafe { ctx.device.destroy_pipeline(p, None) };
        }
    }
}

/// The pipeline key of a planned pass. `brdfs` maps stencil slots to BRDFs.
pub fn pipeline_key(
    kind: PassKind,
    geometry: Geometry,
    brdfs: &[BrdfId],
) -> (Geometry, LightShader) {
    let shader = match kind {
        PassKind::Shade(Shader::Brdf(slot)) => LightShader::Brdf(brdfs[slot as usize]),
        PassKind::Shade(Shader::Branching) => LightShader::Branching,
        PassKind::ZeroPreserved | PassKind::Setup | PassKind::Mask(_) | PassKind::Cleanup => {
            LightShader::None
        }
    };
    (geometry, shader)
}

/// The talk's pass group of a planned pass, for timings: `setup`, `mask-<brdf>`, `shade-<brdf>`
/// (`-branching` for the uber shader), `cleanup`, `zero-preserved`.
pub fn pass_group(kind: PassKind, brdfs: &[BrdfId]) -> String {
    let shader = |s: Shader| match s {
        Shader::Brdf(slot) => brdfs[slot as usize].name(),
        Shader::Branching => "branching",
    };
    match kind {
        PassKind::ZeroPreserved => "zero-preserved".into(),
        PassKind::Setup => "setup".into(),
        PassKind::Mask(s) => format!("mask-{}", shader(s)),
        PassKind::Shade(s) => format!("shade-{}", shader(s)),
        PassKind::Cleanup => "cleanup".into(),
    }
}

/// Creates every pipeline `plan` uses.
pub fn prepare_pipelines(
    ctx: &Context,
    pipelines: &mut LightPipelines,
    plan: &FramePlan,
    brdfs: &[BrdfId],
) -> Result<()> {
    for pass in plan.passes() {
        pipelines.prepare(ctx, pipeline_key(pass.kind, pass.geometry, brdfs))?;
    }
    Ok(())
}

pub struct LightingPass<'a> {
    pub ctx: &'a Context,
    pub cmd: vk::CommandBuffer,
    pub plan: &'a FramePlan,
    /// The scene light each planned light index stands for.
    pub light_indices: &'a [u32],
    pub lights: &'a [Light],
    pub brdfs: &'a [BrdfId],
    pub meshes: &'a Meshes,
    pub pipelines: &'a LightPipelines,
    pub pipeline_layout: vk::PipelineLayout,
    pub sets: [vk::DescriptorSet; 2],
    pub extent: vk::Extent2D,
}

impl LightingPass<'_> {
    /// Records the plan; with `timer`, a timestamp after every step.
    pub(crate) fn record(
        &self,
        targets: &mut Targets,
        mut timer: Option<&mut StepTimer>,
    ) -> Result<()> {
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
        if let Some(t) = timer.as_deref_mut() {
            t.reset(ctx, cmd);
        }
        begin_hdr_rendering(ctx, cmd, targets, self.extent, Load::Keep);
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
        if let Some(t) = timer.as_deref_mut() {
            t.start(ctx, cmd);
        }
        let mut current_light = None;
        for step in &self.plan.steps {
            match step {
                Step::Pass { light, pass } => {
                    if current_light != Some(*light) {
                        if current_light.is_some() {
                            ctx.end_label(cmd);
                        }
                        current_light = Some(*light);
                        self.begin_light(*light);
                    }
                    let scene_light = self.light_indices[*light] as usize;
                    ctx.begin_label(cmd, &pass.label());
                    let key = pipeline_key(pass.kind, pass.geometry, self.brdfs);
                    unsafe {
                        d.cmd_bind_pipeline(
                            cmd,
                            vk::PipelineBindPoint::GRAPHICS,
                            self.pipelines.get(key),
                        )
                    };
                    apply(ctx, cmd, &pass.state);
                    match pass.geometry {
                        Geometry::FullScreen => unsafe { d.cmd_draw(cmd, 3, 1, 0, 0) },
                        Geometry::Volume => match self.lights[scene_light].kind {
                            LightKind::Spot { .. } => self.meshes.light_cone.draw(ctx, cmd),
                            _ => self.meshes.light_sphere.draw(ctx, cmd),
                        },
                    }
                    ctx.end_label(cmd);
                    if let Some(t) = timer.as_deref_mut() {
                        let group = pass_group(pass.kind, self.brdfs);
                        t.mark(ctx, cmd, group, Some(scene_light as u32));
                    }
                }
                Step::FlushHiStencil => {
                    ctx.begin_label(cmd, "flush-hi-stencil");
                    ctx.end_label(cmd);
                    if let Some(t) = timer.as_deref_mut() {
                        t.mark(ctx, cmd, "flush".into(), None);
                    }
                }
                Step::SavePreserved { .. } | Step::RestorePreserved { .. } => {
                    return Err(Error::Unsupported(
                        "saving and restoring preserved stencil bits on the GPU",
                    ));
                }
            }
        }
        if current_light.is_some() {
            ctx.end_label(cmd);
        }
        unsafe { d.cmd_end_rendering(cmd) };
        ctx.end_label(cmd);
        Ok(())
    }

    /// Opens the label of planned light `light` and pushes its scene index.
    fn begin_light(&self, light: usize) {
        let (ctx, cmd) = (self.ctx, self.cmd);
        let index = self.light_indices[light];
        ctx.begin_label(cmd, &format!("light-{index}"));
        unsafe {
            ctx.device.cmd_push_constants(
                cmd,
                self.pipeline_layout,
                vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                0,
                &index.to_ne_bytes(),
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn classification_is_conservative_near_the_eye() {
        let scene = histencil_scene::embedded("default").unwrap();
        let camera = scene.camera;
        let bound = 1.01;
        let mut light = Light::point(camera.eye + Vec3::new(0.0, 0.0, -5.0), 1.0, Vec3::ONE);
        assert_eq!(classify(&light, bound, &camera, 1.0), LightCase::Outside);
        light.radius = 4.95;
        assert_eq!(
            classify(&light, bound, &camera, 1.0),
            LightCase::CrossesNear
        );
        light.radius = 5.05;
        // Eye inside the range sphere, but the near plane may poke out of it.
        assert_eq!(
            classify(&light, bound, &camera, 1.0),
            LightCase::CrossesNear
        );
        light.radius = 5.5;
        assert_eq!(
            classify(&light, bound, &camera, 1.0),
            LightCase::ViewerInside
        );
        light.kind = LightKind::Directional {
            direction: Vec3::NEG_Y,
        };
        assert_eq!(classify(&light, bound, &camera, 1.0), LightCase::FullScreen);
    }

    #[test]
    fn passes_map_to_the_shaders_of_their_brdfs() {
        let brdfs = [BrdfId::Lambert, BrdfId::Ggx];
        assert_eq!(
            pipeline_key(PassKind::Shade(Shader::Brdf(1)), Geometry::Volume, &brdfs),
            (Geometry::Volume, LightShader::Brdf(BrdfId::Ggx))
        );
        assert_eq!(
            pipeline_key(
                PassKind::Mask(Shader::Brdf(1)),
                Geometry::FullScreen,
                &brdfs
            ),
            (Geometry::FullScreen, LightShader::None)
        );
    }
}
