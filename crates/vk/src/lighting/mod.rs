//! The talk's lighting as a part an engine records into its own frame: [`DeferredLighting`]
//! records a [`FramePlan`] into the caller's command buffer, against the caller's G-buffer,
//! depth-stencil and HDR images ([`LightingTargets`]), with the camera and lights of that frame.
//! It submits nothing and waits for nothing; [`crate::Renderer`] lights its frames through it
//! too.
//!
//! Frames in flight: each of the `frames_in_flight` slots has its own uniform and light buffers
//! and descriptor sets, written when a frame is recorded into that slot. The caller cycles the
//! slots and, once its own fence says the GPU finished a slot's frame, says so
//! ([`DeferredLighting::slot_finished`]); a slot is recorded again, and the lighting resized or
//! destroyed, only then: histencil submits nothing and sees no fence, so it is told, and it
//! refuses ([`Error::InFlight`]) rather than rewrite what the GPU may still read.
//!
//! The G-buffer contract (`crates/vk/shaders/include/gbuffer_write.glsl` writes it, `gbuffer.glsl` reads
//! it): [`crate::GBUFFER_FORMATS`] in that order, each pixel's BRDF slot in the stencil's BRDF
//! field with the culling bit clear ([`gbuffer_stencil_reference`]), standard or reversed depth as
//! the [`ViewDesc`] says.

mod checks;
mod create;
mod frames;
pub mod hooks;
pub(crate) mod lut;
mod record_tiled;
mod stencil_check;

pub use checks::frame_inputs_problem;
use checks::{
    bad, bad_setup, check_desc, check_frame, check_usage, needs_hi_stencil, writes_hi_stencil,
    UsageNeeds,
};
pub use frames::{gbuffer_stencil_reference, LightingDesc, LightingFrame, TiledFrame};
pub use record_tiled::TILED_HDR_FORMATS;
pub use stencil_check::{StencilCheck, StencilReport};

use crate::gpu::access::LightingTargets;
use crate::gpu::device::context::Context;
use crate::gpu::device::descriptors::{write_sampled_images, write_storage_buffers};
use crate::gpu::device::error::{Error, Result};
use crate::gpu::device::resources::Buffer;
use crate::gpu::device::teardown::{free_or_retire, Destroy, DestroyResult, PendingSlots};
use crate::gpu::encoder::recording::Recording;
use crate::gpu::encoder::timing::{LightingBreakdown, SlotTimer};
use crate::gpu::frame::gpu_types::{FrameUniforms, GpuLight};
use crate::hi_stencil::{GpuHierarchy, HiStencilSurface};
use crate::lighting::hooks::HookSets;
use crate::passes::depth_id::DepthIdPass;
use crate::passes::light_passes::{Emulation, LightingPass};
use crate::passes::light_pipelines::{prepare_pipelines, BrdfSource, LightPipelines};
use crate::passes::light_volumes::LightVolumes;
use crate::passes::tiled::TileSide;
use crate::passes::tiled::TiledLighting;
use ash::vk;
use histencil_model::{FramePlan, Step, TileStats, ViewDesc};
use histencil_scene::Light;
use std::ops::Deref;

/// The per-frame-in-flight part: buffers the host writes at record time and the sets that point
/// at them and at the frame's G-buffer.
struct Slot {
    uniforms: Buffer,
    lights: Buffer,
    frame_set: vk::DescriptorSet,
    /// histencil's G-buffer set; null with an engine's decode hook.
    gbuffer_set: vk::DescriptorSet,
    timer: SlotTimer,
    /// The hi-stencil emulation's bookkeeping against the technique (`Emulation`).
    emulation: SlotTimer,
}

/// The lighting passes of the talk, recorded into an engine's frames.
///
/// `C` is how it holds its context: `&Context`, or `Arc<Context>` so that an engine's struct
/// owns it beside the context (as [`crate::AlphaLightmaps`] and [`crate::LutTables`] do).
///
/// What an engine writes per frame, after its own G-buffer pass and before its own post
/// passes (the whole engine: `examples/engine`):
///
/// ```no_run
/// use ash::vk;
/// use histencil_model::{
///     plan_frame, FlushPolicy, PlanInputs, PlanSettings, StencilLayout, TechniqueChoice, View,
///     ViewDesc,
/// };
/// use histencil_scene::Light;
/// use histencil_vk::{
///     Backend, BrdfSource, Context, DeferredLighting, HookSets, ImageRef, LightingFrame, LightingTargets,
/// };
///
/// /// `gbuffer`, `depth_stencil` and `hdr` carry the states the engine's barriers left.
/// fn light(
///     lighting: &mut DeferredLighting<&Context>,
///     cmd: vk::CommandBuffer,
///     frame_index: u64,
///     view: &ViewDesc,
///     lights: &[Light],
///     brdf_bounds: &[Vec<histencil_model::Aabb>],
///     images: (Vec<ImageRef>, ImageRef, ImageRef),
/// ) -> Result<LightingTargets, Box<dyn std::error::Error>> {
///     let layout: StencilLayout = lighting.desc().layout;
///     let shapes: Vec<_> = lights.iter().map(Light::shape).collect();
///     let inputs = PlanInputs {
///         lights: &shapes,
///         brdf_bounds,
///         view: &View::new(view)?,
///     };
///     let settings = PlanSettings {
///         technique: TechniqueChoice::Stencil,
///         caps: Backend::Native.platform().caps(),
///         flush: FlushPolicy::Auto,
///     };
///     let plan = plan_frame(&layout, &inputs, &settings)?;
///     let (gbuffer, depth_stencil, hdr) = images;
///     let mut targets = LightingTargets { gbuffer, depth_stencil, hdr };
///     let frame = LightingFrame {
///         slot: (frame_index % 2) as u32,
///         view,
///         lights,
///         plan: &plan,
///         clear_hdr: true,
///         timestamps: false,
///         brdf_source: BrdfSource::Formula,
///         tile_stats: false,
///         hook_sets: HookSets::default(),
///     };
///     // SAFETY: `cmd` is recording on the lighting's device and the images' states are true.
///     // (The engine's fence for this slot was waited on, and `slot_finished` said so, before:
///     // a slot still in flight is refused.)
///     unsafe { lighting.record(cmd, &frame, &mut targets)? };
///     Ok(targets) // each image's state now, for the engine's next barrier
/// }
/// ```
pub struct DeferredLighting<C: Deref<Target = Context>> {
    ctx: C,
    desc: LightingDesc,
    /// Frame, G-buffer, hi-stencil and LUT set layouts: sets 0 to 3 of every light pipeline
    /// (with an engine's decode hook, set 1 is the engine's layout and this one stays null).
    set_layouts: [vk::DescriptorSetLayout; 4],
    pipeline_layout: vk::PipelineLayout,
    pool: vk::DescriptorPool,
    hi_stencil_set: vk::DescriptorSet,
    lut_set: vk::DescriptorSet,
    /// The LUT set is written once tables exist (`set_lut_tables`); binding an unwritten set
    /// is invalid.
    lut_written: bool,
    slots: Vec<Slot>,
    hi_stencil: Option<HiStencilSurface>,
    volumes: Option<LightVolumes>,
    pipelines: LightPipelines,
    /// The tiled technique per tile side, made at its first frame with that side.
    tiled: Vec<(TileSide, TiledLighting)>,
    /// The depth-id technique per tile side, made at its first frame with that side.
    depth_id: Vec<(TileSide, DepthIdPass)>,
    /// The slots recorded into and not yet declared finished (`slot_finished`): their buffers,
    /// sets and stencil views belong to those frames.
    pending: PendingSlots,
    /// Set when a resize failed half way and undoing it failed too (an allocation, twice):
    /// its parts are at two extents, so every recording is refused until a resize succeeds.
    torn: Option<String>,
}

impl<C: Deref<Target = Context>> DeferredLighting<C> {
    /// Creates the pipeline layout, the light volumes, the hi-stencil emulation and every slot's
    /// buffers and sets. Light pipelines are made when a plan first needs them
    /// ([`DeferredLighting::prepare`]). A failure half way frees what was made.
    ///
    /// # Errors
    /// [`Error::BadSetup`] for a zero extent, a depth format without stencil, an HDR format the
    /// device cannot blend into, no frames in flight, too many BRDFs for the layout, or a
    /// depth-stencil format other than the one the context was lent with; Vulkan and allocation
    /// errors.
    pub fn new(ctx: C, desc: &LightingDesc) -> Result<Self> {
        check_desc(desc)?;
        // The light passes add light into the HDR target with blending: a format the device
        // cannot blend into would fail at the first pipeline (a validation error, not a refusal).
        let blend = vk::FormatFeatureFlags::COLOR_ATTACHMENT_BLEND;
        if !ctx.format_features(desc.hdr_format).contains(blend) {
            return Err(bad_setup(format!(
                "HDR format {:?}: the device cannot blend into it as a colour attachment, which \
                 the light passes do (Vulkan requires it of R16G16B16A16_SFLOAT)",
                desc.hdr_format
            )));
        }
        desc.hooks.check(&ctx)?;
        desc.hooks.check_ids(&desc.brdfs)?;
        if ctx.depth_stencil_named && desc.depth_stencil_format != ctx.depth_stencil_format {
            return Err(bad_setup(format!(
                "depth-stencil format {:?}, but the context was lent {:?} \
                 (BorrowedDevice::depth_stencil): name one format, or leave the context's None",
                desc.depth_stencil_format, ctx.depth_stencil_format
            )));
        }
        let mut this = Self {
            ctx,
            desc: desc.clone(),
            set_layouts: [vk::DescriptorSetLayout::null(); 4],
            pipeline_layout: vk::PipelineLayout::null(),
            pool: vk::DescriptorPool::null(),
            hi_stencil_set: vk::DescriptorSet::null(),
            lut_set: vk::DescriptorSet::null(),
            lut_written: false,
            slots: Vec::new(),
            pending: PendingSlots::new(
                desc.frames_in_flight,
                "DeferredLighting",
                "buffers, sets and stencil view",
            ),
            torn: None,
            hi_stencil: None,
            volumes: None,
            tiled: Vec::new(),
            depth_id: Vec::new(),
            pipelines: LightPipelines::new(
                vk::PipelineLayout::null(),
                desc.hooks.modules(),
                desc.hdr_format,
                desc.depth_stencil_format,
            ),
        };
        // On an error `this` drops, destroying what exists so far.
        this.create()?;
        Ok(this)
    }
}

impl<C: Deref<Target = Context>> DeferredLighting<C> {
    /// Makes the lighting fit targets of a new `extent`, keeping every pipeline (viewport and
    /// scissor are dynamic state; the tile side, not the extent, shapes the tiled kernels): the
    /// hi-stencil tile surface and the tiled technique's tile buffers are made anew, nothing
    /// else. A resize to the same extent does nothing. All or nothing: an extent past the
    /// device's limits is refused before anything is made, and a part that cannot be made
    /// (memory) undoes the parts already resized, so the lighting stays at its old extent.
    ///
    /// # Errors
    /// [`Error::BadSetup`] for a zero extent; [`Error::DeviceLimit`] for an extent whose images
    /// pass `maxImageDimension2D` or whose buffers pass `maxStorageBufferRange`;
    /// [`Error::InFlight`] while a slot recorded into is not declared finished
    /// ([`DeferredLighting::slot_finished`]: wait for your frames in flight first, as for any
    /// resize of your own targets); allocation errors. Should undoing fail as well (memory
    /// again), every recording is refused until a resize succeeds.
    pub fn resize(&mut self, extent: vk::Extent2D) -> Result<()> {
        self.pending.refuse_while_any("resize")?;
        if extent.width == 0 || extent.height == 0 {
            return Err(bad_setup(format!(
                "a {}x{} lighting extent",
                extent.width, extent.height
            )));
        }
        if extent == self.desc.extent && self.torn.is_none() {
            return Ok(());
        }
        let max = self.ctx.max_image_dimension;
        if extent.width > max || extent.height > max {
            return Err(Error::DeviceLimit(format!(
                "a {}x{} lighting extent is past this device's maxImageDimension2D ({max})",
                extent.width, extent.height
            )));
        }
        let old = self.desc.extent;
        if let Err(e) = self.resize_parts(extent) {
            // Each part resizes whole or not at all; put back those that did.
            if let Err(undo) = self.resize_parts(old) {
                self.torn = Some(format!(
                    "a resize to {}x{} failed ({e}), and so did undoing it ({undo})",
                    extent.width, extent.height
                ));
            }
            return Err(e);
        }
        self.desc.extent = extent;
        self.torn = None;
        Ok(())
    }

    /// Resizes every part made for an extent to `extent`; stops at the first that fails, which
    /// is left as it was (each part's own resize is all or nothing).
    fn resize_parts(&mut self, extent: vk::Extent2D) -> Result<()> {
        let ctx: &Context = &self.ctx;
        if self.desc.hi_stencil {
            let surface = self.hi_stencil.as_mut().expect("made with the lighting");
            if surface.extent() != extent {
                surface.resize(ctx, extent)?;
                let buffers = surface.light_set_buffers();
                write_storage_buffers(ctx, self.hi_stencil_set, &buffers);
            }
        }
        for (_, tiled) in &mut self.tiled {
            tiled.resize(ctx, extent)?;
        }
        for (_, depth_id) in &mut self.depth_id {
            depth_id.resize(ctx, extent)?;
        }
        Ok(())
    }

    /// Refuses a recording while a failed resize left the parts at two extents.
    fn refuse_if_torn(&self) -> Result<()> {
        match &self.torn {
            None => Ok(()),
            Some(why) => Err(Error::BadFrame(format!(
                "{why}: the lighting's parts are at two extents; resize it again before \
                 recording"
            ))),
        }
    }
}

impl<C: Deref<Target = Context>> DeferredLighting<C> {
    /// What this lighting was made for.
    pub fn desc(&self) -> &LightingDesc {
        &self.desc
    }

    /// Holds an engine's material rows ([`crate::BrdfParams::Materials`]) to this lighting:
    /// every material's BRDF must be one it shades ([`LightingDesc::brdfs`]). A material of
    /// another BRDF would get no light pass under the stencil technique and no tile class under
    /// tiled: its pixels unlit, with no error anywhere. Call it whenever the rows change.
    ///
    /// # Errors
    /// [`Error::BadSetup`] naming the first such material, its BRDF and the lighting's BRDFs.
    pub fn check_materials(&self, rows: &histencil_brdf::MaterialRows) -> Result<()> {
        let shaded = &self.desc.brdfs;
        let Some((index, brdf)) =
            (rows.materials().iter().enumerate()).find(|(_, m)| !shaded.contains(&m.id()))
        else {
            return Ok(());
        };
        let names: Vec<String> = shaded.iter().map(|b| format!("`{b}`")).collect();
        Err(bad_setup(format!(
            "material {index} is `{}`, which this lighting does not shade (it shades {}): its \
             pixels would come out unlit. Make the lighting with LightingDesc::brdfs = \
             MaterialRows::brdfs()",
            brdf.id(),
            names.join(", ")
        )))
    }

    /// Says the GPU has finished the frame last recorded into `slot`, so the slot may be
    /// recorded again and, once every slot is finished, the lighting resized or destroyed. An
    /// engine calls it after waiting for that frame's fence (or timeline value); a slot whose
    /// command buffer was recorded and never submitted (reset or freed instead) may be declared
    /// finished too. Declaring a slot never recorded, or twice, is harmless.
    ///
    /// # Errors
    /// [`Error::BadFrame`] for a slot past `frames_in_flight`.
    ///
    /// # Safety
    /// Every command buffer that recorded `slot` through this lighting has finished executing
    /// on the GPU, or will never be submitted: histencil rewrites that slot's buffers,
    /// descriptor sets and stencil view at its next recording, and frees them at a resize or
    /// destroy, trusting this.
    pub unsafe fn slot_finished(&mut self, slot: u32) -> Result<()> {
        self.pending.finished(slot)
    }

    /// Every slot finished at once, for histencil's own renderer after its device-wide wait.
    ///
    /// # Safety
    /// The GPU has finished every command buffer recorded through this object, or none of
    /// them will be submitted.
    pub(crate) unsafe fn all_finished(&mut self) {
        self.pending.clear();
    }

    /// Whether a slot is recorded into and not yet declared finished.
    pub fn in_flight(&self) -> bool {
        self.pending.any()
    }

    /// Creates every light pipeline `plan` uses, so the first frame that needs them does not
    /// compile them while recording.
    pub fn prepare(&mut self, plan: &FramePlan) -> Result<()> {
        self.prepare_for(plan, false, BrdfSource::Formula, false)
    }

    fn prepare_for(
        &mut self,
        plan: &FramePlan,
        count_stats: bool,
        source: BrdfSource,
        hierarchy: bool,
    ) -> Result<()> {
        let (ctx, brdfs) = (&*self.ctx, &self.desc.brdfs);
        let pipelines = &mut self.pipelines;
        prepare_pipelines(ctx, pipelines, plan, brdfs, count_stats, source, hierarchy)
    }

    /// Light pipelines created so far (kept across [`DeferredLighting::resize`]).
    pub fn pipeline_count(&self) -> usize {
        self.pipelines.count()
    }

    /// The tiled and depth-id techniques' pipelines created so far, over every tile side used
    /// (kept across [`DeferredLighting::resize`]).
    pub fn tiled_pipeline_count(&self) -> usize {
        let tiled = self.tiled.iter().map(|(_, t)| t.pipeline_count());
        let depth_id = self.depth_id.iter().map(|(_, p)| p.pipeline_count());
        tiled.chain(depth_id).sum()
    }

    /// Records `frame`'s lighting into `cmd` against `targets`, and leaves each target's state
    /// as the commands leave the image. Outside any render pass; binds its own pipelines and
    /// sets, sets the dynamic state it uses, and leaves the HDR and depth-stencil images
    /// attached-ready.
    ///
    /// # Errors
    /// [`Error::BadFrame`] when the frame does not fit this lighting (see [`LightingFrame`]), or
    /// the view's projection cannot be inverted per pixel; [`Error::InFlight`] when
    /// `frame.slot` was recorded and not declared finished since
    /// ([`DeferredLighting::slot_finished`]); pipeline creation errors. Nothing is recorded on
    /// an error.
    ///
    /// # Safety
    /// - `cmd` is in the recording state, outside any render pass, on a queue family with
    ///   graphics and compute (the context's own family fits), from the device of the context
    ///   this lighting was made with.
    /// - The images of `targets` are live, from that device, with the usages
    ///   [`LightingTargets`] lists, and their `state`s are true when `cmd` executes: the layout
    ///   each subresource is in, and the stages and accesses of the last commands before it that
    ///   touched it (`ImageState::UNDEFINED` discards contents, so not for the G-buffer or
    ///   depth-stencil).
    /// - What [`DeferredLighting::slot_finished`] was told is true (the slot itself is checked).
    /// - The context outlives `cmd`'s execution. The lighting need not: dropped while `slot` is
    ///   in flight, it leaves what the frame reads to the context ([`Context::free_retired`]).
    pub unsafe fn record(
        &mut self,
        cmd: vk::CommandBuffer,
        frame: &LightingFrame,
        targets: &mut LightingTargets,
    ) -> Result<()> {
        // SAFETY: the caller upholds this fn's # Safety, which is `record_emulating`'s; with
        // no hierarchy it needs nothing more.
        unsafe { self.record_emulating(cmd, frame, targets, None, None) }
    }

    /// [`DeferredLighting::record`], emulating `hierarchy`, the hierarchical stencil of an AMD
    /// GPU (`crate::hi_stencil::amd`), which needs [`LightingDesc::hi_stencil`]; through `outer`
    /// when given (the renderer's frame's recording of `cmd`, whose clock then times the pass
    /// [`names::LIGHTING`](crate::passes::names::LIGHTING)), else through a recording of its own
    /// of the engine's `cmd`, untimed.
    ///
    /// # Safety
    /// As [`DeferredLighting::record`]; with `outer`, that is `cmd`'s one recording, outside
    /// rendering.
    pub(crate) unsafe fn record_emulating(
        &mut self,
        cmd: vk::CommandBuffer,
        frame: &LightingFrame,
        targets: &mut LightingTargets,
        hierarchy: Option<GpuHierarchy>,
        outer: Option<&Recording>,
    ) -> Result<()> {
        let (count_stats, source) = (frame.tile_stats, frame.brdf_source);
        check_frame(&self.desc, frame, targets)?;
        let needs = UsageNeeds::light_passes(&self.desc, frame.plan, hierarchy.is_some());
        check_usage(targets, &needs)?;
        self.pending.refuse_slot(frame.slot, cmd)?;
        self.refuse_if_torn()?;
        if frame.plan.uses_depth_bounds() && !self.ctx.depth_bounds() {
            return Err(Error::BadFrame(
                "the plan confines lights to their depth ranges (FramePlan::with_depth_bounds), \
                 and this device has no depth bounds test enabled for histencil"
                    .into(),
            ));
        }
        if hierarchy.is_some() && !self.desc.hi_stencil {
            return Err(Error::Unsupported(
                "an AMD hierarchy's emulation from a lighting made without hi-stencil",
            ));
        }
        if count_stats && !self.desc.hi_stencil {
            return Err(Error::Unsupported(
                "hi-stencil statistics from a lighting made without hi-stencil",
            ));
        }
        // A call out of order, not a missing feature: the message says what to call first.
        if source == BrdfSource::Table && !self.lut_written {
            return Err(bad(
                "the LUT technique before its tables are set: call DeferredLighting::set_lut_tables \
                 (through C, histencil_lighting_set_lut_tables) first"
                    .into(),
            ));
        }
        self.prepare_for(frame.plan, count_stats, source, hierarchy.is_some())?;
        let inputs = (frame.view, frame.lights, &frame.hook_sets);
        let (frame_set, decode_set) = self.write_slot(frame.slot, inputs, targets)?;
        let ctx: &Context = &self.ctx;
        let slot = &mut self.slots[frame.slot as usize];
        let steps = frame.plan.steps.len() as u32;
        let name = "lighting-step-timestamps";
        slot.timer.prepare(ctx, name, frame.timestamps, steps)?;
        let name = "lighting-emulation-timestamps";
        let emulated = needs_hi_stencil(frame.plan) || hierarchy.is_some();
        let marks = Emulation::marks(frame.plan, hierarchy.as_ref());
        slot.emulation.prepare(ctx, name, emulated, marks)?;
        let mut sets = vec![frame_set, decode_set, self.hi_stencil_set];
        if source == BrdfSource::Table {
            sets.push(self.lut_set);
        }
        let hi_stencil = self.hi_stencil.as_mut().expect("made with the lighting");
        if writes_hi_stencil(frame.plan) || hierarchy.is_some() {
            hi_stencil.prepare_slot(ctx, frame.slot, &targets.depth_stencil)?;
        }
        let timer = slot.timer.active();
        let emulation = slot.emulation.active();
        self.pending.recorded(frame.slot, cmd);
        let record = |rec: &Recording| {
            let pass = LightingPass {
                rec,
                plan: frame.plan,
                lights: frame.lights,
                brdfs: &self.desc.brdfs,
                volumes: self.volumes.as_ref().expect("made with the lighting"),
                pipelines: &self.pipelines,
                pipeline_layout: self.pipeline_layout,
                sets: &sets,
                visibility_set: frame.hook_sets.visibility,
                brdf_source: source,
                extent: self.desc.extent,
                count_stats,
                clear_hdr: frame.clear_hdr,
                depth_sampled: self.desc.hooks.samples_depth(),
                slot: frame.slot,
                engine_hooks: !self.desc.hooks.is_builtin_decode(),
                hierarchy,
            };
            pass.record(targets, hi_stencil, timer, emulation)
        };
        // SAFETY: the caller's # Safety: `cmd` is recording on this context's device, on a queue
        // family with graphics and compute, outside any render pass; this call alone records
        // into it now, or `outer` is its recording (the renderer's).
        unsafe { Recording::through(ctx, cmd, outer, record) }
    }

    /// Of the last frame recorded into `slot`, once the GPU has finished it: the time the
    /// hi-stencil emulator spent on bookkeeping a console does not do (resetting its tile
    /// surface; after each hi-stencil write the split, the touch draw and the tile update; the
    /// copy at each flush), in milliseconds; the rest of the lighting is the platform's technique.
    /// `None` when that frame's plan used no hi-stencil (a native plan). Every frame with
    /// hi-stencil writes these timestamps, two per piece of bookkeeping, where rendering is
    /// split anyway. Waits for the query results.
    pub fn emulation_ms(&self, slot: u32) -> Result<Option<f64>> {
        match self
            .slots
            .get(slot as usize)
            .and_then(|s| s.emulation.last())
        {
            Some(t) => Ok(t.read(&self.ctx)?.group_ms(Emulation::BOOKKEEPING)),
            None => Ok(None),
        }
    }

    /// Writes `slot`'s uniforms from `view` and `lights`, and its G-buffer set from `targets`
    /// with histencil's decode; returns the frame set and the decode set (the engine's, with
    /// its hook).
    ///
    /// # Errors
    /// [`Error::BadFrame`] when the view's projection cannot be inverted per pixel; nothing
    /// is written then.
    fn write_slot(
        &mut self,
        slot: u32,
        (view, lights, hook_sets): (&ViewDesc, &[Light], &HookSets),
        targets: &LightingTargets,
    ) -> Result<(vk::DescriptorSet, vk::DescriptorSet)> {
        let e = self.desc.extent;
        let uniforms = FrameUniforms::from_view(view, e.width, e.height, lights.len() as u32)
            .map_err(|p| bad(p.to_string()))?;
        let ctx: &Context = &self.ctx;
        let slot = &mut self.slots[slot as usize];
        slot.uniforms.write(bytemuck::bytes_of(&uniforms));
        let gpu_lights: Vec<GpuLight> = lights.iter().map(GpuLight::new).collect();
        slot.lights.write(bytemuck::cast_slice(&gpu_lights));
        let decode_set = match hook_sets.decode {
            Some(set) => set,
            None => {
                let views: Vec<vk::ImageView> = targets.gbuffer.iter().map(|g| g.view).collect();
                write_sampled_images(ctx, slot.gbuffer_set, &views);
                slot.gbuffer_set
            }
        };
        Ok((slot.frame_set, decode_set))
    }

    /// The per-step GPU times of the last frame recorded into `slot` with timestamps, once the
    /// GPU has finished it (`None` when that frame had none). Waits for the query results.
    pub fn step_timings(&self, slot: u32) -> Result<Option<LightingBreakdown>> {
        match self.slots.get(slot as usize).and_then(|s| s.timer.last()) {
            Some(t) => Ok(Some(t.read(&self.ctx)?)),
            None => Ok(None),
        }
    }

    /// The hi-stencil statistics of the last frame recorded with
    /// [`LightingFrame::tile_stats`], read once the GPU has finished it; `flushes` from that
    /// frame's `plan`. One set of counters for all slots: a caller counts a frame, waits for it,
    /// then reads, before the next counting frame. `None` for a lighting made without
    /// [`LightingDesc::hi_stencil`], which has no counters (and refuses counting frames).
    pub fn tile_stats(&self, plan: &FramePlan) -> Option<TileStats> {
        if !self.desc.hi_stencil {
            return None;
        }
        let hi = self.hi_stencil.as_ref()?;
        Some(TileStats {
            flushes: plan
                .steps
                .iter()
                .filter(|s| matches!(s, Step::FlushHiStencil))
                .count() as u64,
            ..hi.read_stats()
        })
    }

    /// Frees everything now, once the engine's fences say the GPU is done and
    /// [`DeferredLighting::slot_finished`] was told so (dropping it while a slot is in flight
    /// leaves its objects to the context instead, freed with it or at
    /// [`Context::free_retired`]).
    ///
    /// # Errors
    /// [`crate::StillInFlight`] while a slot is not declared finished: it holds the lighting, whole
    /// and unchanged, and the error naming the slots (dropping it leaves its objects to the context until
    /// the GPU is known to be done: `Context::free_retired`).
    pub fn destroy(self) -> DestroyResult<Self> {
        PendingSlots::destroy(self, |l| &l.pending)
    }

    /// Points the LUT technique at `tables` (one per material, in the order of the G-buffer's
    /// material indices; [`crate::LutTables::new`]) for the frames recorded with
    /// [`BrdfSource::Table`] after this.
    ///
    /// # Safety
    /// `tables` outlive every command buffer recorded with [`BrdfSource::Table`] after this
    /// call, until the GPU has finished them; no command buffer that reads earlier tables is
    /// still pending (the set is rewritten in place).
    pub unsafe fn set_lut_tables(
        &mut self,
        tables: &crate::LutTables<impl Deref<Target = Context>>,
    ) {
        write_storage_buffers(&self.ctx, self.lut_set, &tables.buffers());
        self.lut_written = true;
    }

    pub(crate) fn pipeline_layout(&self) -> vk::PipelineLayout {
        self.pipeline_layout
    }

    pub(crate) fn volumes(&self) -> &LightVolumes {
        self.volumes.as_ref().expect("made with the lighting")
    }
}

impl<C: Deref<Target = Context>> Drop for DeferredLighting<C> {
    /// Frees everything, also after a creation that failed half way. While a slot is in flight
    /// (recorded, not declared finished: its command buffer may not even be submitted yet) the
    /// objects go to the context instead, freed once the GPU is known to be done
    /// ([`Context::free_retired`], or the context's drop): dropping never waits, and a frame
    /// recorded before the drop reads live objects when it runs.
    fn drop(&mut self) {
        let null_pipelines = LightPipelines::new(
            vk::PipelineLayout::null(),
            self.desc.hooks.modules(),
            self.desc.hdr_format,
            self.desc.depth_stencil_format,
        );
        let mut pipelines = std::mem::replace(&mut self.pipelines, null_pipelines);
        let mut tiled = std::mem::take(&mut self.tiled);
        let mut depth_id = std::mem::take(&mut self.depth_id);
        let mut slots = std::mem::take(&mut self.slots);
        let mut hi_stencil = self.hi_stencil.take();
        let mut volumes = self.volumes.take();
        let (pool, pipeline_layout, set_layouts) =
            (self.pool, self.pipeline_layout, self.set_layouts);
        let free = move |ctx: &Context| {
            pipelines.destroy(ctx);
            for (_, t) in &mut tiled {
                t.destroy(ctx);
            }
            for (_, p) in &mut depth_id {
                p.destroy(ctx);
            }
            for slot in &mut slots {
                slot.uniforms.destroy(ctx);
                slot.lights.destroy(ctx);
                slot.timer.destroy(ctx);
                slot.emulation.destroy(ctx);
            }
            if let Some(h) = hi_stencil.as_mut() {
                h.destroy(ctx);
            }
            if let Some(v) = volumes.as_mut() {
                v.destroy(ctx);
            }
            let d = &ctx.device;
            // SAFETY: the GPU is done with the pool, the layouts and the sets: no slot is
            // pending (`slot_finished`'s # Safety), or this runs from the context's retired
            // list once the device is idle or `free_retired`'s caller says so; the pipelines
            // made with the layout are destroyed. Each handle was made from `ctx.device` by
            // `create`, or is still null after a creation that failed half way (a no-op).
            unsafe {
                d.destroy_descriptor_pool(pool, None);
                d.destroy_pipeline_layout(pipeline_layout, None);
                // The null ones (set 1 with an engine's decode hook) are no-ops.
                for l in set_layouts {
                    d.destroy_descriptor_set_layout(l, None);
                }
            }
        };
        free_or_retire(&self.ctx, self.pending.any(), free);
    }
}
