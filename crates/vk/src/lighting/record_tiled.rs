//! The tiled and depth-id techniques recorded through a lighting: no plan and no stencil; the
//! classification, the light lists, then the tiled kernels or the depth-id passes
//! (`crate::passes::tiled`, `crate::passes::depth_id`).

use super::checks::{bad, check_slot_view_and_lights, check_targets, check_usage, UsageNeeds};
use super::{DeferredLighting, TiledFrame};
use crate::gpu::access::LightingTargets;
use crate::gpu::device::context::Context;
use crate::gpu::device::error::Result;
use crate::gpu::device::resources::Buffer;
use crate::gpu::encoder::recording::Recording;
use crate::lighting::hooks::LightHooks;
use crate::passes::depth_id::{DepthIdDesc, DepthIdPass};
use crate::passes::tiled::{MixedTiles, TileSide};
use crate::passes::tiled::{TiledDesc, TiledLighting, TiledSets, TiledShade};
use ash::vk;
use std::ops::Deref;

/// The HDR formats the tiled and depth-id techniques take (their kernels write the HDR image
/// as a storage image declared `rgba16f`); the light-volume techniques take any colour format
/// the engine renders to. An engine asks before making a lighting it will record them with.
pub const TILED_HDR_FORMATS: &[vk::Format] = &[vk::Format::R16G16B16A16_SFLOAT];

impl<C: Deref<Target = Context>> DeferredLighting<C> {
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
    /// [`Error::BadFrame`](crate::Error::BadFrame) when the frame does not fit this lighting (slot, light count, target
    /// extents and formats), [`Error::InFlight`](crate::Error::InFlight) for a slot not declared
    /// finished since its last frame, or the HDR format is not `R16G16B16A16_SFLOAT` (the kernels store
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
        // SAFETY: the caller upholds this fn's # Safety, which is `record_tiled_with`'s.
        unsafe { self.record_tiled_with(cmd, frame, targets, TiledShade::Kernels, None) }
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
    /// As [`DeferredLighting::record_tiled`], and [`Error::BadFrame`](crate::Error::BadFrame) for
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
        // SAFETY: the caller upholds this fn's # Safety: `record_tiled_with`'s, and the hook
        // resources readable by the fragment shaders the depth-id passes shade with.
        unsafe { self.record_tiled_with(cmd, frame, targets, TiledShade::DepthId, None) }
    }

    /// [`DeferredLighting::record_tiled`], through `outer` when given (the renderer's frame's
    /// recording of `cmd`, whose clock then times the classification, `tile-classify`, the
    /// light lists, `tile-lights`, and the shading, `lighting`, as passes of their own), else
    /// through a recording of its own of the engine's `cmd`, untimed.
    ///
    /// # Safety
    /// As [`DeferredLighting::record_tiled`]; with `outer`, that is `cmd`'s one recording,
    /// outside rendering.
    pub(crate) unsafe fn record_tiled_with(
        &mut self,
        cmd: vk::CommandBuffer,
        frame: &TiledFrame,
        targets: &mut LightingTargets,
        shade: TiledShade,
        outer: Option<&Recording>,
    ) -> Result<()> {
        if shade == TiledShade::DepthId && frame.mixed == MixedTiles::Branching {
            return Err(bad(
                "the depth-id technique shades each BRDF in a pass of its own: \
                 MixedTiles::Branching is the tiled kernels' (record_tiled)"
                    .to_owned(),
            ));
        }
        check_slot_view_and_lights(&self.desc, frame.slot, frame.view, frame.lights)?;
        check_targets(&self.desc, &frame.hook_sets, targets)?;
        let needs = UsageNeeds::tiled(&self.desc);
        check_usage(targets, &needs)?;
        self.pending.refuse_slot(frame.slot, cmd)?;
        self.refuse_if_torn()?;
        if let Some(why) = self.desc.hooks.tiled_refusal() {
            return Err(bad(format!(
                "the tiled technique's kernels cannot bind the hooks: {why}"
            )));
        }
        if !TILED_HDR_FORMATS.contains(&self.desc.hdr_format) {
            let technique = match shade {
                TiledShade::DepthId => {
                    "the depth-id technique (its tile classification binds \
                                        the HDR image as the tiled kernels do)"
                }
                _ => "the tiled technique",
            };
            return Err(bad(format!(
                "{technique} stores light as rgba16f, and the lighting's HDR format is {:?}: \
                 make the lighting with one of TILED_HDR_FORMATS ({TILED_HDR_FORMATS:?}) to \
                 record it",
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
        self.pending.recorded(frame.slot, cmd);
        let depth_sampled = self.desc.hooks.samples_depth();
        let (clear, mixed) = (frame.clear_hdr, frame.mixed);
        let shape = frame.classify;
        let record = |rec: &Recording| {
            // Each a pass of its own, timed where `rec` has a clock (the renderer's).
            tiled.record_classify(rec, &sets, targets, depth_sampled, clear, mixed, shape);
            tiled.record_light_lists(rec, frame.lights.len() as u32);
            // The lighting itself: one pass, whichever way its BRDFs' pixels are found.
            rec.pass(crate::passes::names::LIGHTING, |rec| match shade {
                TiledShade::Kernels => tiled.record_shade(rec, mixed, &mut targets.hdr),
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
                    let buffers = tiled.buffers();
                    pass.record(
                        rec,
                        frame.slot,
                        bound,
                        &push,
                        targets,
                        depth_sampled,
                        buffers,
                    );
                }
            });
        };
        // SAFETY: the caller's # Safety: `cmd` is recording on this context's device, on a queue
        // family with graphics and compute, outside any render pass; this call alone records
        // into it now, or `outer` is its recording (the renderer's).
        unsafe { Recording::through(ctx, cmd, outer, record) };
        Ok(())
    }

    /// Records a copy of frame-in-flight `slot`'s depth-id image for tiles of `side`, as its
    /// last depth-id frame left it, into `buffer` (2 bytes per pixel).
    pub(crate) fn copy_depth_ids(
        &mut self,
        rec: &Recording,
        side: TileSide,
        slot: u32,
        buffer: &Buffer,
    ) {
        // A recording of the slot's depth-id image: the slot is in flight until declared
        // finished, as after any recording (its caller, the renderer, declared it first).
        debug_assert!(
            self.pending.refuse_slot(slot, rec.any()).is_ok(),
            "slot {slot} copied while in flight"
        );
        self.pending.recorded(slot, rec.any());
        let (_, pass) = self
            .depth_id
            .iter_mut()
            .find(|(s, _)| *s == side)
            .expect("a depth-id frame was recorded");
        pass.copy_ids(rec, slot, buffer);
    }

    /// The set layout the decode hook binds at set 1: histencil's G-buffer's, or the engine's.
    fn decode_layout(&self) -> vk::DescriptorSetLayout {
        match &self.desc.hooks {
            LightHooks::Builtin | LightHooks::BuiltinWithBrdfs(_) => self.set_layouts[1],
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
}
