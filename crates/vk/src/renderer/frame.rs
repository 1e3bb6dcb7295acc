//! One renderer frame: its passes in order (the forward pass, or the G-buffer, emission and
//! lighting through `DeferredLighting`; then alpha lightmaps and the alpha pass, tonemap,
//! readback), submitted and waited for.

use super::{Frame, Renderer};
use crate::alpha::AlphaInputs;
use crate::gpu::access::LightingTargets;
use crate::gpu::device::error::{Error, Result, VkCall};
use crate::gpu::encoder::recording::Recording;
use crate::gpu::encoder::timing::{progress_words, FrameTimings};
use crate::gpu::frame::readback::Readback;
use crate::gpu::frame::targets::GBUFFER_FORMATS;
use crate::hi_stencil::GpuHierarchy;
use crate::lighting::hooks::HookSets;
use crate::lighting::{LightingFrame, TiledFrame};
use crate::passes::geometry::{GbufferStencil, MeshInputs};
use crate::passes::light_pipelines::BrdfSource;
use crate::passes::names;
use crate::passes::tiled::TiledShade;
use crate::passes::tonemap::TonemapInputs;
use crate::renderer::technique::{FrameDesc, MixedTiles, Shading, Technique, TileClassify};
use ash::vk;
use histencil_model::{DepthConvention, FramePlan, ViewDesc};

impl<'c> Renderer<'c> {
    /// Renders one frame and waits for it: the forward reference ([`Shading::Forward`]) or a
    /// [`Technique`]'s deferred frame. `readback` says which images to copy back.
    pub fn render(&mut self, shading: impl Into<Shading>, readback: Readback) -> Result<Frame> {
        self.render_frame(&FrameDesc::new(shading, readback))
    }

    /// Renders the frame `desc` describes and waits for it.
    pub fn render_frame(&mut self, desc: &FrameDesc) -> Result<Frame> {
        let ctx = self.ctx;
        let view = self.frame_view(desc)?;
        self.alpha_lighting()?;
        let deferred = match desc.shading {
            Shading::Forward => None,
            Shading::Deferred(technique) => {
                let (technique, plan) = self.resolve_in(technique, &view)?;
                if technique.brdf_source() == BrdfSource::Table {
                    self.lut_tables()?;
                }
                Some((technique, plan))
            }
        };
        let hierarchy = match &deferred {
            Some((technique, _)) => self.gpu_hierarchy(desc, *technique)?,
            None => None,
        };
        let mut recording = self.begin_commands()?;
        self.timestamps.time(&mut recording);
        let rec = &recording;
        match &deferred {
            None => self.record_forward_pass(rec, desc),
            Some((technique, plan)) => {
                let lit = (*technique, hierarchy);
                self.record_deferred(rec, desc, lit, &view, plan)?
            }
        }
        if let Some(alpha) = self.alpha.as_mut() {
            let frame_set = self.descriptors.frame_set;
            let (scene, meshes) = (&self.scene, &self.meshes);
            // A timed pass of its own where the alpha mode has lightmaps
            // (`names::ALPHA_LIGHTMAPS`).
            alpha.record_lightmaps(rec, scene, &view, desc.alpha, desc.pass_timing)?;
            let inputs = AlphaInputs {
                scene,
                meshes,
                frame_set,
                mode: desc.alpha,
                extent: self.extent,
                depth: desc.depth,
            };
            let targets = &mut self.targets;
            // A timed pass of its own (`names::ALPHA`).
            alpha.record_alpha(rec, &inputs, targets)?;
        }
        let inputs = TonemapInputs {
            frame_set: self.descriptors.frame_set,
            extent: self.extent,
        };
        // A timed pass of its own (`names::TONEMAP`).
        self.tonemap.record(rec, &inputs, &mut self.targets);
        // Only the deferred frame has a G-buffer to read BRDF ids from.
        let readback = Readback {
            brdf_ids: desc.readback.brdf_ids && deferred.is_some(),
            ..desc.readback
        };
        self.readback.record(rec, &mut self.targets, readback);
        self.submit_and_wait(recording)?;
        let mut timings = self.timestamps.read(ctx)?;
        let planned = deferred.as_ref().filter(|(t, _)| t.records_plan());
        if desc.pass_timing && planned.is_some() {
            timings.lighting = self.lighting.step_timings(0)?;
        }
        if planned.is_some() {
            timings.bookkeeping_ms = self.lighting.emulation_ms(0)?;
        }
        if let Some(alpha) = self.alpha.as_ref().filter(|_| desc.pass_timing) {
            timings.lightmaps = alpha.lightmap_timings()?;
        }
        let images = self.readback.read(readback, &self.desc.brdfs.set)?;
        let tile_stats = match &deferred {
            Some((t, plan)) if desc.tile_stats && t.records_plan() => {
                self.lighting.tile_stats(plan)
            }
            Some((Technique::DepthId { side }, _)) if desc.tile_stats => {
                Some(self.depth_id_stats(*side)?)
            }
            _ => None,
        };
        Ok(Frame {
            timings,
            images,
            tile_stats,
        })
    }

    /// The forward frame's one pass: every object lit by every light into the HDR target.
    fn record_forward_pass(&mut self, rec: &Recording, desc: &FrameDesc) {
        let mut targets = self.targets.lighting();
        let inputs = self.mesh_inputs(desc.depth);
        self.mesh_passes.record_forward(rec, &inputs, &mut targets);
        self.targets.lit(&targets);
    }

    /// The deferred frame's passes: the G-buffer, emission into the HDR target, and the
    /// lighting of `plan` through [`crate::DeferredLighting`], by `technique` and on an AMD
    /// platform emulating `hierarchy`.
    fn record_deferred(
        &mut self,
        rec: &Recording,
        desc: &FrameDesc,
        (technique, hierarchy): (Technique, Option<GpuHierarchy>),
        view: &ViewDesc,
        plan: &FramePlan,
    ) -> Result<()> {
        let ctx = self.ctx;
        // Emitted light goes into the HDR target once; the lighting adds onto it.
        let emits = self.scene.objects.iter().any(|o| o.material.emits());
        self.record_gbuffer_pass(rec, desc, emits);
        let tiled = match technique {
            Technique::Tiled { mixed, side } => Some((mixed, side, TiledShade::Kernels)),
            Technique::DepthId { side } => Some((MixedTiles::PerBrdf, side, TiledShade::DepthId)),
            _ => None,
        };
        if let Some((mixed, side, shade)) = tiled {
            let frame = TiledFrame {
                slot: 0,
                view,
                lights: &self.scene.lights,
                clear_hdr: !emits,
                side,
                mixed,
                classify: TileClassify::for_context(ctx),
                hook_sets: HookSets::default(),
            };
            let mut targets = self.targets.lighting();
            // SAFETY: as for `record_emulating` below; and the HDR target has `STORAGE` usage
            // (`Targets::new`), and the built-in hooks bind no engine resources. The lighting
            // records through `rec`, so the classification, the light lists and the lighting are
            // timed passes of this frame's clock.
            unsafe {
                let (cmd, lighting) = (rec.outside(), &mut self.lighting);
                lighting.record_tiled_with(cmd, &frame, &mut targets, shade, Some(rec))?;
            }
            self.targets.lit(&targets);
            return Ok(());
        }
        let frame = LightingFrame {
            slot: 0,
            view,
            lights: &self.scene.lights,
            plan,
            clear_hdr: !emits,
            timestamps: desc.pass_timing,
            brdf_source: technique.brdf_source(),
            tile_stats: desc.tile_stats,
            hook_sets: HookSets::default(),
        };
        let mut targets = self.targets.lighting();
        // SAFETY: `rec` was begun by `begin_commands` on this context's device, the one the
        // lighting was made with, and every pass before this one ended its rendering (the
        // lighting records through `rec`, `cmd`'s one recording); the targets are the
        // renderer's own, with the states it tracks (`Targets::lit` after each pass);
        // `begin_commands` declared slot 0 finished after the last frame's wait.
        unsafe {
            let cmd = rec.outside();
            let lighting = &mut self.lighting;
            lighting.record_emulating(cmd, &frame, &mut targets, hierarchy, Some(rec))?;
        }
        self.targets.lit(&targets);
        Ok(())
    }

    /// Resets the frame's command pool (its one command buffer; resetting pools, not single
    /// buffers, is what the best-practices layer asks for), begins the command buffer and
    /// returns the recording the frame's passes record through.
    pub(super) fn begin_commands(&mut self) -> Result<Recording<'c>> {
        // The renderer's last frame was submitted and waiting for it failed (a timeout or a
        // lost device): it records nothing more, and says why as the wait did (a device error).
        if let Some(result) = self.unfinished.get() {
            return Err(Error::Vulkan {
                call: "vkWaitForFences (an earlier frame's; the renderer records nothing more)",
                result,
            });
        }
        // SAFETY: every frame `submit_and_wait` submitted was waited for (`unfinished` is
        // `None`), so slot 0's last frame has finished, or was never submitted (an error before
        // the submit).
        unsafe { self.lighting.slot_finished(0)? };
        let (d, cmd) = (&self.ctx.device, self.cmd);
        // SAFETY: the pool and its one command buffer were made from this device and are used
        // by this renderer alone (`&mut self`); the buffer is not pending, as said above.
        unsafe {
            d.reset_command_pool(self.command_pool, vk::CommandPoolResetFlags::empty())
                .call("vkResetCommandPool")?;
            let begin = vk::CommandBufferBeginInfo::default()
                .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            d.begin_command_buffer(cmd, &begin)
                .call("vkBeginCommandBuffer")?;
        }
        if let Some(hazards) = self.ctx.hazards.get() {
            hazards.begun(cmd);
        }
        // SAFETY: `cmd` was begun just now, outside rendering, on the context's queue family
        // (graphics and compute); the renderer records into it through this recording alone.
        Ok(unsafe { Recording::new(self.ctx, cmd) })
    }

    /// Ends, submits and waits for the frame's command buffer, recorded through `rec`
    /// ([`Self::begin_commands`]'s).
    pub(super) fn submit_and_wait(&mut self, rec: Recording) -> Result<()> {
        let (ctx, cmd) = (self.ctx, rec.outside());
        self.timestamps.submitted(rec.finish());
        // SAFETY: `cmd` is recording (`begin_commands`) and outside rendering: every pass ends
        // its own. The fence is this renderer's, unsignalled (reset after each wait, created
        // unsignalled) and not in use by another submit. `Context::submit` holds the queue's
        // lock against histencil's other submits (renderers sharing the context on several
        // threads), and `Context::from_raw`'s # Safety keeps a lent device's other users off.
        unsafe {
            ctx.device
                .end_command_buffer(cmd)
                .call("vkEndCommandBuffer")?;
            let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
            let submit = vk::SubmitInfo2::default().command_buffer_infos(&cmds);
            ctx.submit(&[submit], self.fence).call("vkQueueSubmit2")?;
            // Until the wait succeeds, a failure of it is what every later frame reports.
            self.unfinished.set(Some(vk::Result::TIMEOUT));
            let step = ctx.step("waiting on the GPU");
            if let Err(result) = self.wait_watching(step.as_deref()) {
                self.unfinished.set(Some(result));
                let progress = match self.timestamps.written(ctx) {
                    Some(n) => progress_words(self.timestamps.names(), n),
                    None => "the frame's timestamps cannot be read (the device is lost), so how \
                             far the GPU got is unknown"
                        .to_owned(),
                };
                return Err(Error::GpuStalled {
                    call: "vkWaitForFences",
                    result,
                    progress,
                });
            }
            self.unfinished.set(None);
            ctx.device
                .reset_fences(&[self.fence])
                .call("vkResetFences")?;
        }
        Ok(())
    }

    /// Waits for the frame's fence up to the context's fence timeout, in slices (50 ms, each
    /// twice the last, at most 1 s); where the observer saw `step`, after each slice it is
    /// told how far the GPU has got whenever that changed (the frame's timestamps: a runner
    /// that kills a hung worker keeps the GPU's own step).
    fn wait_watching(&self, step: Option<&str>) -> std::result::Result<(), vk::Result> {
        let ctx = self.ctx;
        let start = std::time::Instant::now();
        let timeout =
            std::time::Duration::from_nanos(crate::gpu::device::context::FENCE_TIMEOUT_NS);
        let mut slice = std::time::Duration::from_millis(50);
        let mut told = None;
        loop {
            let left = timeout.saturating_sub(start.elapsed());
            let wait = slice.min(left).as_nanos() as u64;
            // SAFETY: the fence is this renderer's, submitted with the frame just now; a
            // timed-out wait leaves it as it was, to be waited for again.
            let waited = unsafe { ctx.device.wait_for_fences(&[self.fence], true, wait) };
            if let (Ok(()), Some(hazards)) = (&waited, ctx.hazards.get()) {
                hazards.waited(self.fence);
            }
            match waited {
                Err(vk::Result::TIMEOUT) if left > slice => {}
                other => return other,
            }
            // A submission without a clock has no progress to tell.
            let timed = !self.timestamps.names().is_empty();
            if let Some(step) = step.filter(|_| timed) {
                let written = self.timestamps.written(ctx);
                if let Some(n) = written.filter(|n| told != Some(*n)) {
                    ctx.step_progress(step, &progress_words(self.timestamps.names(), n));
                    told = written;
                }
            }
            slice = (slice * 2).min(std::time::Duration::from_secs(1));
        }
    }

    /// Records the G-buffer pass into the renderer's targets, with the emitted light written
    /// into the HDR target where `emissive` (the deferred frame's, when the scene emits).
    pub(super) fn record_gbuffer_pass(
        &mut self,
        rec: &Recording,
        desc: &FrameDesc,
        emissive: bool,
    ) {
        let mut targets = self.targets.lighting();
        let (depth, pattern) = (desc.depth, desc.preserved_pattern);
        self.record_gbuffer_into(rec, &mut targets, (depth, pattern), emissive);
        self.targets.lit(&targets);
    }

    /// What the mesh passes draw this frame: the scene's objects with their materials.
    fn mesh_inputs(&self, depth: DepthConvention) -> MeshInputs<'_> {
        MeshInputs {
            scene: &self.scene,
            meshes: &self.meshes,
            frame_set: self.descriptors.frame_set,
            material_sets: &self.maps.object_sets,
            material_indices: &self.object_materials,
            extent: self.extent,
            depth,
        }
    }

    /// The pass [`names::GBUFFER`]: the G-buffer of `targets` written with the depth convention
    /// and preserved-bits pattern given, and where `emissive` the emitted light into its HDR
    /// image, which the lighting then adds onto (one label and one time for both).
    fn record_gbuffer_into(
        &self,
        rec: &Recording,
        targets: &mut LightingTargets,
        (depth, preserved_pattern): (DepthConvention, u8),
        emissive: bool,
    ) {
        let stencil = GbufferStencil {
            layout: &self.stencil_layout,
            slots: &self.object_slots,
            preserved_pattern,
        };
        let inputs = self.mesh_inputs(depth);
        rec.pass(names::GBUFFER, |rec| {
            let passes = &self.mesh_passes;
            passes.record_gbuffer(rec, &inputs, &stencil, targets);
            if emissive {
                passes.record_emissive(rec, &inputs, targets);
            }
        });
    }

    /// Records histencil's G-buffer pass of the scene (its camera, its objects) into another
    /// owner's images: the G-buffer and depth-stencil of `targets` are cleared and written, in
    /// the formats of the contract ([`crate::GBUFFER_FORMATS`], the context's depth-stencil
    /// format), and left attached-ready with their states updated; the HDR image is untouched.
    /// For engines and tests that light histencil's scenes with [`crate::DeferredLighting`].
    ///
    /// # Errors
    /// [`crate::Error::BadFrame`] when an image's extent or format differs from the renderer's.
    ///
    /// # Safety
    /// `cmd` is recording, outside a render pass, on the renderer's device; the G-buffer and
    /// depth-stencil images of `targets` are live with `COLOR_ATTACHMENT` and
    /// `DEPTH_STENCIL_ATTACHMENT` usage, and their states are true when `cmd` executes.
    pub unsafe fn record_gbuffer(
        &self,
        cmd: vk::CommandBuffer,
        targets: &mut LightingTargets,
    ) -> Result<()> {
        let images = targets.gbuffer.iter().zip(GBUFFER_FORMATS);
        let ds = (&targets.depth_stencil, self.ctx.depth_stencil_format);
        for (image, format) in images.chain([ds]) {
            if image.extent != self.extent || image.format != format {
                return Err(crate::Error::BadFrame(format!(
                    "a {:?} {}x{} image where the G-buffer pass writes {format:?} {}x{}",
                    image.format,
                    image.extent.width,
                    image.extent.height,
                    self.extent.width,
                    self.extent.height
                )));
            }
        }
        // SAFETY: this fn's # Safety is `Recording::new`'s, and the renderer's device is its
        // context's.
        let rec = unsafe { Recording::new(self.ctx, cmd) };
        self.record_gbuffer_into(&rec, targets, (DepthConvention::Standard, 0), false);
        rec.finish();
        Ok(())
    }

    /// Renders `frames` frames of `desc` without readback and returns the median of each
    /// timing.
    pub fn measure(&mut self, desc: impl Into<FrameDesc>, frames: usize) -> Result<FrameTimings> {
        Ok(FrameTimings::median(&self.measure_frames(desc, frames)?))
    }

    /// Renders `frames` frames (at least one) of `desc` without readback and returns each
    /// frame's timings, for callers that want the spread as well as the median.
    pub fn measure_frames(
        &mut self,
        desc: impl Into<FrameDesc>,
        frames: usize,
    ) -> Result<Vec<FrameTimings>> {
        let desc = FrameDesc {
            readback: Readback::NONE,
            ..desc.into()
        };
        (0..frames.max(1))
            .map(|_| Ok(self.render_frame(&desc)?.timings))
            .collect()
    }
}
