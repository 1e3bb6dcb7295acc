//! The CPU simulator's inputs, captured from the GPU's own frame.

use super::Renderer;
use crate::gpu::device::error::Result;
use crate::gpu::device::resources::Buffer;
use crate::hi_stencil::GpuHierarchy;
use crate::renderer::capture::{FootprintCapture, SimulatorInputs};
use crate::renderer::technique::{Backend, FrameDesc, Technique, TileSide};
use crate::shader_consts::HI_STENCIL_TILE;
use ash::vk;
use histencil_model::amd::{choose_pretests, slot_tile_counts, Pretest, PRETEST_SLOTS};
use histencil_model::depth_id::{depth_id_stats, slot_id};
use histencil_model::{Footprint, SoftTarget, TileStats, TileSurface};

impl Renderer<'_> {
    /// The CPU simulator's inputs for the deferred frame `desc`, captured from the GPU: the
    /// G-buffer pass's depth and stencil, the plan, and each planned light's footprint as
    /// rasterised.
    /// `histencil_model::Simulator` run on them predicts the stencil and the hi-stencil
    /// statistics ([`super::Frame::tile_stats`]) the GPU frame produces.
    ///
    /// Every depth convention the frame can have is captured as the frame renders it: depths
    /// and footprints in the frame's convention (reversed Z stores far as 0), its far plane
    /// finite or at infinity.
    ///
    /// # Errors
    /// [`crate::Error::Unsupported`] for a forward frame (it has no stencil plan);
    /// [`crate::Error::MissingFormat`] without a 32-bit float depth buffer (the simulator
    /// compares f32 depths); besides the errors of
    /// [`Renderer::plan`] and of Vulkan calls.
    pub fn simulator_inputs(&mut self, desc: impl Into<FrameDesc>) -> Result<SimulatorInputs> {
        let desc = &desc.into();
        let Some(technique) = desc.shading.technique() else {
            return Err(crate::Error::Unsupported(
                "simulator inputs of a forward frame, which has no stencil to simulate",
            ));
        };
        let ctx = self.ctx;
        // The G-buffer pass and the captured volumes project with the frame's own view.
        let view = self.frame_view(desc)?;
        let plan = self.plan_in(technique, &view)?;
        let layout = self.lighting.pipeline_layout();
        let mut capture = FootprintCapture::new(ctx, layout, self.extent)?;
        let pixels = u64::from(self.extent.width) * u64::from(self.extent.height);
        let mut depth = Buffer::readback(ctx, "depth-readback", pixels * 4)?;
        let mut stencil = Buffer::readback(ctx, "simulator-stencil-readback", pixels)?;
        let result = (|| {
            let rec = self.begin_commands()?;
            self.record_gbuffer_pass(&rec, desc, false);
            let image = &mut self.targets.depth_stencil;
            rec.copy_image_to_buffer(image, vk::ImageAspectFlags::DEPTH, &depth);
            rec.copy_image_to_buffer(image, vk::ImageAspectFlags::STENCIL, &stencil);
            rec.host_readable(vk::PipelineStageFlags2::COPY);
            self.submit_and_wait(rec)?;
            let target = SoftTarget {
                width: self.extent.width,
                height: self.extent.height,
                depth: bytemuck::cast_slice(depth.read()).to_vec(),
                stencil: stencil.read().to_vec(),
            };
            let mut footprints = Vec::new();
            for (planned, light) in plan.lights.iter().enumerate() {
                let index = light.input as u32;
                if plan.is_full_screen(planned) {
                    let full = Footprint::full_screen(target.width, target.height);
                    footprints.push(full.in_convention(desc.depth));
                    continue;
                }
                let rec = self.begin_commands()?;
                // SAFETY: `rec` was just begun by `begin_commands`, outside rendering; the
                // frame set's layout is made identical to the lighting's frame set layout, set 0
                // of `layout` (`Descriptors::new`), and both live as long as the renderer.
                unsafe {
                    let graphics = vk::PipelineBindPoint::GRAPHICS;
                    rec.bind_sets(graphics, layout, 0, &[self.descriptors.frame_set]);
                }
                let light = &self.scene.lights[index as usize];
                capture.record(&rec, layout, self.lighting.volumes(), (index, light));
                self.submit_and_wait(rec)?;
                footprints.push(capture.footprint(desc.depth)?);
            }
            Ok(SimulatorInputs {
                layout: self.stencil_layout,
                tile_size: HI_STENCIL_TILE,
                target,
                plan,
                footprints,
            })
        })();
        capture.destroy(ctx);
        depth.destroy(ctx);
        stencil.destroy(ctx);
        result
    }
}

impl Renderer<'_> {
    /// The depth-id statistics of the depth-id frame just rendered with tiles of `side`: its id
    /// image as the GPU wrote it, read back, and the model's hierarchical depth run on it
    /// (`histencil_model::depth_id_stats`, 8x8 tiles): every BRDF slot's full-screen pass tests
    /// every tile, rejects those whose id range excludes its id, and shades its own pixels.
    /// llvmpipe has no hierarchical depth: the rejections are what such a GPU would make of
    /// these ids, the fragments what any GPU's EQUAL test shades.
    pub(super) fn depth_id_stats(&mut self, side: TileSide) -> Result<TileStats> {
        let ctx = self.ctx;
        let (width, height) = (self.extent.width, self.extent.height);
        let pixels = u64::from(width) * u64::from(height);
        let mut ids = Buffer::readback(ctx, "depth-id-readback", pixels * 2)?;
        let result = (|| {
            let rec = self.begin_commands()?;
            self.lighting.copy_depth_ids(&rec, side, 0, &ids);
            rec.host_readable(vk::PipelineStageFlags2::COPY);
            self.submit_and_wait(rec)?;
            let ids: &[u16] = bytemuck::cast_slice(ids.read());
            let tiles = TileSurface::new(width, height, HI_STENCIL_TILE);
            let passes: Vec<u16> = (0..self.brdfs.len() as u32).map(slot_id).collect();
            Ok(depth_id_stats(ids, width, &tiles, &passes))
        })();
        ids.destroy(ctx);
        result
    }
}

impl Renderer<'_> {
    /// The hierarchy the deferred frame `desc` lit by `technique` emulates: on the AMD
    /// platforms the GPU's own ([`crate::Backend::has_gpu_hierarchy`]), none elsewhere. GFX9-11
    /// binds its pretests before the G-buffer pass: [`Renderer::amd_pretests`].
    pub(super) fn gpu_hierarchy(
        &mut self,
        desc: &FrameDesc,
        technique: Technique,
    ) -> Result<Option<GpuHierarchy>> {
        if !technique.records_plan() {
            return Ok(None);
        }
        Ok(match technique.backend() {
            Backend::AmdAndOr => Some(GpuHierarchy::AndOr { read_mask: true }),
            Backend::AmdAndOrUnmasked => Some(GpuHierarchy::AndOr { read_mask: false }),
            Backend::AmdPretest => Some(GpuHierarchy::Pretests(self.amd_pretests(desc)?)),
            _ => None,
        })
    }

    /// The two pretests an AMD GFX9-11 frame binds (`histencil_model::amd::choose_pretests`),
    /// from how many 8x8 tiles of the frame's own G-buffer stencil hold each BRDF slot: a
    /// G-buffer pass of `desc`, read back, before the frame (an engine would use the previous
    /// frame's). The simulator's oracle makes the same choice from its captured stencil.
    pub fn amd_pretests(&mut self, desc: &FrameDesc) -> Result<[Option<Pretest>; PRETEST_SLOTS]> {
        let ctx = self.ctx;
        let (width, height) = (self.extent.width, self.extent.height);
        let pixels = u64::from(width) * u64::from(height);
        let mut stencil = Buffer::readback(ctx, "pretest-stencil-readback", pixels)?;
        let result = (|| {
            let rec = self.begin_commands()?;
            self.record_gbuffer_pass(&rec, desc, false);
            let image = &mut self.targets.depth_stencil;
            rec.copy_image_to_buffer(image, vk::ImageAspectFlags::STENCIL, &stencil);
            rec.host_readable(vk::PipelineStageFlags2::COPY);
            self.submit_and_wait(rec)?;
            let layout = &self.stencil_layout;
            let tiles = TileSurface::new(width, height, HI_STENCIL_TILE);
            let counts = slot_tile_counts(layout, stencil.read(), width, &tiles);
            Ok(choose_pretests(layout, &counts))
        })();
        stencil.destroy(ctx);
        result
    }
}
