//! What a renderer frame is planned with: the camera as a view in the frame's depth convention,
//! the planner's inputs from the scene, and the uniforms of the mesh and alpha passes.

use super::Renderer;
use crate::gpu::device::error::Result;
use crate::gpu::frame::gpu_types::FrameUniforms;
use crate::renderer::technique::{Backend, FrameDesc, MixedTiles, Technique, TileSide};
use histencil_model::{
    plan_frame, DepthConvention, FarPlane, FrameChoice, FramePlan, LightShape, Perspective,
    PlanError, PlanInputs, View, ViewDesc,
};

impl Renderer<'_> {
    /// The lighting plan of a frame, from histencil-model's planner on the scene's plain inputs:
    /// each light that touches an object and that the camera can see, classified against the
    /// camera, with the BRDF slots it touches ([`FramePlan::lights`] says which scene light each
    /// planned light is).
    pub fn plan(&self, technique: Technique) -> Result<FramePlan> {
        self.plan_in(technique, &self.view_desc())
    }

    /// What a frame of `technique` records: the adaptive technique on the native backend lights
    /// the whole frame tiled (the device's tiles, [`crate::TileSide::for_context`]; mixed tiles
    /// per BRDF), or by depth ids with the same tiles' light lists, where its costs predict
    /// that surely cheaper than its plan ([`histencil_model::CostModel::frame_choice`]; never
    /// with the talk's costs, which have no tiled figures); on an emulated backend it keeps the
    /// platform's plan, whose behaviour it is there to show. Every other technique is itself.
    pub fn resolve(&self, technique: Technique) -> Result<Technique> {
        self.resolve_in(technique, &self.view_desc())
            .map(|(t, _)| t)
    }

    /// [`Renderer::resolve`] with `view`, and the plan the frame records unless it is tiled.
    pub(super) fn resolve_in(
        &self,
        technique: Technique,
        view: &ViewDesc,
    ) -> Result<(Technique, FramePlan)> {
        let plan = self.plan_in(technique, view)?;
        if let Technique::Adaptive {
            backend: Backend::Native,
            ..
        } = technique
        {
            let side = TileSide::for_context(self.ctx);
            let costs = self.cost_model(Backend::Native);
            let chosen = match costs.frame_choice(&plan, self.brdfs.len()) {
                FrameChoice::Planned => technique,
                FrameChoice::Tiled => Technique::Tiled {
                    mixed: MixedTiles::PerBrdf,
                    side,
                },
                FrameChoice::DepthId => Technique::DepthId { side },
            };
            return Ok((chosen, plan));
        }
        Ok((technique, plan))
    }

    pub(super) fn plan_in(&self, technique: Technique, view: &ViewDesc) -> Result<FramePlan> {
        let settings = technique.plan_settings(|backend| self.cost_model(backend));
        let view = View::new(view).map_err(PlanError::from)?;
        let shapes: Vec<LightShape> = self.scene.lights.iter().map(|l| l.shape()).collect();
        let mut brdf_bounds = self.scene.brdf_bounds(&self.brdfs);
        // A scene with no opaque surface (only translucent ones) still has a one-slot stencil
        // layout, whose slot has no surfaces: one empty list, as the planner asks of every slot.
        brdf_bounds.resize(self.stencil_layout.brdfs_in_use() as usize, Vec::new());
        let inputs = PlanInputs {
            lights: &shapes,
            brdf_bounds: &brdf_bounds,
            view: &view,
        };
        let plan = plan_frame(&self.stencil_layout, &inputs, &settings)?;
        // Where the device has the depth bounds test, every light's shade passes are confined
        // to its depth range: the same image, fewer pixels shaded for nothing.
        Ok(if self.ctx.depth_bounds() {
            plan.with_depth_bounds()
        } else {
            plan
        })
    }

    /// The camera as the planner and the lighting take it, with standard depth and its own far
    /// plane.
    pub(super) fn view_desc(&self) -> ViewDesc {
        let aspect = self.extent.width as f32 / self.extent.height as f32;
        self.scene.camera.view_desc(aspect)
    }

    /// The camera with depth stored as `depth` says, its far plane at infinity if asked.
    pub(super) fn view_desc_in(&self, depth: DepthConvention, infinite_far: bool) -> ViewDesc {
        if depth == DepthConvention::Standard && !infinite_far {
            return self.view_desc();
        }
        let c = &self.scene.camera;
        Perspective {
            eye: c.eye.into(),
            target: c.target.into(),
            up: c.up.into(),
            fov_y_radians: c.fov_y_radians,
            aspect: self.extent.width as f32 / self.extent.height as f32,
            near: c.near,
            far: if infinite_far {
                FarPlane::Infinite
            } else {
                FarPlane::Finite(c.far)
            },
            depth,
        }
        .desc()
    }

    /// The view of the frame `desc` (its depth convention and far plane), written into the
    /// frame uniforms that the mesh passes, the alpha pass and the simulator's captured light
    /// volumes project with.
    pub(super) fn frame_view(&mut self, desc: &FrameDesc) -> Result<ViewDesc> {
        let view = self.view_desc_in(desc.depth, desc.infinite_far);
        self.frame_uniforms
            .write(bytemuck::bytes_of(&self.uniforms(&view)?));
        Ok(view)
    }

    /// The mesh and alpha passes' uniforms for `view`: the camera's own (the forward reference's
    /// eye and rays stay as they always were), with the projection and far depth of `view`.
    pub(super) fn uniforms(&self, view: &ViewDesc) -> Result<FrameUniforms> {
        let (w, h) = (self.extent.width, self.extent.height);
        let lights = self.scene.lights.len() as u32;
        let camera = FrameUniforms::new(&self.scene.camera, w, h, lights);
        if *view == self.view_desc() {
            return Ok(camera);
        }
        let projected = FrameUniforms::from_view(view, w, h, lights)
            .map_err(|p| crate::Error::BadFrame(p.to_string()))?;
        Ok(FrameUniforms {
            proj: projected.proj,
            view_proj: projected.view_proj,
            settings: projected.settings,
            ..camera
        })
    }
}
