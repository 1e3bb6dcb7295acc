//! The talk's lighting as a part an engine records into its own frame: [`DeferredLighting`]
//! records a [`FramePlan`] into the caller's command buffer, against the caller's G-buffer,
//! depth-stencil and HDR images ([`LightingTargets`]), with the camera and lights of that frame.
//! It submits nothing and waits for nothing; [`crate::Renderer`] lights its frames through it
//! too.
//!
//! Frames in flight: each of the `frames_in_flight` slots has its own uniform and light buffers
//! and descriptor sets, written when a frame is recorded into that slot. The caller cycles the
//! slots and records into one again only after the GPU finished the frame that last used it
//! (the engine's own fence per frame in flight does this).
//!
//! The G-buffer contract (`crates/vk/shaders/include/gbuffer_write.glsl` writes it, `gbuffer.glsl` reads
//! it): [`crate::GBUFFER_FORMATS`] in that order, each pixel's BRDF slot in the stencil's BRDF
//! field with the culling bit clear ([`gbuffer_stencil_reference`]), standard or reversed depth as
//! the [`ViewDesc`] says.

use crate::access::{ImageRef, LightingTargets};
use crate::context::Context;
use crate::descriptors::{
    create_pipeline_layout, create_set_layout, write_frame_set, write_sampled_images,
    write_storage_buffers, FRAME_SET, GBUFFER_SET, GRAPHICS_STAGES, HI_STENCIL_SET, LUT_SET,
};
use crate::error::{Error, Result, VkCall};
use crate::gpu_types::{FrameUniforms, GpuLight, PUSH_CONSTANT_BYTES};
use crate::hi_stencil::{GpuHierarchy, HiStencilSurface};
use crate::hooks::{HookSets, LightHooks};
use crate::meshes::LightVolumes;
use crate::passes::depth_id::{DepthIdDesc, DepthIdPass};
use crate::passes::light_pipelines::{prepare_pipelines, BrdfSource, LightPipelines};
use crate::passes::lighting::{Emulation, LightingPass};
use crate::passes::tiled::{TiledDesc, TiledLighting, TiledSets, TiledShade};
use crate::resources::Buffer;
use crate::targets::GBUFFER_FORMATS;
use crate::teardown::{Destroy, InFlight};
use crate::technique::{MixedTiles, TileClassify, TileSide};
use crate::timing::{LightingBreakdown, SlotTimer};
use ash::vk;
use gpu_allocator::MemoryLocation;
use histencil_brdf::BrdfId;
use histencil_model::{FramePlan, StencilLayout, Step, TileStats, ViewDesc};
use histencil_scene::Light;
use std::ops::Deref;

/// What a [`DeferredLighting`] is made for: fixed for its lifetime.
#[derive(Clone, Debug)]
pub struct LightingDesc {
    /// Where the culling bit, the BRDF field and the engine's bits sit in the stencil.
    pub layout: StencilLayout,
    /// The BRDF of each stencil slot, in slot order.
    pub brdfs: Vec<BrdfId>,
    /// The size of every target.
    pub extent: vk::Extent2D,
    /// The depth-stencil target's format (a format with a stencil aspect).
    pub depth_stencil_format: vk::Format,
    /// The HDR target's format: any colour format the device blends into.
    pub hdr_format: vk::Format,
    /// How many frames the caller records before it waits for the oldest (at least 1).
    pub frames_in_flight: u32,
    /// The most lights a frame may carry.
    pub max_lights: u32,
    /// Emulate console hi-stencil, which the PS3-like and 360-like plans use (and 360-like
    /// save/restore): a word per 8x8 tile and two bytes per pixel of scratch. Without it only
    /// plans for the native backend can be recorded.
    pub hi_stencil: bool,
    /// Where the light shaders get each pixel's surface and each light's visibility:
    /// histencil's G-buffer and no shadows, or the engine's hooks ([`crate::EngineHooks`]).
    pub hooks: LightHooks,
}

impl LightingDesc {
    /// The stencil slot of `brdf`: its index in [`LightingDesc::brdfs`].
    pub fn slot_of(&self, brdf: BrdfId) -> Option<u32> {
        self.brdfs.iter().position(|b| *b == brdf).map(|i| i as u32)
    }

    /// The stencil reference and write mask with which the engine's G-buffer pass draws a
    /// surface of `brdf` ([`gbuffer_stencil_reference`] of its slot); `None` for a BRDF the
    /// lighting is not made with (its pixels would match no light pass). One numbering for the
    /// engine: its materials and its decode hook (`Surface::brdf`) name BRDF ids, and the slot
    /// a BRDF's pixels carry in stencil comes from here, so the two cannot disagree.
    pub fn stencil_reference(&self, brdf: BrdfId) -> Option<(u8, u8)> {
        gbuffer_stencil_reference(&self.layout, self.slot_of(brdf)?)
    }
}

/// One frame's lighting.
#[derive(Clone, Copy, Debug)]
pub struct LightingFrame<'a> {
    /// Which frame-in-flight slot's buffers and sets this frame uses (`< frames_in_flight`).
    pub slot: u32,
    /// The camera, as the plan was made with it.
    pub view: &'a ViewDesc,
    /// The frame's lights; the plan's light inputs index them.
    pub lights: &'a [Light],
    /// The plan, from [`histencil_model::plan_frame`] on the same lights and view.
    pub plan: &'a FramePlan,
    /// Clear the HDR target to black first; otherwise light adds onto its contents.
    pub clear_hdr: bool,
    /// Write a GPU timestamp after every step ([`DeferredLighting::step_timings`]).
    pub timestamps: bool,
    /// Where shade passes read each BRDF's value: its formula, or its material's look-up table
    /// (the talk's LUT technique; [`DeferredLighting::set_lut_tables`] first, and the G-buffer's
    /// material index names the table).
    pub brdf_source: BrdfSource,
    /// Count hi-stencil tiles tested and culled and fragments shaded
    /// ([`DeferredLighting::tile_stats`]); needs `LightingDesc::hi_stencil`.
    pub tile_stats: bool,
    /// The engine's sets for its hooks (none with histencil's built-in hooks).
    pub hook_sets: HookSets,
}

/// One frame lit by the tiled technique ([`DeferredLighting::record_tiled`]): no plan, no
/// stencil; the BRDF of each pixel comes from its surface.
#[derive(Clone, Copy, Debug)]
pub struct TiledFrame<'a> {
    /// Which frame-in-flight slot's buffers and sets this frame uses (`< frames_in_flight`).
    pub slot: u32,
    /// The camera.
    pub view: &'a ViewDesc,
    /// The frame's lights.
    pub lights: &'a [Light],
    /// Clear the HDR target to black first; otherwise light adds onto its contents.
    pub clear_hdr: bool,
    /// The tiles' side: [`TileSide::for_device`] picks 8x8 on a CPU rasteriser, faster there,
    /// and 16x16 on a GPU.
    pub side: TileSide,
    /// What a tile of several BRDFs does.
    pub mixed: MixedTiles,
    /// How the classification's work is shaped (the same results either way):
    /// [`TileClassify::for_device`] picks the faster for the device.
    pub classify: TileClassify,
    /// The engine's sets for its hooks (none with histencil's built-in hooks).
    pub hook_sets: HookSets,
}

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
///     // SAFETY: `cmd` is recording on the lighting's device, the images' states are true, and
///     // the frame two frames ago (the last one in this slot) has finished on the GPU.
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
    in_flight: InFlight,
}

/// The stencil reference with which an engine's G-buffer pass writes BRDF slot `slot`, and the
/// write mask: the BRDF field and the culling bit (which must be 0 when lighting starts), so the
/// engine's own bits are left as they are. `None` for a slot the layout does not have.
pub fn gbuffer_stencil_reference(layout: &StencilLayout, slot: u32) -> Option<(u8, u8)> {
    (slot < layout.brdfs_in_use()).then(|| {
        (
            layout.brdf_reference(slot),
            layout.brdf_mask() | layout.culling_mask(),
        )
    })
}

impl<C: Deref<Target = Context>> DeferredLighting<C> {
    /// Creates the pipeline layout, the light volumes, the hi-stencil emulation and every slot's
    /// buffers and sets. Light pipelines are made when a plan first needs them
    /// ([`DeferredLighting::prepare`]). A failure half way frees what was made.
    ///
    /// # Errors
    /// [`Error::BadSetup`] for a zero extent, a depth format without stencil, no frames in
    /// flight, too many BRDFs for the layout, or a depth-stencil format other than the one the
    /// context was lent with; Vulkan and allocation errors.
    pub fn new(ctx: C, desc: &LightingDesc) -> Result<Self> {
        check_desc(desc)?;
        desc.hooks.check(&ctx)?;
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
            hi_stencil: None,
            volumes: None,
            tiled: Vec::new(),
            depth_id: Vec::new(),
            in_flight: InFlight::default(),
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

    fn create(&mut self) -> Result<()> {
        let ctx: &Context = &self.ctx;
        let named = [
            ("frame-set-layout", FRAME_SET),
            ("gbuffer-set-layout", GBUFFER_SET),
            ("hi-stencil-set-layout", HI_STENCIL_SET),
            ("lut-set-layout", LUT_SET),
        ];
        let hooks = &self.desc.hooks;
        let builtin = matches!(hooks, LightHooks::Builtin);
        for (i, (name, set)) in named.into_iter().enumerate() {
            if i == 1 && !builtin {
                continue;
            }
            // The tiled technique's compute kernels bind the frame, G-buffer and filler sets.
            let stages = match i {
                2 => GRAPHICS_STAGES,
                _ => GRAPHICS_STAGES | vk::ShaderStageFlags::COMPUTE,
            };
            self.set_layouts[i] = create_set_layout(ctx, name, set, stages)?;
        }
        let mut layouts = self.set_layouts.to_vec();
        if let LightHooks::Engine(engine) = hooks {
            layouts[1] = engine.decode_layout;
            layouts.extend(engine.visibility_layout);
        }
        self.pipeline_layout = create_pipeline_layout(
            ctx,
            "lighting-pipeline-layout",
            &layouts,
            GRAPHICS_STAGES,
            PUSH_CONSTANT_BYTES,
        )?;
        self.pipelines = LightPipelines::new(
            self.pipeline_layout,
            hooks.modules(),
            self.desc.hdr_format,
            self.desc.depth_stencil_format,
        );
        self.volumes = Some(LightVolumes::new(ctx)?);
        // Without the emulation the light pipelines still bind its set: a one-tile surface.
        let surface = if self.desc.hi_stencil {
            self.desc.extent
        } else {
            vk::Extent2D {
                width: 1,
                height: 1,
            }
        };
        let slots = self.desc.frames_in_flight;
        self.hi_stencil = Some(HiStencilSurface::new(ctx, surface, slots)?);

        let storage_per_slot = 1;
        let shared_storage = (HI_STENCIL_SET.len() + LUT_SET.len()) as u32;
        let sizes = [
            vk::DescriptorPoolSize::default()
                .ty(vk::DescriptorType::UNIFORM_BUFFER)
                .descriptor_count(slots),
            vk::DescriptorPoolSize::default()
                .ty(vk::DescriptorType::STORAGE_BUFFER)
                .descriptor_count(slots * storage_per_slot + shared_storage),
            vk::DescriptorPoolSize::default()
                .ty(vk::DescriptorType::SAMPLED_IMAGE)
                .descriptor_count(slots * GBUFFER_SET.len() as u32),
        ];
        let sets_per_slot = if builtin { 2 } else { 1 };
        let info = vk::DescriptorPoolCreateInfo::default()
            .max_sets(sets_per_slot * slots + 2)
            .pool_sizes(&sizes);
        self.pool = unsafe { ctx.device.create_descriptor_pool(&info, None) }
            .call("vkCreateDescriptorPool")?;
        ctx.name(self.pool, "lighting-descriptor-pool");
        let [frame_layout, gbuffer_layout, hi_stencil_layout, lut_layout] = self.set_layouts;
        let mut layouts = vec![hi_stencil_layout, lut_layout];
        for _ in 0..slots {
            layouts.push(frame_layout);
            if builtin {
                layouts.push(gbuffer_layout);
            }
        }
        let alloc = vk::DescriptorSetAllocateInfo::default()
            .descriptor_pool(self.pool)
            .set_layouts(&layouts);
        let sets = unsafe { ctx.device.allocate_descriptor_sets(&alloc) }
            .call("vkAllocateDescriptorSets")?;
        self.hi_stencil_set = sets[0];
        ctx.name(sets[0], "hi-stencil-set");
        ctx.name(sets[1], "lut-set");
        let hi = self.hi_stencil.as_ref().expect("made above");
        write_storage_buffers(ctx, self.hi_stencil_set, &hi.light_set_buffers());
        self.lut_set = sets[1];

        let light_bytes = u64::from(self.desc.max_lights.max(1)) * size_of::<GpuLight>() as u64;
        for (i, pair) in sets[2..].chunks(sets_per_slot as usize).enumerate() {
            let frame_set = pair[0];
            let gbuffer_set = pair.get(1).copied().unwrap_or_default();
            ctx.name(frame_set, &format!("lighting-frame-set-{i}"));
            if builtin {
                ctx.name(gbuffer_set, &format!("lighting-gbuffer-set-{i}"));
            }
            let uniforms = Buffer::new(
                ctx,
                &format!("lighting-uniforms-{i}"),
                size_of::<FrameUniforms>() as u64,
                vk::BufferUsageFlags::UNIFORM_BUFFER,
                MemoryLocation::CpuToGpu,
            )?;
            let lights = Buffer::new(
                ctx,
                &format!("lighting-lights-{i}"),
                light_bytes,
                vk::BufferUsageFlags::STORAGE_BUFFER,
                MemoryLocation::CpuToGpu,
            );
            let lights = match lights {
                Ok(l) => l,
                Err(e) => {
                    let mut uniforms = uniforms;
                    uniforms.destroy(ctx);
                    return Err(e);
                }
            };
            write_frame_set(ctx, frame_set, uniforms.handle, lights.handle);
            self.slots.push(Slot {
                uniforms,
                lights,
                frame_set,
                gbuffer_set,
                timer: SlotTimer::default(),
                emulation: SlotTimer::default(),
            });
        }
        Ok(())
    }
}

impl<C: Deref<Target = Context>> DeferredLighting<C> {
    /// Makes the lighting fit targets of a new `extent`, keeping every pipeline (viewport and
    /// scissor are dynamic state; the tile side, not the extent, shapes the tiled kernels): the
    /// hi-stencil tile surface and the tiled technique's tile buffers are made anew, nothing
    /// else. A resize to the same extent does nothing; a failure leaves the lighting as it was.
    ///
    /// # Errors
    /// [`Error::BadSetup`] for a zero extent; allocation errors.
    ///
    /// # Safety
    /// The GPU has finished every command buffer this lighting recorded into (wait for your
    /// frames in flight first, as for any resize of your own targets).
    pub unsafe fn resize(&mut self, extent: vk::Extent2D) -> Result<()> {
        if extent.width == 0 || extent.height == 0 {
            return Err(bad_setup(format!(
                "a {}x{} lighting extent",
                extent.width, extent.height
            )));
        }
        if extent == self.desc.extent {
            return Ok(());
        }
        let ctx: &Context = &self.ctx;
        if self.desc.hi_stencil {
            let surface = self.hi_stencil.as_mut().expect("made with the lighting");
            surface.resize(ctx, extent)?;
            let buffers = surface.light_set_buffers();
            write_storage_buffers(ctx, self.hi_stencil_set, &buffers);
        }
        for (_, tiled) in &mut self.tiled {
            tiled.resize(ctx, extent)?;
        }
        for (_, depth_id) in &mut self.depth_id {
            depth_id.resize(ctx, extent)?;
        }
        self.desc.extent = extent;
        Ok(())
    }
}

fn bad(message: String) -> Error {
    Error::BadFrame(message)
}

fn bad_setup(message: String) -> Error {
    Error::BadSetup(message)
}

fn check_desc(desc: &LightingDesc) -> Result<()> {
    let e = desc.extent;
    if e.width == 0 || e.height == 0 {
        return Err(bad_setup(format!(
            "a {}x{} lighting extent",
            e.width, e.height
        )));
    }
    if !crate::access::aspect_of(desc.depth_stencil_format).contains(vk::ImageAspectFlags::STENCIL)
    {
        return Err(bad_setup(format!(
            "depth format {:?} has no stencil for the BRDF ids",
            desc.depth_stencil_format
        )));
    }
    if desc.frames_in_flight == 0 {
        return Err(bad_setup("frames_in_flight must be at least 1".into()));
    }
    for (slot, brdf) in desc.brdfs.iter().enumerate() {
        if let Some(first) = desc.brdfs[..slot].iter().position(|b| b == brdf) {
            return Err(bad_setup(format!(
                "{brdf:?} is in BRDF slots {first} and {slot}: one slot per BRDF, so that a BRDF id \
                 names one slot"
            )));
        }
    }
    let slots = desc.layout.brdfs_in_use() as usize;
    if desc.brdfs.len() > slots {
        return Err(bad_setup(format!(
            "{} BRDFs for a stencil layout with {slots} BRDF slots",
            desc.brdfs.len()
        )));
    }
    Ok(())
}

/// Whether recording `plan` needs the hi-stencil emulation: a hi-stencil test, write or flush,
/// or the stencil copy of a 360-like save/restore.
fn needs_hi_stencil(plan: &FramePlan) -> bool {
    plan.steps.iter().any(|step| match step {
        Step::Pass { pass, .. } => pass.state.tests_hi_stencil() || pass.state.writes_hi_stencil(),
        Step::FlushHiStencil | Step::SavePreserved { .. } | Step::RestorePreserved { .. } => true,
    })
}

/// Whether `plan` writes hi-stencil: its tile updates read the frame's stencil.
fn writes_hi_stencil(plan: &FramePlan) -> bool {
    plan.passes().any(|pass| pass.state.writes_hi_stencil())
}

/// Checks one frame against the lighting's description: the slot, the light count, the plan's
/// light indices and depth convention, and every target's extent and format.
fn check_frame(
    desc: &LightingDesc,
    frame: &LightingFrame,
    targets: &LightingTargets,
) -> Result<()> {
    check_slot_and_lights(desc, frame.slot, frame.lights.len())?;
    if let Some(l) = frame
        .plan
        .lights
        .iter()
        .find(|l| l.input >= frame.lights.len())
    {
        return Err(bad(format!(
            "the plan lights input {} of {} lights",
            l.input,
            frame.lights.len()
        )));
    }
    if !desc.hi_stencil && needs_hi_stencil(frame.plan) {
        return Err(bad(
            "the plan uses hi-stencil (a PS3-like or 360-like backend), and this lighting was \
             made without it (LightingDesc::hi_stencil)"
                .into(),
        ));
    }
    if frame.plan.depth != frame.view.depth {
        return Err(bad(format!(
            "the plan is for {:?} depth, the view is {:?}",
            frame.plan.depth, frame.view.depth
        )));
    }
    // A plan made for another view or other lights records without complaint and lights the
    // frame wrong: hold it to what it was made for.
    if let Some(made_for) = &frame.plan.made_for {
        let shapes = frame.lights.iter().map(|l| l.shape());
        if let Some(difference) = made_for.difference(frame.view, shapes, &desc.layout) {
            return Err(bad(difference));
        }
    }
    check_targets(desc, &frame.hook_sets, targets)
}

/// Checks a frame's slot and light count against the lighting's description.
fn check_slot_and_lights(desc: &LightingDesc, slot: u32, lights: usize) -> Result<()> {
    if slot >= desc.frames_in_flight {
        return Err(bad(format!(
            "slot {slot} of {} frames in flight",
            desc.frames_in_flight
        )));
    }
    if lights > desc.max_lights as usize {
        return Err(bad(format!(
            "{lights} lights, more than the {} this lighting was made for",
            desc.max_lights
        )));
    }
    Ok(())
}

/// Checks the hook sets and every target's extent and format against the description.
fn check_targets(
    desc: &LightingDesc,
    hook_sets: &HookSets,
    targets: &LightingTargets,
) -> Result<()> {
    let expect = |what: &str, image: &ImageRef, format: vk::Format| {
        if image.extent != desc.extent {
            return Err(bad(format!(
                "{what} is {}x{}, the lighting {}x{}",
                image.extent.width, image.extent.height, desc.extent.width, desc.extent.height
            )));
        }
        if image.format != format {
            return Err(bad(format!(
                "{what} is {:?}, the lighting expects {format:?}",
                image.format
            )));
        }
        Ok(())
    };
    desc.hooks.check_sets(hook_sets)?;
    if let LightHooks::Builtin = desc.hooks {
        let names = [
            "G-buffer albedo",
            "G-buffer normal-depth",
            "G-buffer material",
        ];
        if targets.gbuffer.len() != names.len() {
            return Err(bad(format!(
                "{} G-buffer images, and histencil's G-buffer has {}",
                targets.gbuffer.len(),
                names.len()
            )));
        }
        for ((image, name), format) in targets.gbuffer.iter().zip(names).zip(GBUFFER_FORMATS) {
            expect(name, image, format)?;
        }
    } else if let LightHooks::Engine(engine) = &desc.hooks {
        // The decode reads these through the engine's set; the lighting barriers each one for
        // the light shaders' reads, so one left out would be read in whatever layout it was.
        let formats = &engine.surface_formats;
        if targets.gbuffer.len() != formats.len() {
            return Err(bad(format!(
                "{} surface images in LightingTargets::gbuffer, and the engine's decode hook \
                 reads {} (EngineHooks::new's surface formats)",
                targets.gbuffer.len(),
                formats.len()
            )));
        }
        for (i, (image, format)) in targets.gbuffer.iter().zip(formats).enumerate() {
            expect(&format!("surface image {i}"), image, *format)?;
        }
    }
    expect(
        "the depth-stencil target",
        &targets.depth_stencil,
        desc.depth_stencil_format,
    )?;
    expect("the HDR target", &targets.hdr, desc.hdr_format)
}

impl<C: Deref<Target = Context>> DeferredLighting<C> {
    /// What this lighting was made for.
    pub fn desc(&self) -> &LightingDesc {
        &self.desc
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
    /// the view's projection cannot be inverted per pixel; pipeline creation errors. Nothing is
    /// recorded on an error.
    ///
    /// # Safety
    /// - `cmd` is in the recording state, on a queue family with graphics, from the device of
    ///   the context this lighting was made with.
    /// - The images of `targets` are live, from that device, with the usages
    ///   [`LightingTargets`] lists, and their `state`s are true when `cmd` executes: the layout
    ///   each subresource is in, and the stages and accesses of the last commands before it that
    ///   touched it (`ImageState::UNDEFINED` discards contents, so not for the G-buffer or
    ///   depth-stencil).
    /// - The GPU has finished every command buffer that recorded into `frame.slot` before;
    ///   this call rewrites that slot's buffers and descriptor sets.
    pub unsafe fn record(
        &mut self,
        cmd: vk::CommandBuffer,
        frame: &LightingFrame,
        targets: &mut LightingTargets,
    ) -> Result<()> {
        self.record_emulating(cmd, frame, targets, None)
    }

    /// [`DeferredLighting::record`], emulating `hierarchy`, the hierarchical stencil of an AMD
    /// GPU (`crate::hi_stencil::amd`), which needs [`LightingDesc::hi_stencil`].
    ///
    /// # Safety
    /// As [`DeferredLighting::record`].
    pub(crate) unsafe fn record_emulating(
        &mut self,
        cmd: vk::CommandBuffer,
        frame: &LightingFrame,
        targets: &mut LightingTargets,
        hierarchy: Option<GpuHierarchy>,
    ) -> Result<()> {
        let (count_stats, source) = (frame.tile_stats, frame.brdf_source);
        check_frame(&self.desc, frame, targets)?;
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
        if source == BrdfSource::Table && !self.lut_written {
            return Err(Error::Unsupported(
                "the LUT technique before its tables exist",
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
        let pass = LightingPass {
            ctx,
            cmd,
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
            hierarchy,
        };
        let hi_stencil = self.hi_stencil.as_mut().expect("made with the lighting");
        if writes_hi_stencil(frame.plan) || hierarchy.is_some() {
            hi_stencil.prepare_slot(ctx, frame.slot, &targets.depth_stencil)?;
        }
        let timer = slot.timer.active();
        let emulation = slot.emulation.active();
        self.in_flight.mark();
        pass.record(targets, hi_stencil, timer, emulation)
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

    /// Records `frame` lit by the tiled technique into `cmd` against `targets`, as engines
    /// today light many BRDFs: a compute pass classifies each tile of the surfaces (the BRDFs
    /// its pixels use, their depth range, the lights that can reach it), then one indirect
    /// dispatch per BRDF runs a kernel specialised to it over its tiles
    /// (`crate::passes::tiled`). No plan and no stencil: the BRDF comes from each pixel's
    /// surface, through the decode hook. Leaves the HDR target in `GENERAL` (written by compute
    /// shaders) and the depth-stencil image as it was, or, with an engine's decode hook, with
    /// its depth read by compute shaders in `DEPTH_READ_ONLY_STENCIL_ATTACHMENT_OPTIMAL`.
    ///
    /// # Errors
    /// [`Error::BadFrame`] when the frame does not fit this lighting (slot, light count, target
    /// extents and formats), or the HDR format is not `R16G16B16A16_SFLOAT` (the kernels store
    /// to it as `rgba16f`); pipeline creation errors. Nothing is recorded on an error.
    ///
    /// # Safety
    /// As [`DeferredLighting::record`]; the HDR image also has `STORAGE` usage, and the
    /// engine's hook resources are readable by compute shaders (its set layouts include the
    /// compute stage, its barriers the compute-shader stage).
    pub unsafe fn record_tiled(
        &mut self,
        cmd: vk::CommandBuffer,
        frame: &TiledFrame,
        targets: &mut LightingTargets,
    ) -> Result<()> {
        self.record_tiled_with(cmd, frame, targets, TiledShade::Kernels, |_, _| {})
    }

    /// Records `frame` lit by the depth-id technique, as Bevy's deferred renderer lights its
    /// lighting passes (`crate::passes::depth_id`): the tiled technique's classification and
    /// light lists, then each pixel's BRDF slot copied into a 16-bit depth image and one
    /// full-screen pass per BRDF drawn at its slot's depth with compare EQUAL, each pixel adding
    /// its tile's lights. The same image as [`DeferredLighting::record_tiled`], bit for bit;
    /// what differs is how a BRDF's pixels are found, which a GPU's hierarchical depth speeds
    /// up. Leaves the HDR target in `GENERAL`, written by fragment shaders, and the G-buffer (or
    /// the decode hook's images) read by fragment shaders; with an engine's decode hook the
    /// depth-stencil image's depth read by them, in `DEPTH_READ_ONLY_STENCIL_ATTACHMENT_OPTIMAL`.
    ///
    /// # Errors
    /// As [`DeferredLighting::record_tiled`], and [`Error::BadFrame`] for
    /// [`MixedTiles::Branching`]: each BRDF has its own pass here, so no tile is shaded by one
    /// kernel branching per pixel.
    ///
    /// # Safety
    /// As [`DeferredLighting::record_tiled`], and the hook resources are readable by fragment
    /// shaders too.
    pub unsafe fn record_depth_id(
        &mut self,
        cmd: vk::CommandBuffer,
        frame: &TiledFrame,
        targets: &mut LightingTargets,
    ) -> Result<()> {
        self.record_tiled_with(cmd, frame, targets, TiledShade::DepthId, |_, _| {})
    }

    /// [`DeferredLighting::record_tiled`], calling `between` with the pass's name after the
    /// classification (`tile-classify`) and after the light lists (`tile-lights`), before the
    /// shade kernels (the renderer's timestamps between them).
    ///
    /// # Safety
    /// As [`DeferredLighting::record_tiled`].
    pub(crate) unsafe fn record_tiled_with(
        &mut self,
        cmd: vk::CommandBuffer,
        frame: &TiledFrame,
        targets: &mut LightingTargets,
        shade: TiledShade,
        mut between: impl FnMut(vk::CommandBuffer, &'static str),
    ) -> Result<()> {
        if shade == TiledShade::DepthId && frame.mixed == MixedTiles::Branching {
            return Err(bad(
                "the depth-id technique shades each BRDF in a pass of its own: \
                 MixedTiles::Branching is the tiled kernels' (record_tiled)"
                    .to_owned(),
            ));
        }
        check_slot_and_lights(&self.desc, frame.slot, frame.lights.len())?;
        check_targets(&self.desc, &frame.hook_sets, targets)?;
        if let Some(why) = self.desc.hooks.tiled_refusal() {
            return Err(bad(format!(
                "the tiled technique's kernels cannot bind the hooks: {why}"
            )));
        }
        if self.desc.hdr_format != vk::Format::R16G16B16A16_SFLOAT {
            return Err(bad(format!(
                "the tiled technique stores light as rgba16f, and the HDR target is {:?}",
                self.desc.hdr_format
            )));
        }
        self.prepare_tiled(frame.side)?;
        if shade == TiledShade::DepthId {
            self.prepare_depth_id(frame.side)?;
        }
        let inputs = (frame.view, frame.lights, &frame.hook_sets);
        let (frame_set, decode_set) = self.write_slot(frame.slot, inputs, targets)?;
        let ctx: &Context = &self.ctx;
        // A tiled frame writes neither timer: the slot's last planned frame's times go.
        let slot = &mut self.slots[frame.slot as usize];
        slot.timer
            .prepare(ctx, "lighting-step-timestamps", false, 0)?;
        slot.emulation
            .prepare(ctx, "lighting-emulation-timestamps", false, 0)?;
        let tiled = &self
            .tiled
            .iter()
            .find(|(s, _)| *s == frame.side)
            .expect("made")
            .1;
        tiled.set_target(ctx, frame.slot, targets.hdr.view);
        let sets = TiledSets {
            slot: frame.slot,
            frame: frame_set,
            decode: decode_set,
            visibility: frame.hook_sets.visibility,
        };
        self.in_flight.mark();
        let depth_sampled = self.desc.hooks.samples_depth();
        let (clear, mixed) = (frame.clear_hdr, frame.mixed);
        let shape = frame.classify;
        tiled.record_classify(ctx, cmd, &sets, targets, depth_sampled, clear, mixed, shape);
        between(cmd, "tile-classify");
        tiled.record_light_lists(ctx, cmd, frame.lights.len() as u32);
        between(cmd, "tile-lights");
        match shade {
            TiledShade::Kernels => tiled.record_shade(ctx, cmd, mixed),
            TiledShade::DepthId => {
                let side = frame.side;
                let (_, pass) = self
                    .depth_id
                    .iter_mut()
                    .find(|(s, _)| *s == side)
                    .expect("made");
                let bound = (
                    [frame_set, decode_set, tiled.set(frame.slot)],
                    sets.visibility,
                );
                let push = tiled.push_bytes(clear, mixed);
                pass.record(ctx, cmd, frame.slot, bound, &push, targets, depth_sampled);
            }
        }
        Ok(())
    }

    /// Records a copy of frame-in-flight `slot`'s depth-id image for tiles of `side`, as its
    /// last depth-id frame left it, into `buffer` (2 bytes per pixel).
    pub(crate) fn copy_depth_ids(
        &mut self,
        cmd: vk::CommandBuffer,
        side: TileSide,
        slot: u32,
        buffer: &Buffer,
    ) {
        let (_, pass) = self
            .depth_id
            .iter_mut()
            .find(|(s, _)| *s == side)
            .expect("a depth-id frame was recorded");
        pass.copy_ids(&self.ctx, cmd, slot, buffer);
    }

    /// The set layout the decode hook binds at set 1: histencil's G-buffer's, or the engine's.
    fn decode_layout(&self) -> vk::DescriptorSetLayout {
        match &self.desc.hooks {
            LightHooks::Builtin => self.set_layouts[1],
            LightHooks::Engine(engine) => engine.decode_layout,
        }
    }

    /// Makes the depth-id technique's pipelines and id images for tiles of `side`, if not yet
    /// made (after the tiled technique's for that side, whose set layout it binds).
    fn prepare_depth_id(&mut self, side: TileSide) -> Result<()> {
        if self.depth_id.iter().any(|(s, _)| *s == side) {
            return Ok(());
        }
        let tiled = &self.tiled.iter().find(|(s, _)| *s == side).expect("made").1;
        let hooks = &self.desc.hooks;
        let [frame, _, _, filler] = self.set_layouts;
        let decode = self.decode_layout();
        let mut set_layouts = vec![frame, decode, tiled.set_layout()];
        if let Some(visibility) = hooks.visibility_layout() {
            set_layouts.extend([filler, visibility]);
        }
        let desc = DepthIdDesc {
            extent: self.desc.extent,
            tile_side: side.pixels(),
            brdfs: &self.desc.brdfs,
            frames_in_flight: self.desc.frames_in_flight,
            modules: &hooks.modules(),
            set_layouts: &set_layouts,
            push_bytes: TiledLighting::PUSH_BYTES,
        };
        let made = DepthIdPass::new(&self.ctx, &desc)?;
        self.depth_id.push((side, made));
        Ok(())
    }

    /// Makes the tiled technique's pipelines and buffers for tiles of `side`, if not yet made.
    fn prepare_tiled(&mut self, side: TileSide) -> Result<()> {
        if self.tiled.iter().any(|(s, _)| *s == side) {
            return Ok(());
        }
        let ctx: &Context = &self.ctx;
        let hooks = &self.desc.hooks;
        let [frame, _, _, filler] = self.set_layouts;
        let decode = self.decode_layout();
        let desc = TiledDesc {
            extent: self.desc.extent,
            side,
            brdfs: &self.desc.brdfs,
            max_lights: self.desc.max_lights,
            frames_in_flight: self.desc.frames_in_flight,
            modules: &hooks.modules(),
            layouts: [frame, decode],
            visibility: hooks.visibility_layout().map(|v| (filler, v)),
        };
        let made = TiledLighting::new(ctx, &desc)?;
        self.tiled.push((side, made));
        Ok(())
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

    /// Frees everything now, without the device-wide wait that dropping does once this has
    /// recorded (`vkDeviceWaitIdle`, which Vulkan counts as a use of every queue of the
    /// device): an engine that submits from other threads frees through this, once its own
    /// fences say the GPU is done.
    ///
    /// # Safety
    /// The GPU has finished every command buffer recorded with this lighting.
    pub unsafe fn destroy(mut self) {
        self.in_flight.clear();
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
    /// Once this has recorded, waits for the device to go idle (so nothing else may use any
    /// of its queues meanwhile; [`DeferredLighting::destroy`] does not wait), then frees
    /// everything, also after a creation that failed half way.
    fn drop(&mut self) {
        let ctx: &Context = &self.ctx;
        let d = &ctx.device;
        self.in_flight.wait(ctx);
        self.pipelines.destroy(ctx);
        for (_, t) in &mut self.tiled {
            t.destroy(ctx);
        }
        for (_, p) in &mut self.depth_id {
            p.destroy(ctx);
        }
        for slot in &mut self.slots {
            slot.uniforms.destroy(ctx);
            slot.lights.destroy(ctx);
            slot.timer.destroy(ctx);
            slot.emulation.destroy(ctx);
        }
        if let Some(h) = self.hi_stencil.as_mut() {
            h.destroy(ctx);
        }
        if let Some(v) = self.volumes.as_mut() {
            v.destroy(ctx);
        }
        unsafe {
            d.destroy_descriptor_pool(self.pool, None);
            d.destroy_pipeline_layout(self.pipeline_layout, None);
            // The null ones (set 1 with an engine's decode hook) are no-ops.
            for l in self.set_layouts {
                d.destroy_descriptor_set_layout(l, None);
            }
        }
    }
}
