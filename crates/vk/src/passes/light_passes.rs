//! The deferred lighting pass, driven by histencil-model's frame plan: every light's passes
//! (setup, per-BRDF mask and shade, cleanup, as `plan_light` derives them for the platform
//! backend), with the state of each draw translated by `Recording::apply` (`gpu/frame/state.rs`).
//!
//! This module only decides how each light is classified and which BRDFs it touches, and records
//! the plan; the stencil logic lives in the model, where the CPU simulator checks it.
//!
//! On backends with hi-stencil, the plan's hi-stencil writes, tests and flushes run on the GPU
//! tile surface of `crate::hi_stencil`, so its failures (stale tiles without a flush, preserved
//! bits on 360-like hardware without zeroing) show in the image as they would on the console.

use super::light_pipelines::{
    pipeline_key, BrdfSource, LightPipelineKey, LightPipelines, LightShader,
};
use super::{begin_hdr_rendering_as, Load, CLEAR_BLACK};
use crate::gpu::access::{uses_of, BufferAccess, Contents, ImageAccess, LightingTargets};
use crate::gpu::device::error::Result;
use crate::gpu::encoder::recording::Recording;
use crate::gpu::encoder::timing::StepTimer;
use crate::gpu::frame::state::FULLSCREEN;
use crate::hi_stencil::{
    plan_touches, tile_rect, GpuHierarchy, HiStencilSurface, TouchedTiles, WriteTiles,
};
use crate::passes::light_volumes::LightVolumes;
use crate::shader_consts::{LIGHT_DRAW_COUNT, LIGHT_DRAW_HI_STENCIL_TEST};
use ash::vk;
use histencil_brdf::BrdfId;
use histencil_model::{
    CompareOp, DepthRange, DepthState, FaceStencil, FramePlan, Geometry, HiStencilState, Pass,
    PassKind, PassState, Shader, StencilOp, Step,
};
use histencil_scene::Light;

/// Push constants of the light passes (include/light_draw.glsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LightDrawPush {
    /// The light's index in the frame's light buffer.
    pub light_index: u32,
    /// Unique per draw of a frame: the hi-stencil emulation marks covered tiles with it.
    pub stamp: u32,
    /// `LIGHT_DRAW_*` bits (`shader_consts::LIGHT_DRAW_FLAGS`).
    pub flags: u32,
    /// The stencil bit a restore draw writes.
    pub bit: u32,
}

/// The talk's pass group of a planned pass, for timings: `setup`, `mask-<brdf>`, `shade-<brdf>`
/// (`-branching` for the uber shader, `-lut` for the table shader), `cleanup`, `zero-preserved`.
pub fn pass_group(kind: PassKind, brdfs: &[BrdfId], source: BrdfSource) -> String {
    let shader = |s: Shader| match s {
        _ if source == BrdfSource::Table => "lut",
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

/// One frame's lighting as `DeferredLighting::record` hands it to the recorder: the plan and
/// everything its steps bind, borrowed for the recording only.
pub struct LightingPass<'a> {
    /// The recording the commands go through (its device, and whether rendering is open).
    pub(crate) rec: &'a Recording<'a>,
    /// The model's steps for this frame, in order.
    pub plan: &'a FramePlan,
    /// The frame's lights; a planned light's index points here and into the light buffer.
    pub lights: &'a [Light],
    /// The BRDF of each stencil slot, for the per-BRDF shaders and the timing groups.
    pub brdfs: &'a [BrdfId],
    /// The unit sphere and cone meshes a light's volume is drawn with.
    pub volumes: &'a LightVolumes,
    /// The pipelines made for this plan's pass states.
    pub pipelines: &'a LightPipelines,
    /// The layout of those pipelines, for binding sets and pushing [`LightDrawPush`].
    pub pipeline_layout: vk::PipelineLayout,
    /// Frame, G-buffer and hi-stencil sets, and the LUT set when shading from tables.
    pub sets: &'a [vk::DescriptorSet],
    /// The engine's visibility hook set, bound at set 4.
    pub visibility_set: Option<vk::DescriptorSet>,
    /// Whether shade passes evaluate each BRDF's formula or its material's table.
    pub brdf_source: BrdfSource,
    /// The size of the targets, for the render area and hi-stencil tile rectangles.
    pub extent: vk::Extent2D,
    /// Count tile and fragment statistics (extra draws and atomics).
    pub count_stats: bool,
    /// Clear the HDR target first (otherwise light adds onto it).
    pub clear_hdr: bool,
    /// The decode hook may sample the depth aspect: the depth-stencil is attached with
    /// read-only depth (`DEPTH_READ_ONLY_STENCIL_ATTACHMENT_OPTIMAL`). Light passes never
    /// write depth.
    pub depth_sampled: bool,
    /// The frame-in-flight slot, whose hi-stencil update set reads this frame's stencil.
    pub slot: u32,
    /// An engine's hooks bind their own resources (`LightHooks::Engine`), which their shaders
    /// may write: a split then orders every write, not only histencil's own buffers.
    pub(crate) engine_hooks: bool,
    /// On the AMD platforms, the GPU's own hierarchy the emulation follows
    /// (`crate::hi_stencil::amd`): evaluated before every pass it tests, which then rejects
    /// the tiles it rules out.
    pub hierarchy: Option<GpuHierarchy>,
}

/// The lighting's rendering into the HDR and depth-stencil attachments, open or not as the
/// recording says ([`Recording::is_rendering`]). Hi-stencil writes, flushes and the
/// preserved-bit copy happen outside rendering, so the lighting pass is split around them.
struct Rendering {
    /// The HDR target needs no clear (done by the first opening, or not asked for).
    cleared: bool,
    /// The buffers light shaders write (the hi-stencil surface's touched marks and
    /// statistics, [`HiStencilSurface::fragment_written`]): what a split hands over.
    counted: [vk::Buffer; 2],
    /// The hi-stencil's active tiles, which they read.
    tested: vk::Buffer,
}

impl Rendering {
    fn open(&mut self, pass: &LightingPass, targets: &mut LightingTargets) {
        if pass.rec.is_rendering() {
            return;
        }
        // The light shaders test the active tiles (a flush since the last opening rewrote them).
        pass.rec
            .declare_buffers(&[(self.tested, BufferAccess::FragmentRead)]);
        let hdr = if self.cleared {
            Load::Keep
        } else {
            Load::Clear(CLEAR_BLACK)
        };
        let attachments = (&mut targets.hdr, &mut targets.depth_stencil);
        let depth = if pass.depth_sampled {
            ImageAccess::StencilAttachmentDepthSampled
        } else {
            ImageAccess::DepthStencilAttachment
        };
        let loads = (hdr, Load::Keep);
        begin_hdr_rendering_as(pass.rec, attachments, pass.extent, loads, depth);
        self.cleared = true;
    }

    fn close(&mut self, pass: &LightingPass) {
        if pass.rec.is_rendering() {
            // The rendering `Rendering::open` began (the touch draw ends its own).
            pass.rec.end_rendering();
        }
    }

    /// Ends rendering and hands the buffers light shaders write over to the draws after:
    /// draws that share the statistics buffer cannot be ordered inside one dynamic rendering
    /// instance. Exact, not a full memory barrier (as it was until 2026-11-29): the attachments
    /// are handed over by `open`'s transitions, the stencil to the tile update by its own, and
    /// the tile surface's other buffers by the hi-stencil's reset, flush and save
    /// declarations (`Recording::declare_buffers` derives each barrier).
    /// Synchronisation validation does not see these buffers' hazards (with no barrier here
    /// at all every test passed on lavapipe, which runs draws in order, 2026-11-29); histencil's
    /// hazard check does (`gpu/device/hazards`, `tests/tests/hazards.rs`). What it found: the light
    /// shaders reach these buffers by atomics alone, which need no memory dependency between
    /// draws, so what the split gives the statistics draws is their order (ending the
    /// rendering, and the attachments' barriers when it opens again); the declaration's
    /// barrier hands over what they wrote. An engine's hooks bind resources
    /// histencil cannot see, which their shaders may write: with them, the full barrier.
    fn split(&mut self, pass: &LightingPass) {
        self.close(pass);
        if pass.engine_hooks {
            pass.rec.memory_barrier();
            return;
        }
        let rw = BufferAccess::FragmentReadWrite;
        pass.rec
            .declare_buffers(&self.counted.map(|buffer| (buffer, rw)));
    }
}

/// The emulator's bookkeeping timed apart from the technique it emulates: a timestamp on each
/// side of every piece of work a console does not do (resetting the tile surface; after a
/// hi-stencil write, ending rendering, drawing its volume into the touch image and
/// re-evaluating the tiles it touched; copying pending tiles to active at a flush), so the
/// `bookkeeping` group is that work and the rest of the lighting pass is the platform's
/// technique. What stays inside the technique's draws: reading the tile surface in a testing
/// draw, where hardware tests tiles before shading.
pub(crate) struct Emulation;

impl Emulation {
    /// The group of a span of the platform's own passes.
    pub const TECHNIQUE: &'static str = "technique";
    /// The group of a span of emulator bookkeeping.
    pub const BOOKKEEPING: &'static str = "bookkeeping";

    /// Timestamps `plan` needs after the start mark: one after the reset, two per hi-stencil
    /// write and flush and per evaluation of `hierarchy`, one at the end.
    pub fn marks(plan: &FramePlan, hierarchy: Option<&GpuHierarchy>) -> u32 {
        let ops = plan
            .steps
            .iter()
            .filter(|step| match step {
                Step::Pass { pass, .. } => {
                    pass.state.hi_stencil.is_some_and(|h| h.write)
                        || hierarchy.is_some_and(|h| h.test_for(pass).is_some())
                }
                Step::FlushHiStencil => true,
                _ => false,
            })
            .count() as u32;
        2 * ops + 2
    }
}

/// The two optional timers a recording writes: a timestamp after every step of the plan, and
/// the emulator's bookkeeping timed apart from the technique ([`Emulation`]). Every recorded
/// step goes through [`Timers::step`], every piece of bookkeeping through
/// [`Timers::bookkeeping`], so labels and timestamps are written in one place.
struct Timers<'t> {
    steps: Option<&'t mut StepTimer>,
    emulation: Option<&'t mut StepTimer>,
}

impl Timers<'_> {
    /// Records `body` as one step: inside the debug label `label`, then a step timestamp
    /// closing the span, named by `group` (the pass group and the scene light it lit).
    fn step<R>(
        &mut self,
        pass: &LightingPass,
        label: &str,
        group: impl FnOnce() -> (String, Option<u32>),
        body: impl FnOnce(&mut Self) -> R,
    ) -> R {
        let result = pass.rec.step(label, |_| body(self));
        if let Some(t) = self.steps.as_deref_mut() {
            let (group, light) = group();
            t.mark(pass.rec, group, light);
        }
        result
    }

    /// Records `body`, the emulator's bookkeeping: the span before it closes as the platform's
    /// technique, `body`'s own span as bookkeeping.
    fn bookkeeping(&mut self, pass: &LightingPass, body: impl FnOnce()) {
        self.mark(pass, Emulation::TECHNIQUE);
        body();
        self.mark(pass, Emulation::BOOKKEEPING);
    }

    /// Ends the emulation timer's span before it: `group` names what it timed.
    fn mark(&mut self, pass: &LightingPass, group: &str) {
        if let Some(t) = self.emulation.as_deref_mut() {
            t.mark(pass.rec, group.into(), None);
        }
    }
}

/// A stamp per draw that is unique in the frame and never 0 (the cleared `touched` value).
fn stamp(step: usize, count_draw: bool) -> u32 {
    2 * step as u32 + 1 + u32::from(count_draw)
}

impl LightingPass<'_> {
    /// Records the plan; with `timer`, a timestamp after every step; with `emulation`, one on
    /// each side of every piece of hi-stencil bookkeeping ([`Emulation::marks`]).
    pub(crate) fn record(
        &self,
        targets: &mut LightingTargets,
        hi_stencil: &mut HiStencilSurface,
        timer: Option<&mut StepTimer>,
        emulation: Option<&mut StepTimer>,
    ) -> Result<()> {
        let rec = self.rec;
        let mut timers = Timers {
            steps: timer,
            emulation,
        };
        // One pass: its label, and its time where `rec` has a clock (the renderer's frame).
        rec.pass(super::names::LIGHTING, |rec| {
            let (sampled, keep) = (ImageAccess::FragmentSampled, Contents::Keep);
            let mut uses = uses_of(&mut targets.gbuffer, sampled, keep);
            rec.declare(&mut uses);
            // Query resets are outside rendering.
            if let Some(t) = timers.steps.as_deref_mut() {
                t.reset(rec);
            }
            if let Some(t) = timers.emulation.as_deref_mut() {
                t.reset(rec);
                t.start(rec);
            }
            hi_stencil.record_reset(self.rec);
            // The light shaders count into the hi-stencil's touched marks and statistics.
            let counted = hi_stencil.fragment_written();
            rec.declare_buffers(&counted.map(|b| (b, BufferAccess::FragmentReadWrite)));
            timers.mark(self, Emulation::BOOKKEEPING);
            self.bind_sets();
            let mut rendering = Rendering {
                cleared: !self.clear_hdr,
                counted,
                tested: hi_stencil.fragment_read(),
            };
            rendering.open(self, targets);
            if let Some(t) = timers.steps.as_deref_mut() {
                t.start(rec);
            }
            // Each planned light's passes sit inside one label of its own.
            let mut current_light = None;
            let mut light_label = |light: Option<usize>| {
                if current_light == light {
                    return;
                }
                if current_light.is_some() {
                    rec.end_label();
                }
                current_light = light;
                if let Some(light) = light {
                    let input = self.plan.lights[light].input;
                    rec.begin_label(&format!("light-{input}"));
                }
            };
            let touches = plan_touches(self.plan);
            for (index, step) in self.plan.steps.iter().enumerate() {
                match step {
                    Step::Pass { light, pass } => {
                        light_label(Some(*light));
                        let scene_light = self.plan.lights[*light].input as u32;
                        let group = || {
                            let group = pass_group(pass.kind, self.brdfs, self.brdf_source);
                            (group, Some(scene_light))
                        };
                        timers.step(self, &pass.label(), group, |timers| {
                            let test = self.hierarchy.as_ref().and_then(|h| h.test_for(pass));
                            if let Some(test) = test {
                                timers.bookkeeping(self, || {
                                    rendering.close(self);
                                    let rect =
                                        tile_rect(self.extent, self.screen_rect(*light, pass));
                                    let ds = &mut targets.depth_stencil;
                                    hi_stencil.record_evaluate(self.rec, self.slot, ds, test, rect);
                                });
                            }
                            let bounded = (pass, self.plan.lights[*light].depth_range);
                            let tested = test.is_some();
                            self.record_pass(
                                targets,
                                &mut rendering,
                                index,
                                bounded,
                                scene_light,
                                tested,
                            );
                            if let Some(hi) = pass.state.hi_stencil.filter(|h| h.write) {
                                timers.bookkeeping(self, || {
                                    rendering.split(self);
                                    let touched =
                                        touches[index].expect("every write has its touch");
                                    let write = (*light, pass, &hi, touched);
                                    self.record_write_tiles(targets, hi_stencil, write);
                                });
                            }
                        });
                    }
                    Step::FlushHiStencil => {
                        let group = || ("flush".to_owned(), None);
                        timers.step(self, "flush-hi-stencil", group, |timers| {
                            timers.bookkeeping(self, || {
                                rendering.close(self);
                                hi_stencil.record_flush(self.rec);
                            })
                        });
                    }
                    Step::SavePreserved { .. } => {
                        let group = || ("save-preserved".to_owned(), None);
                        timers.step(self, "save-preserved", group, |_| {
                            rendering.close(self);
                            hi_stencil.record_save(self.rec, &mut targets.depth_stencil);
                        });
                    }
                    Step::RestorePreserved { mask } => {
                        light_label(None);
                        let group = || ("restore-preserved".to_owned(), None);
                        timers.step(self, "restore-preserved", group, |_| {
                            rendering.open(self, targets);
                            self.record_restore(*mask);
                        });
                    }
                }
            }
            light_label(None);
            rendering.close(self);
            timers.mark(self, Emulation::TECHNIQUE);
            if self.count_stats {
                hi_stencil.record_stats_readable(self.rec);
            }
        });
        Ok(())
    }

    /// Binds the frame's sets, and the engine's visibility set where it has one.
    fn bind_sets(&self) {
        let (rec, layout) = (self.rec, self.pipeline_layout);
        let graphics = vk::PipelineBindPoint::GRAPHICS;
        // SAFETY: the sets and the layout were made from this context's device by the
        // lighting, and the sets match the layout's set layouts from set 0 (and the visibility
        // layout at VISIBILITY_SET).
        unsafe {
            rec.bind_sets(graphics, layout, 0, self.sets);
            if let Some(set) = self.visibility_set {
                let first = crate::lighting::hooks::VISIBILITY_SET;
                rec.bind_sets(graphics, layout, first, &[set]);
            }
        }
    }

    /// Where plan light `light`'s `pass` lies on screen: its light's rectangle for a volume,
    /// `None` (the whole frame) for a full-screen pass.
    fn screen_rect(&self, light: usize, pass: &Pass) -> Option<histencil_model::NdcRect> {
        match pass.geometry {
            Geometry::Volume => self.plan.lights[light].screen_rect,
            Geometry::FullScreen => None,
        }
    }

    /// One planned pass: the statistics draw of a hi-stencil test (a console's, or with
    /// `hierarchy_tested` the GPU hierarchy's the caller evaluated) and the pass's own draw (the
    /// caller updates the tiles of a hi-stencil write).
    fn record_pass(
        &self,
        targets: &mut LightingTargets,
        rendering: &mut Rendering,
        step: usize,
        (pass, bounds): (&Pass, Option<DepthRange>),
        scene_light: u32,
        hierarchy_tested: bool,
    ) {
        let state = &pass.state;
        debug_assert!(
            !(state.tests_hi_stencil() && state.writes_stencil()),
            "check_frame refuses a hi-stencil test in a pass that writes stencil"
        );
        let shades = matches!(pass.kind, PassKind::Shade(_));
        let mut flags = 0;
        if state.tests_hi_stencil() || hierarchy_tested {
            flags |= LIGHT_DRAW_HI_STENCIL_TEST;
            if self.count_stats {
                self.split_for_counting(rendering);
                rendering.open(self, targets);
                let count = PassState {
                    depth: DepthState::OFF,
                    front: None,
                    back: None,
                    color_write: false,
                    hi_stencil: None,
                    // The statistics count every tile the draw covers, as the simulator does.
                    depth_bounds: false,
                    ..*state
                };
                let key = (pass.geometry, LightShader::CountTiles);
                let push = LightDrawPush {
                    light_index: scene_light,
                    stamp: stamp(step, true),
                    ..Default::default()
                };
                self.draw(key, &count, (pass.geometry, None), push);
            }
        }
        if shades && self.count_stats {
            flags |= LIGHT_DRAW_COUNT;
            self.split_for_counting(rendering);
        }
        rendering.open(self, targets);
        let push = LightDrawPush {
            light_index: scene_light,
            stamp: stamp(step, false),
            flags,
            bit: 0,
        };
        let tests = self.hierarchy.is_some();
        let key = pipeline_key(pass, self.brdfs, self.count_stats, self.brdf_source, tests);
        self.draw(key, state, (pass.geometry, bounds), push);
    }

    /// Outside rendering, after the hi-stencil write `hi` of plan light `light`'s `pass`: the
    /// emulator's bookkeeping. A volume write that learns its tiles by drawing
    /// ([`TouchedTiles::Drawn`]) draws the same volume with the same faces into the touch
    /// image, with no depth or stencil test (every covered pixel counts, whatever the write's
    /// tests did); then the tile update re-evaluates the touched tiles of the light's screen
    /// rectangle.
    fn record_write_tiles(
        &self,
        targets: &mut LightingTargets,
        hi_stencil: &mut HiStencilSurface,
        (light, pass, hi, touched): (usize, &Pass, &HiStencilState, TouchedTiles),
    ) {
        let rect = tile_rect(self.extent, self.screen_rect(light, pass));
        if touched == TouchedTiles::Drawn && !rect.is_empty() {
            hi_stencil.begin_touch(self.rec, rect);
            let state = PassState {
                cull: pass.state.cull,
                depth: DepthState {
                    compare: Some(CompareOp::Always),
                    write: true,
                },
                color_write: false,
                ..FULLSCREEN
            };
            let push = LightDrawPush {
                light_index: self.plan.lights[light].input as u32,
                ..Default::default()
            };
            let key = (Geometry::Volume, LightShader::TouchTiles);
            self.draw(key, &state, (Geometry::Volume, None), push);
            hi_stencil.end_touch(self.rec);
        }
        let ds = &mut targets.depth_stencil;
        let tiles = WriteTiles { touched, rect };
        hi_stencil.record_update(self.rec, self.slot, ds, hi, tiles);
    }

    /// Writes the saved preserved bits of `mask` back: one pass zeroes them, then one pass per
    /// bit sets it where the saved copy had it (stencil references are per draw, not per pixel).
    fn record_restore(&self, mask: u8) {
        let write = |write_mask: u8, reference: u8| {
            FaceStencil::writing(write_mask, reference, StencilOp::Replace, StencilOp::Keep)
        };
        let state = |face: FaceStencil| PassState {
            front: Some(face),
            back: Some(face),
            color_write: false,
            ..FULLSCREEN
        };
        let zero = (Geometry::FullScreen, LightShader::StencilOnly);
        self.draw(
            zero,
            &state(write(mask, 0)),
            (Geometry::FullScreen, None),
            LightDrawPush::default(),
        );
        for bit in (0..8).map(|b| 1u8 << b).filter(|b| mask & b != 0) {
            let push = LightDrawPush {
                bit: u32::from(bit),
                ..Default::default()
            };
            let key = (Geometry::FullScreen, LightShader::RestoreBit);
            self.draw(
                key,
                &state(write(bit, bit)),
                (Geometry::FullScreen, None),
                push,
            );
        }
    }

    /// Records one draw; `bounds` is the light's depth range for a pass confined to it.
    /// Splits the rendering before a statistics draw: its atomics follow the stamp protocol,
    /// which needs the draws before it finished (ending the rendering, and the attachments'
    /// barriers when it opens again, order them; atomics need no memory dependency). The
    /// hazard test that leaves it out (`HandOver::LightSplit`) finds the counted draws of one
    /// rendering unordered.
    fn split_for_counting(&self, rendering: &mut Rendering) {
        if crate::gpu::device::hazards::records(crate::gpu::device::hazards::HandOver::LightSplit) {
            rendering.split(self);
        }
    }

    fn draw(
        &self,
        key: LightPipelineKey,
        state: &PassState,
        (geometry, bounds): (Geometry, Option<DepthRange>),
        push: LightDrawPush,
    ) {
        let rec = self.rec;
        // SAFETY: inside rendering (`record_pass` opens the lighting's before a pass's draws,
        // `begin_touch` the touch image's, `Rendering::open` before a restore); the pipeline
        // was made for this plan's pass state (`prepare_pipelines`) with `pipeline_layout`,
        // whose push range holds a `LightDrawPush` for both stages.
        unsafe {
            let graphics = vk::PipelineBindPoint::GRAPHICS;
            rec.bind_pipeline(graphics, self.pipelines.get(key));
            let stages = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT;
            rec.push(self.pipeline_layout, stages, 0, bytemuck::bytes_of(&push));
        }
        rec.apply_bounded(state, bounds);
        // A statistics draw's atomics follow the stamp protocol (hi_stencil_count.frag counts a
        // tile the first time a draw's stamp meets it): they need the draws before finished,
        // which the split gives them. Other draws' atomics (none run) need no order.
        let counts = push.flags & LIGHT_DRAW_COUNT != 0 || key.1 == LightShader::CountTiles;
        rec.ordered_atomics(counts);
        match geometry {
            // SAFETY: inside rendering (`draw` checks it) with a full-screen pipeline bound just
            // above, its sets and state, which draws its triangle from the vertex index alone.
            Geometry::FullScreen => unsafe { rec.draw(3, 0) },
            Geometry::Volume => {
                let kind = &self.lights[push.light_index as usize].kind;
                self.volumes.draw(rec, kind);
            }
        }
        rec.ordered_atomics(false);
    }
}
