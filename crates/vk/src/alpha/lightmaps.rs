//! The talk's lightmaps for an engine's alpha entities, recorded into its frames:
//! [`AlphaLightmaps`] lights each entity's region of the caller's lightmap atlas with every light
//! that reaches it (one additive draw per pair, with the deferred pass's light code), in the
//! caller's command buffer. The engine plans the regions with
//! [`histencil_alpha::plan_regions`] and samples the atlas from its own alpha shaders through
//! `crates/vk/shaders/include/lightmap_sample.glsl`, reading each entity's record from
//! [`AlphaLightmaps::entity_buffer`].
//!
//! Frames in flight work as in [`crate::DeferredLighting`]: each slot has its own buffers and
//! sets, rewritten when a frame is recorded into it (the buffers grow when a frame needs more),
//! and a slot is recorded again, or the lightmaps destroyed, only once the engine said its last
//! frame finished ([`AlphaLightmaps::slot_finished`]; [`Error::InFlight`] otherwise).

#[path = "lightmap_create.rs"]
mod create;

use super::gpu::{frame_records, AlphaDrawPush, FrameRecords};
use super::lightmap_checks::{bad, check_direction, check_frame};
use crate::gpu::access::ImageRef;
use crate::gpu::device::context::Context;
use crate::gpu::device::descriptors::{
    binding, create_pipeline_layout, create_set_layout, write_frame_set, write_storage_buffers,
    BindingDesc, BindingKind, FRAME_SET, GRAPHICS_STAGES,
};
use crate::gpu::device::error::{Error, Result, VkCall};
use crate::gpu::device::pipelines::{create_pipeline, Blend, PipelineDesc, VertexInput};
use crate::gpu::device::resources::Buffer;
use crate::gpu::device::teardown::{free_or_retire, DestroyResult, PendingSlots};
use crate::gpu::encoder::recording::Recording;
use crate::gpu::encoder::timing::{LightmapTimings, SlotTimer};
use crate::gpu::frame::attachments::{begin_all_cleared, CLEAR_BLACK};
use crate::gpu::frame::gpu_types::{FrameUniforms, GpuLight};
use crate::gpu::frame::state::FULLSCREEN;
use crate::shaders;
use ash::vk;
use gpu_allocator::MemoryLocation;
use histencil_alpha::AlphaEntity;
use histencil_alpha::{LightmapLayout, Region, Viewer};
use histencil_model::ViewDesc;
use histencil_scene::Light;
use std::ops::Deref;

/// Set 1 of the alpha pipelines (include/alpha.glsl): entity records, dust and ribbon points,
/// each entity's light list, and the objects' baked probes.
pub(crate) const ALPHA_SET: &[BindingDesc] = &[
    binding(0, BindingKind::StorageBuffer, ""),
    binding(1, BindingKind::StorageBuffer, ""),
    binding(2, BindingKind::StorageBuffer, ""),
    binding(3, BindingKind::StorageBuffer, ""),
];

/// What an [`AlphaLightmaps`] is made for: fixed for its lifetime.
#[derive(Clone, Copy, Debug)]
pub struct AlphaLightmapsDesc {
    /// The lightmap atlas's format: a colour format the device blends into (HDR radiance;
    /// `R16G16B16A16_SFLOAT` as histencil's own).
    pub atlas_format: vk::Format,
    /// How many frames the caller records before it waits for the oldest (at least 1).
    pub frames_in_flight: u32,
    /// With a format, [`AlphaLightmaps::record_directional`] also lights a direction map of
    /// this format (four channels, blendable, as the atlas: `R16G16B16A16_SFLOAT` as
    /// histencil's own); `None` makes only plain lightmaps.
    pub direction_format: Option<vk::Format>,
}

/// One frame's lightmaps.
#[derive(Clone, Copy, Debug)]
pub struct LightmapFrame<'a> {
    /// Which frame-in-flight slot's buffers and sets this frame uses (`< frames_in_flight`).
    pub slot: u32,
    /// The camera: particle probe frames face it, and probes are lit towards it.
    pub view: &'a ViewDesc,
    /// The frame's lights; each entity is lit by those whose range reaches its bounds.
    pub lights: &'a [Light],
    /// The entities to light, in the order their records are written
    /// ([`AlphaLightmaps::entity_buffer`]).
    pub entities: &'a [AlphaEntity<'a>],
    /// The entities' regions, from [`histencil_alpha::plan_entities`] (or
    /// [`histencil_alpha::plan_regions`] on their descriptions), in the same order.
    pub layout: &'a LightmapLayout,
    /// Write a GPU timestamp after the clear and after each entity's draws
    /// ([`AlphaLightmaps::timings`]). Opt-in: on some drivers a timestamp between draws
    /// serialises them.
    pub timestamps: bool,
}

struct Slot {
    uniforms: Buffer,
    lights: Buffer,
    /// Entity records, points, light list, probes: `ALPHA_SET` bindings 0 to 3.
    storage: [Buffer; 4],
    frame_set: vk::DescriptorSet,
    alpha_set: vk::DescriptorSet,
    /// Per entity, the lights the last frame in this slot draws into its region.
    entity_lights: Vec<Vec<u32>>,
    /// Timestamps of the last frame in this slot, when it asked for them.
    timer: SlotTimer,
}

const STORAGE_NAMES: [&str; 4] = [
    "alpha-entities",
    "alpha-points",
    "alpha-entity-lights",
    "alpha-probes",
];

/// Per-entity lightmaps for translucent objects and particle systems, recorded into an engine's
/// frames.
///
/// Per frame, after the engine planned its entities' regions:
///
/// ```no_run
/// use ash::vk;
/// use histencil_alpha::{plan_entities, ChoiceSettings, Viewer};
/// use histencil_model::ViewDesc;
/// use histencil_scene::Light;
/// use histencil_vk::{AlphaEntity, AlphaLightmaps, Context, ImageRef, LightmapFrame};
///
/// fn lightmaps(
///     lightmaps: &mut AlphaLightmaps<&Context>,
///     cmd: vk::CommandBuffer,
///     slot: u32,
///     view: &ViewDesc,
///     lights: &[Light],
///     entities: &[AlphaEntity],
///     atlas: &mut ImageRef,
/// ) -> Result<(), Box<dyn std::error::Error>> {
///     // Each entity's slices and texels from the CPU error estimate, then its region.
///     let viewer = Viewer::from_view(view).ok_or("a view without a camera")?;
///     let settings = ChoiceSettings::default();
///     let plan = plan_entities(entities, &viewer, lights, 720, atlas.extent.width, &settings)?;
///     let layout = plan.layout;
///     let frame = LightmapFrame { slot, view, lights, entities, layout: &layout, timestamps: false };
///     // SAFETY: `cmd` records on the lightmaps' device outside any render pass, and the atlas
///     // state and usage are true. (The slot is checked: the engine said `slot_finished(slot)`
///     // once its fence for the slot's last frame was signalled.)
///     unsafe { lightmaps.record(cmd, &frame, atlas)? };
///     // The engine's alpha shaders read `lightmaps.entity_buffer(slot)` and the atlas, once
///     // its barrier takes the atlas from `atlas.state` to a shader read.
///     Ok(())
/// }
/// ```
pub struct AlphaLightmaps<C: Deref<Target = Context>> {
    ctx: C,
    desc: AlphaLightmapsDesc,
    /// The lightmap shaders: histencil's, or compiled for a BRDF set.
    modules: &'static crate::BrdfModules,
    /// Frame and alpha set layouts: sets 0 and 1 of the lightmap pass (and of histencil's alpha
    /// pass).
    set_layouts: [vk::DescriptorSetLayout; 2],
    pipeline_layout: vk::PipelineLayout,
    pipeline: vk::Pipeline,
    /// Lights the atlas with irradiance and the direction map (lightmap_directional.frag),
    /// when the desc has a direction format.
    directional_pipeline: vk::Pipeline,
    pool: vk::DescriptorPool,
    slots: Vec<Slot>,
    /// The slots recorded into and not yet declared finished (`slot_finished`).
    pending: PendingSlots,
}

impl<C: Deref<Target = Context>> AlphaLightmaps<C> {
    /// Creates the lightmap pipeline and every slot's buffers and sets. A failure half way
    /// frees what was made.
    ///
    /// # Errors
    /// [`Error::BadSetup`] for no frames in flight or a depth-stencil atlas format; Vulkan and
    /// allocation errors.
    pub fn new(ctx: C, desc: &AlphaLightmapsDesc) -> Result<Self> {
        Self::with_modules(ctx, desc, crate::BrdfModules::builtin())
    }

    /// As [`AlphaLightmaps::new`], lighting with the lightmap shaders of `modules` (a BRDF set's).
    pub fn with_modules(
        ctx: C,
        desc: &AlphaLightmapsDesc,
        modules: &'static crate::BrdfModules,
    ) -> Result<Self> {
        let bad = |message: String| Error::BadSetup(message);
        if desc.frames_in_flight == 0 {
            return Err(bad("frames_in_flight must be at least 1".into()));
        }
        for (what, format) in [
            ("atlas", Some(desc.atlas_format)),
            ("direction map", desc.direction_format),
        ] {
            if let Some(format) = format {
                if crate::gpu::access::aspect_of(format) != vk::ImageAspectFlags::COLOR {
                    return Err(bad(format!(
                        "{what} format {format:?} is not a colour format"
                    )));
                }
            }
        }
        let mut this = Self {
            ctx,
            desc: *desc,
            modules,
            set_layouts: [vk::DescriptorSetLayout::null(); 2],
            pipeline_layout: vk::PipelineLayout::null(),
            pipeline: vk::Pipeline::null(),
            directional_pipeline: vk::Pipeline::null(),
            pool: vk::DescriptorPool::null(),
            slots: Vec::new(),
            pending: PendingSlots::new(desc.frames_in_flight, "AlphaLightmaps", "buffers and sets"),
        };
        // On an error `this` drops, destroying what exists so far.
        this.create()?;
        Ok(this)
    }

    /// The shaders it lights with, and the BRDF set they evaluate.
    pub fn modules(&self) -> &'static crate::BrdfModules {
        self.modules
    }

    /// Frees everything now, once its own fences say the GPU is done and
    /// [`Self::slot_finished`] was told so (dropping it while a slot is in flight leaves its
    /// objects to the context instead, freed with it or at `Context::free_retired`). Every draw of yours
    /// that read an [`Self::entity_buffer`] must be finished too (in the same frames, as a rule).
    ///
    /// # Errors
    /// [`crate::StillInFlight`] while a slot is not declared finished: it holds the lightmaps, whole,
    /// and the error naming the slots (dropping it leaves its objects to the context until
    /// the GPU is known to be done: `Context::free_retired`).
    pub fn destroy(self) -> DestroyResult<Self> {
        PendingSlots::destroy(self, |l| &l.pending)
    }

    /// Says the GPU has finished the frame last recorded into `slot` (and your draws that read
    /// its [`Self::entity_buffer`]), so the slot may be recorded again and, once every slot is,
    /// the lightmaps destroyed without a wait. A slot recorded and never submitted may be
    /// declared finished too; declaring one never recorded, or twice, is harmless.
    ///
    /// # Errors
    /// [`Error::BadFrame`] for a slot past `frames_in_flight`.
    ///
    /// # Safety
    /// Every command buffer that recorded `slot` through these lightmaps, or read its entity
    /// buffer, has finished executing on the GPU, or will never be submitted: the next
    /// recording rewrites (and may replace) that slot's buffers and sets, trusting this.
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

    /// What these lightmaps were made for.
    pub fn desc(&self) -> &AlphaLightmapsDesc {
        &self.desc
    }

    /// The entity records of the last frame recorded into `slot`
    /// ([`crate::AlphaEntityRecord`], in entity order): what an engine's alpha shader binds as
    /// the `AlphaEntity` array of `alpha_entity.glsl` (a storage buffer) to sample the atlas.
    /// Recording into `slot` again may replace the buffer when it grows, so bind it after.
    pub fn entity_buffer(&self, slot: u32) -> Option<vk::Buffer> {
        self.slots.get(slot as usize).map(|s| s.storage[0].handle)
    }

    /// The GPU times of the last frame recorded into `slot`, once the GPU has finished it:
    /// `None` when that frame asked for no timestamps. Waits for the query results.
    ///
    /// # Errors
    /// Vulkan errors reading the queries.
    pub fn timings(&self, slot: u32) -> Result<Option<LightmapTimings>> {
        match self.slots.get(slot as usize).and_then(|s| s.timer.last()) {
            Some(timer) => Ok(Some(timer.read_lightmaps(&self.ctx)?)),
            None => Ok(None),
        }
    }

    /// Lightmap draws the last frame recorded into `slot` made: one per (entity, light that
    /// reaches its bounds).
    pub fn draws(&self, slot: u32) -> usize {
        self.slots
            .get(slot as usize)
            .map_or(0, |s| s.entity_lights.iter().map(Vec::len).sum())
    }

    /// Lights every entity's region of `atlas` for `frame`, after clearing the whole atlas to
    /// black, and leaves `atlas.state` as a colour attachment just written.
    ///
    /// # Errors
    /// [`Error::BadFrame`] when the frame does not fit: a slot outside the range, entities that
    /// [`AlphaEntity::problem`] refuses or that do not match the layout's regions, an atlas of
    /// another format or smaller than the layout, a view without an invertible camera. Nothing
    /// is recorded on an error.
    ///
    /// # Safety
    /// - `cmd` is in the recording state, outside any render pass, on a queue family with
    ///   graphics, from the device of the context these lightmaps were made with.
    /// - `atlas` is live, from that device, its `usage` is what it was created with (which
    ///   must hold `COLOR_ATTACHMENT`; checked), and its `state` is true when `cmd` executes.
    /// - What [`Self::slot_finished`] was told is true (the slot itself is checked:
    ///   [`Error::InFlight`] for one recorded and not declared finished since).
    pub unsafe fn record(
        &mut self,
        cmd: vk::CommandBuffer,
        frame: &LightmapFrame,
        atlas: &mut ImageRef,
    ) -> Result<()> {
        self.write_frame(cmd, frame, atlas)?;
        // SAFETY: this fn's # Safety: `cmd` is recording on the lightmaps' device, on a graphics
        // queue family, outside any render pass; this call alone records into it now.
        unsafe { self.record_pass(cmd, (frame.slot, frame.layout), atlas, None, None) };
        Ok(())
    }

    /// Lights every entity's region of `atlas` with the irradiance at each probe (the sum of
    /// `incident * N.L` over the lights in front of its normal; no BRDF), and of `direction` with
    /// the irradiance-weighted sum of their directions (xyz: the sum of `w L`, w: the sum of `w`,
    /// `w` the irradiance's luminance), after clearing both to black;
    /// leaves both states as colour attachments just written. The engine's alpha shader reads
    /// both at the same coordinates (`lightmap_sample.glsl`: `lightmap_direction`) and evaluates
    /// its own BRDF with its own normal and view along the dominant direction: what plain
    /// lightmaps cannot do for normal-mapped or sharply specular entities, at the price of one
    /// direction for all the lights reaching a texel.
    ///
    /// # Errors
    /// As [`Self::record`]; also [`Error::BadFrame`] when these lightmaps were made without a
    /// direction format, or `direction` differs from it or from the atlas's extent.
    ///
    /// # Safety
    /// As [`Self::record`], for `direction` as for `atlas`.
    pub unsafe fn record_directional(
        &mut self,
        cmd: vk::CommandBuffer,
        frame: &LightmapFrame,
        atlas: &mut ImageRef,
        direction: &mut ImageRef,
    ) -> Result<()> {
        check_direction(&self.desc, atlas, direction)?;
        self.write_frame(cmd, frame, atlas)?;
        // SAFETY: as in `record`, whose # Safety this fn's is.
        unsafe {
            self.record_pass(
                cmd,
                (frame.slot, frame.layout),
                atlas,
                Some(direction),
                None,
            )
        };
        Ok(())
    }

    /// Checks `frame` (to be recorded into `cmd`) and writes its records, lights and uniforms
    /// into its slot.
    pub(crate) fn write_frame(
        &mut self,
        cmd: vk::CommandBuffer,
        frame: &LightmapFrame,
        atlas: &ImageRef,
    ) -> Result<()> {
        check_frame(&self.desc, frame, atlas, &self.modules.set)?;
        self.pending.refuse_slot(frame.slot, cmd)?;
        let viewer = Viewer::from_view(frame.view)
            .ok_or_else(|| bad("the view's world-to-view matrix cannot be inverted".into()))?;
        let e = atlas.extent;
        let uniforms =
            FrameUniforms::from_view(frame.view, e.width, e.height, frame.lights.len() as u32)
                .map_err(|p| bad(p.to_string()))?;
        let records = frame_records(frame.entities, &frame.layout.regions, &viewer, frame.lights);
        let ctx: &Context = &self.ctx;
        let slot = &mut self.slots[frame.slot as usize];
        let gpu_lights: Vec<GpuLight> = frame.lights.iter().map(GpuLight::new).collect();
        let FrameRecords {
            records,
            points,
            probes,
            light_list,
            entity_lights,
        } = records;
        super::lightmap_checks::check_probe_bytes(ctx, probes.len())?;
        let bytes: [&[u8]; 4] = [
            bytemuck::cast_slice(&records),
            bytemuck::cast_slice(&points),
            bytemuck::cast_slice(&light_list),
            bytemuck::cast_slice(&probes),
        ];
        let mut grown = fit(
            ctx,
            &mut slot.lights,
            "lightmap-lights",
            frame.slot,
            gpu_lights.len() * size_of::<GpuLight>(),
        )?;
        if grown {
            write_frame_set(
                ctx,
                slot.frame_set,
                slot.uniforms.handle,
                slot.lights.handle,
            );
        }
        grown = false;
        for ((buffer, name), data) in slot.storage.iter_mut().zip(STORAGE_NAMES).zip(bytes) {
            grown |= fit(ctx, buffer, name, frame.slot, data.len())?;
        }
        if grown {
            write_storage_buffers(
                ctx,
                slot.alpha_set,
                &slot.storage.each_ref().map(|b| b.handle),
            );
        }
        slot.uniforms.write(bytemuck::bytes_of(&uniforms));
        slot.lights.write(bytemuck::cast_slice(&gpu_lights));
        for (buffer, data) in slot.storage.iter_mut().zip(bytes) {
            buffer.write(data);
        }
        // A clear mark, then one mark per entity at most.
        let steps = frame.entities.len() as u32 + 1;
        let name = "lightmap-timestamps";
        slot.timer.prepare(ctx, name, frame.timestamps, steps)?;
        slot.entity_lights = entity_lights;
        Ok(())
    }

    /// Records the lightmap pass of the frame last written into `slot`: clears `atlas` (and
    /// `direction`, which makes it the directional pass), then one additive draw per (entity,
    /// light that reaches it) over the entity's region. Through `outer` when given (the
    /// renderer's frame's recording of `cmd`, whose clock then times the pass
    /// [`names::ALPHA_LIGHTMAPS`](crate::passes::names::ALPHA_LIGHTMAPS)), else through a
    /// recording of its own of the engine's `cmd`, untimed.
    ///
    /// # Safety
    /// As [`Recording::new`]: `cmd` is recording on this context's device, on a graphics queue
    /// family, outside any render pass, and only this call records into it meanwhile; with
    /// `outer`, that is `cmd`'s one recording, outside rendering.
    pub(crate) unsafe fn record_pass(
        &mut self,
        cmd: vk::CommandBuffer,
        (slot, layout): (u32, &LightmapLayout),
        atlas: &mut ImageRef,
        direction: Option<&mut ImageRef>,
        outer: Option<&Recording>,
    ) {
        let ctx: &Context = &self.ctx;
        self.pending.recorded(slot, cmd);
        let slot = &mut self.slots[slot as usize];
        let record = |rec: &Recording| {
            // Queries are reset outside rendering, as Vulkan requires.
            let mut timer = slot.timer.active();
            if let Some(t) = timer.as_deref_mut() {
                t.reset(rec);
                t.start(rec);
            }
            // One pass, with or without a direction map: its label, and its time where `rec` has a
            // clock (the renderer's frame).
            rec.pass(crate::passes::names::ALPHA_LIGHTMAPS, |rec| {
                let pipeline = match direction {
                    Some(direction) => {
                        begin_all_cleared(rec, &mut [atlas, direction], CLEAR_BLACK);
                        self.directional_pipeline
                    }
                    None => {
                        begin_all_cleared(rec, &mut [atlas], CLEAR_BLACK);
                        self.pipeline
                    }
                };
                // SAFETY: the recording is on this context's device (the # Safety of `record` and
                // `record_directional`, and `AlphaLighting` records into the renderer's own),
                // inside the rendering begun above. The pipeline is non-null: the directional one
                // only with a direction map, which `check_direction` (or `AlphaLighting`'s desc)
                // ties to a direction format; it and the layout were made by `create` and live as
                // long as `self`. The slot's sets were written by `write_frame` and match the
                // layout's sets 0 and 1.
                unsafe {
                    let sets = [slot.frame_set, slot.alpha_set];
                    rec.bind_graphics(pipeline, self.pipeline_layout, &sets);
                }
                rec.apply(&FULLSCREEN);
                if let Some(t) = timer.as_deref_mut() {
                    t.mark(rec, "clear".to_owned(), None);
                }
                for (index, (r, lights)) in
                    layout.regions.iter().zip(&slot.entity_lights).enumerate()
                {
                    if lights.is_empty() {
                        continue;
                    }
                    let mut region = r.region;
                    (region.width, region.height) = r.shape.size();
                    set_region(rec, region);
                    for &light in lights {
                        let push = AlphaDrawPush {
                            entity: index as u32,
                            light,
                            ..Default::default()
                        };
                        // SAFETY: inside the rendering begun above, with the pipeline and sets
                        // bound, the dynamic state set (`apply`, `set_region`); the push is
                        // `AlphaDrawPush` at offset 0, the layout's graphics-stage range; the
                        // full-screen triangle reads no vertex buffer.
                        unsafe {
                            let bytes = bytemuck::bytes_of(&push);
                            rec.push(self.pipeline_layout, GRAPHICS_STAGES, 0, bytes);
                            rec.draw(3, 0);
                        }
                    }
                    if let Some(t) = timer.as_deref_mut() {
                        t.mark(rec, "entity".to_owned(), Some(index as u32));
                    }
                }
                rec.end_rendering();
            });
        };
        // SAFETY: this fn's # Safety is `Recording::new`'s, or `outer` is `cmd`'s recording (the
        // renderer's).
        unsafe { Recording::through(ctx, cmd, outer, record) };
    }

    /// Sets 0 and 1 of the alpha pipelines (frame, alpha), for histencil's own alpha pass.
    pub(crate) fn alpha_set_layout(&self) -> vk::DescriptorSetLayout {
        self.set_layouts[1]
    }

    /// The alpha set (records, points, light lists, probes) of `slot`'s last frame.
    pub(crate) fn alpha_set(&self, slot: u32) -> vk::DescriptorSet {
        self.slots[slot as usize].alpha_set
    }
}

impl<C: Deref<Target = Context>> Drop for AlphaLightmaps<C> {
    /// Frees everything, also after a creation that failed half way; while a slot is in flight,
    /// leaves it to the context until the GPU is known to be done (as
    /// [`crate::DeferredLighting`]'s drop does).
    fn drop(&mut self) {
        let mut slots = std::mem::take(&mut self.slots);
        let pipelines = [self.pipeline, self.directional_pipeline];
        let (pool, pipeline_layout, set_layouts) =
            (self.pool, self.pipeline_layout, self.set_layouts);
        let free = move |ctx: &Context| {
            for slot in &mut slots {
                slot.uniforms.destroy(ctx);
                slot.lights.destroy(ctx);
                for b in &mut slot.storage {
                    b.destroy(ctx);
                }
                slot.timer.destroy(ctx);
            }
            let d = &ctx.device;
            // SAFETY: the GPU is done with these: no slot is pending (`slot_finished`'s
            // # Safety), or this runs from the context's retired list once the device is idle
            // or `free_retired`'s caller says so. Each was made by `create` from `ctx.device`,
            // or is null (no direction format, or a creation that failed half way), which
            // destroying ignores.
            unsafe {
                for p in pipelines {
                    d.destroy_pipeline(p, None);
                }
                d.destroy_descriptor_pool(pool, None);
                d.destroy_pipeline_layout(pipeline_layout, None);
                for l in set_layouts {
                    d.destroy_descriptor_set_layout(l, None);
                }
            }
        };
        free_or_retire(&self.ctx, self.pending.any(), free);
    }
}

/// Makes the storage buffer `buffer` hold at least `bytes` (and never less than 256), replacing it with one of the
/// next power of two when it is too small. True when it was replaced (its sets need rewriting).
fn fit(ctx: &Context, buffer: &mut Buffer, name: &str, slot: u32, bytes: usize) -> Result<bool> {
    let needed = (bytes as u64).max(256);
    if buffer.size >= needed {
        return Ok(false);
    }
    let grown = Buffer::new(
        ctx,
        &format!("{name}-{slot}"),
        needed.next_power_of_two(),
        vk::BufferUsageFlags::STORAGE_BUFFER,
        MemoryLocation::CpuToGpu,
    )?;
    let mut old = std::mem::replace(buffer, grown);
    old.destroy(ctx);
    Ok(true)
}

/// Viewport and scissor over one atlas region.
pub(crate) fn set_region(rec: &Recording, r: Region) {
    let viewport = vk::Viewport {
        x: r.x as f32,
        y: r.y as f32,
        width: r.width as f32,
        height: r.height as f32,
        min_depth: 0.0,
        max_depth: 1.0,
    };
    let scissor = vk::Rect2D {
        offset: vk::Offset2D {
            x: r.x as i32,
            y: r.y as i32,
        },
        extent: vk::Extent2D {
            width: r.width,
            height: r.height,
        },
    };
    // The region's shape: non-zero and inside the atlas, as `check_frame` held every region
    // before the recording.
    rec.set_viewport(viewport);
    rec.set_scissor(scissor);
}
