//! The renderer: owns a scene's GPU resources and records / submits whole frames. This file
//! holds what it owns and how it is made and configured; `frame.rs` the order of a frame's
//! passes, `simulator.rs` what the CPU simulator is given.

mod frame;
mod simulator;

use crate::alpha::AlphaLighting;
use crate::context::Context;
use crate::deferred_lighting::{DeferredLighting, LightingDesc};
use crate::descriptors::{DescriptorTargets, Descriptors};
use crate::error::{Result, VkCall};
use crate::gpu_types::{FrameUniforms, GpuLight};
use crate::lut::LutTables;
use crate::meshes::Meshes;
use crate::pipelines::{PipelineLayouts, Pipelines, TargetFormats};
use crate::readback::{FrameImages, ReadbackBuffers};
use crate::resources::Buffer;
use crate::targets::{check_extent, Targets, GBUFFER_FORMATS, HDR_FORMAT, LDR_FORMAT};
use crate::technique::{Backend, Technique};
use crate::timing::{FrameTimings, Timestamps};
use ash::vk;
use histencil_brdf::lut::Lut;
use histencil_brdf::{Brdf, BrdfId};
use histencil_model::{
    plan_frame, CostModel, DepthConvention, FarPlane, FramePlan, LightShape, Perspective,
    PlanError, PlanInputs, StencilBits, StencilLayout, TalkFigures, TileStats, View, ViewDesc,
};
use histencil_scene::Scene;

/// The LUT technique's table resolution until [`Renderer::set_lut_resolution`] says otherwise:
/// the `brdf-report` tables put the broad lobes within about 1e-3 of their formula at 32
/// points per axis (the sharp ones need more, see the README), at 384 KiB per 3D table.
pub const DEFAULT_LUT_RESOLUTION: u32 = 32;

/// The most materials the G-buffer can index: integers are exact in its f16 alpha up to here.
const MAX_MATERIALS: usize = 2048;

/// The distinct BRDF materials of `scene` in first-use order (the LUT technique's tables) and
/// each object's index among them.
fn distinct_materials(scene: &Scene) -> (Vec<Brdf>, Vec<u32>) {
    let mut materials: Vec<Brdf> = Vec::new();
    let indices = scene
        .objects
        .iter()
        .map(|o| {
            let brdf = o.material.brdf;
            let index = materials
                .iter()
                .position(|m| *m == brdf)
                .unwrap_or_else(|| {
                    materials.push(brdf);
                    materials.len() - 1
                });
            index as u32
        })
        .collect();
    (materials, indices)
}

/// The talk gives no fixed cost per draw; the default cost model assumes this one.
const ASSUMED_DRAW_OVERHEAD_MS: f64 = 0.005;

/// The stencil slot of BRDF `id`: its index among the BRDFs in use.
fn slot_of(brdfs: &[BrdfId], id: BrdfId) -> u32 {
    brdfs
        .iter()
        .position(|b| *b == id)
        .expect("brdfs_in_use lists every object's BRDF") as u32
}

/// A rendered frame: its GPU timings, the images asked for, and the hi-stencil statistics when
/// [`crate::FrameDesc::tile_stats`] asks for them (deferred techniques only).
pub struct Frame {
    pub timings: FrameTimings,
    pub images: FrameImages,
    pub tile_stats: Option<TileStats>,
}

/// A scene ready to render at one resolution.
pub struct Renderer<'c> {
    ctx: &'c Context,
    scene: Scene,
    stencil_layout: StencilLayout,
    /// The BRDFs in use; a BRDF's index here is its stencil slot.
    brdfs: Vec<BrdfId>,
    /// Each object's BRDF slot.
    object_slots: Vec<u32>,
    /// The distinct BRDF materials (one LUT table each) and each object's index among them.
    materials: Vec<Brdf>,
    object_materials: Vec<u32>,
    lut_resolution: u32,
    /// Baked when the LUT technique first renders at `lut_resolution`.
    lut_tables: Option<LutTables>,
    /// Lightmap region side for every entity; `None`: from screen coverage.
    lightmap_side: Option<u32>,
    /// Created at the first frame of a scene with alpha entities (and again when the lightmap
    /// resolution changes).
    alpha: Option<AlphaLighting<'c>>,
    /// The lighting passes, as an engine records them, into this renderer's targets.
    lighting: DeferredLighting<'c>,
    /// The adaptive technique's costs; `None`: fitted to the talk's figures for the backend.
    cost_model: Option<CostModel>,
    extent: vk::Extent2D,
    targets: Targets,
    meshes: Meshes,
    frame_uniforms: Buffer,
    lights: Buffer,
    descriptors: Descriptors,
    pipelines: Pipelines,
    command_pool: vk::CommandPool,
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
    timestamps: Timestamps,
    readback: ReadbackBuffers,
}

impl<'c> Renderer<'c> {
    /// Validates the scene and the resolution, then builds everything a frame needs, with the
    /// talk's stencil layout (culling bit 0, BRDF bits above it).
    pub fn new(ctx: &'c Context, scene: Scene, width: u32, height: u32) -> Result<Self> {
        Self::with_stencil_bits(ctx, scene, width, height, None)
    }

    /// As [`Renderer::new`], with the culling bit and the BRDF field where an engine wants them
    /// (`None`: the talk's layout).
    ///
    /// # Errors
    /// [`crate::Error::Layout`] when the scene's BRDFs do not fit at those positions, besides the
    /// errors of [`Renderer::new`].
    pub fn with_stencil_bits(
        ctx: &'c Context,
        mut scene: Scene,
        width: u32,
        height: u32,
        bits: Option<StencilBits>,
    ) -> Result<Self> {
        // The resolution first: a scene built for a zero-sized view (a lab wall) would otherwise
        // take the blame for it.
        let extent = check_extent(ctx, width, height)?;
        scene.validate()?;
        scene.normalise_lights();
        let brdfs: Vec<BrdfId> = scene.brdfs_in_use();
        let brdf_count = brdfs.len().max(1) as u32;
        let stencil_layout = match bits {
            None => StencilLayout::new(brdf_count, 0)?,
            Some(bits) => StencilLayout::with_positions(brdf_count, bits)?,
        };
        let object_slots = scene
            .objects
            .iter()
            .map(|o| slot_of(&brdfs, o.material.brdf.id()))
            .collect();
        let (materials, object_materials) = distinct_materials(&scene);

        let lighting = DeferredLighting::new(
            ctx,
            &LightingDesc {
                layout: stencil_layout,
                brdfs: brdfs.clone(),
                extent,
                depth_stencil_format: ctx.depth_stencil_format,
                hdr_format: HDR_FORMAT,
                frames_in_flight: 1,
                max_lights: scene.lights.len() as u32,
                hi_stencil: true,
            },
        )?;
        let targets = Targets::new(ctx, extent)?;
        let meshes = Meshes::new(ctx, &scene.meshes)?;
        let uniforms = FrameUniforms::new(&scene.camera, width, height, scene.lights.len() as u32);
        let frame_uniforms = Buffer::with_data(
            ctx,
            "frame-uniforms",
            vk::BufferUsageFlags::UNIFORM_BUFFER,
            bytemuck::bytes_of(&uniforms),
        )?;
        let gpu_lights: Vec<GpuLight> = scene.lights.iter().map(GpuLight::new).collect();
        let lights = Buffer::with_data(
            ctx,
            "scene-lights",
            vk::BufferUsageFlags::STORAGE_BUFFER,
            bytemuck::cast_slice(&gpu_lights),
        )?;
        let descriptors = Descriptors::new(
            ctx,
            &DescriptorTargets {
                frame_uniforms: frame_uniforms.handle,
                lights: lights.handle,
                hdr_view: targets.hdr.view,
            },
        )?;
        let pipelines = Pipelines::new(
            ctx,
            &PipelineLayouts {
                mesh: descriptors.mesh_pipeline_layout,
                lighting: lighting.pipeline_layout(),
                tonemap: descriptors.tonemap_pipeline_layout,
            },
            &TargetFormats {
                gbuffer: GBUFFER_FORMATS,
                hdr: HDR_FORMAT,
                ldr: LDR_FORMAT,
                depth_stencil: ctx.depth_stencil_format,
            },
        )?;
        let pool_info = vk::CommandPoolCreateInfo::default().queue_family_index(ctx.queue_family);
        let command_pool = unsafe { ctx.device.create_command_pool(&pool_info, None) }
            .call("vkCreateCommandPool")?;
        ctx.name(command_pool, "frame-command-pool");
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(command_pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        let cmd = unsafe { ctx.device.allocate_command_buffers(&alloc) }
            .call("vkAllocateCommandBuffers")?[0];
        ctx.name(cmd, "frame-commands");
        let fence = unsafe {
            ctx.device
                .create_fence(&vk::FenceCreateInfo::default(), None)
        }
        .call("vkCreateFence")?;
        ctx.name(fence, "frame-fence");
        let timestamps = Timestamps::new(ctx)?;
        let readback = ReadbackBuffers::new(ctx, extent)?;
        Ok(Self {
            ctx,
            scene,
            stencil_layout,
            brdfs,
            object_slots,
            materials,
            object_materials,
            lut_resolution: DEFAULT_LUT_RESOLUTION,
            lut_tables: None,
            lightmap_side: None,
            alpha: None,
            lighting,
            cost_model: None,
            extent,
            targets,
            meshes,
            frame_uniforms,
            lights,
            descriptors,
            pipelines,
            command_pool,
            cmd,
            fence,
            timestamps,
            readback,
        })
    }

    /// The scene being rendered.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    pub fn stencil_layout(&self) -> &StencilLayout {
        &self.stencil_layout
    }

    /// The BRDFs in use, in stencil slot order.
    pub fn brdfs(&self) -> &[BrdfId] {
        &self.brdfs
    }

    /// The stencil value each object's G-buffer draw writes with `preserved_pattern` in the
    /// preserved bits ([`crate::FrameDesc::preserved_pattern`]).
    pub fn object_stencil_values(&self, preserved_pattern: u8) -> Vec<u8> {
        self.object_slots
            .iter()
            .map(|s| {
                crate::passes::geometry::gbuffer_stencil(
                    &self.stencil_layout,
                    *s,
                    preserved_pattern,
                )
                .map_or(0, |f| f.reference)
            })
            .collect()
    }

    /// The costs [`Technique::Adaptive`] chooses with, e.g. calibrated on this device. Without
    /// them it uses the talk's measurements fitted by [`CostModel::from_talk`] (360 figures for
    /// the 360-like backend, PS3 figures otherwise) with an assumed 5 us per extra draw.
    pub fn set_cost_model(&mut self, costs: Option<CostModel>) {
        self.cost_model = costs;
    }

    /// The costs the adaptive technique uses with `backend`.
    pub fn cost_model(&self, backend: Backend) -> CostModel {
        self.cost_model.unwrap_or_else(|| {
            let figures = match backend {
                Backend::X360 { .. } => TalkFigures::X360,
                Backend::Ps3 | Backend::Native => TalkFigures::PS3,
            };
            CostModel::from_talk(&figures, ASSUMED_DRAW_OVERHEAD_MS)
        })
    }

    /// Sets the LUT technique's table resolution (grid points per axis); the tables are baked
    /// again on the next LUT frame.
    ///
    /// # Errors
    /// [`crate::Error::Lut`] outside `2..=`[`Lut::MAX_RESOLUTION`].
    pub fn set_lut_resolution(&mut self, resolution: u32) -> Result<()> {
        Lut::check_resolution(resolution)?;
        if resolution != self.lut_resolution {
            if let Some(mut old) = self.lut_tables.take() {
                old.destroy(self.ctx);
            }
            self.lut_resolution = resolution;
        }
        Ok(())
    }

    pub fn lut_resolution(&self) -> u32 {
        self.lut_resolution
    }

    /// The LUT technique's tables at the current resolution, baked and uploaded on first use
    /// (by table index: the scene's distinct BRDF materials in first-use order).
    ///
    /// # Errors
    /// [`crate::Error::TooManyMaterials`] beyond what the G-buffer indexes, and those of
    /// [`LutTables::new`].
    pub fn lut_tables(&mut self) -> Result<&LutTables> {
        if self.lut_tables.is_none() {
            if self.materials.len() > MAX_MATERIALS {
                return Err(crate::Error::TooManyMaterials {
                    count: self.materials.len(),
                    max: MAX_MATERIALS,
                });
            }
            let tables = LutTables::new(self.ctx, &self.materials, self.lut_resolution)?;
            // SAFETY: the renderer keeps the tables until it drops them or bakes new ones, and
            // it waits for every frame it submits.
            unsafe { self.lighting.set_lut_tables(&tables) };
            self.lut_tables = Some(tables);
        }
        Ok(self.lut_tables.as_ref().expect("baked above"))
    }

    /// Gives every alpha entity's lightmap `side` texels a side (a ribbon `side` texels along
    /// it; dust keeps one texel per mote); `None` sizes them from screen coverage
    /// (`histencil_alpha::side_for_coverage`). The atlas is laid out again on the next frame.
    ///
    /// # Errors
    /// [`crate::Error::Lightmap`] for a side outside 2..=[`histencil_alpha::MAX_FORCED_SIDE`]
    /// (the renderer keeps its setting).
    pub fn set_lightmap_resolution(&mut self, side: Option<u32>) -> Result<()> {
        if let Some(s) = side {
            histencil_alpha::check_forced_side(s)?;
        }
        if side != self.lightmap_side {
            if let Some(mut old) = self.alpha.take() {
                old.destroy(self.ctx);
            }
            self.lightmap_side = side;
        }
        Ok(())
    }

    /// The alpha entities' lightmap layout (atlas size, each entity's region), planned on first
    /// use; `None` for a scene without alpha entities.
    ///
    /// # Errors
    /// [`crate::Error::Lightmap`] when the entities do not fit the atlas.
    pub fn lightmap_layout(&mut self) -> Result<Option<&histencil_alpha::LightmapLayout>> {
        Ok(self.alpha_lighting()?.map(|a| a.layout()))
    }

    /// Each alpha entity's lightmap parameters (slices, side) and the error estimate behind
    /// them, in `histencil_alpha::entities` order; empty for a scene without alpha entities.
    ///
    /// # Errors
    /// [`crate::Error::Lightmap`] when the entities do not fit the atlas.
    pub fn lightmap_parameters(&mut self) -> Result<Vec<histencil_alpha::Parameters>> {
        Ok(self
            .alpha_lighting()?
            .map_or_else(Vec::new, |a| a.parameters().to_vec()))
    }

    /// Lightmap draws per frame: one per (entity, light that reaches its bounds).
    pub fn lightmap_draws(&mut self) -> Result<usize> {
        Ok(self.alpha_lighting()?.map_or(0, |a| a.lightmap_draws()))
    }

    fn alpha_lighting(&mut self) -> Result<Option<&mut AlphaLighting<'c>>> {
        if self.scene.alpha_entity_count() == 0 {
            return Ok(None);
        }
        if self.alpha.is_none() {
            self.alpha = Some(AlphaLighting::new(
                self.ctx,
                &self.scene,
                self.extent,
                self.lightmap_side,
                self.descriptors.frame_layout,
            )?);
        }
        Ok(self.alpha.as_mut())
    }

    /// Light pipelines created so far.
    pub fn light_pipeline_count(&self) -> usize {
        self.lighting.pipeline_count()
    }

    /// The lighting plan of a frame, from histencil-model's planner on the scene's plain inputs:
    /// each light that touches an object and that the camera can see, classified against the
    /// camera, with the BRDF slots it touches ([`FramePlan::lights`] says which scene light each
    /// planned light is).
    pub fn plan(&self, technique: Technique) -> Result<FramePlan> {
        self.plan_in(technique, &self.view_desc())
    }

    fn plan_in(&self, technique: Technique, view: &ViewDesc) -> Result<FramePlan> {
        let Some(settings) = technique.plan_settings(|backend| self.cost_model(backend)) else {
            return Ok(FramePlan::empty(view.depth));
        };
        let view = View::new(view).map_err(PlanError::from)?;
        let shapes: Vec<LightShape> = self.scene.lights.iter().map(|l| l.shape()).collect();
        let brdf_bounds = self.scene.brdf_bounds(&self.brdfs);
        let inputs = PlanInputs {
            lights: &shapes,
            brdf_bounds: &brdf_bounds,
            view: &view,
        };
        Ok(plan_frame(&self.stencil_layout, &inputs, &settings)?)
    }

    /// The camera as the planner and the lighting take it, with standard depth and its own far
    /// plane.
    fn view_desc(&self) -> ViewDesc {
        let aspect = self.extent.width as f32 / self.extent.height as f32;
        self.scene.camera.view_desc(aspect)
    }

    /// The camera with depth stored as `depth` says, its far plane at infinity if asked.
    fn view_desc_in(&self, depth: DepthConvention, infinite_far: bool) -> ViewDesc {
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

    /// The mesh and alpha passes' uniforms for `view`: the camera's own (the forward reference's
    /// eye and rays stay as they always were), with the projection and far depth of `view`.
    fn uniforms(&self, view: &ViewDesc) -> Result<FrameUniforms> {
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

impl Drop for Renderer<'_> {
    fn drop(&mut self) {
        let ctx = self.ctx;
        unsafe {
            let _ = ctx.device.device_wait_idle();
            ctx.device.destroy_fence(self.fence, None);
            ctx.device.destroy_command_pool(self.command_pool, None);
        }
        self.timestamps.destroy(ctx);
        self.readback.destroy(ctx);
        self.pipelines.destroy(ctx);
        if let Some(t) = self.lut_tables.as_mut() {
            t.destroy(ctx);
        }
        if let Some(a) = self.alpha.as_mut() {
            a.destroy(ctx);
        }
        self.descriptors.destroy(ctx);
        self.lights.destroy(ctx);
        self.frame_uniforms.destroy(ctx);
        self.meshes.destroy(ctx);
        self.targets.destroy(ctx);
    }
}
