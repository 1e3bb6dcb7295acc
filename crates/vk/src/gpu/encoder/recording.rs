//! The encoder: the one way histencil records into a command buffer. A [`Recording`] owns the
//! state a recording has (whether dynamic rendering is open, which debug labels are open), so
//! that beginning and ending rendering, opening and closing a label, and asking for the command
//! buffer inside or outside rendering all go through it and a debug build checks each against
//! that state. No pass takes a bare `vk::CommandBuffer`: only the entry points do (an engine's
//! `unsafe fn record*` and the crate-private bodies they share with the renderer), each
//! recording through the renderer's `Recording` when the renderer hands it over, else wrapping
//! the engine's buffer in a `Recording` of its own at once. The commands
//! themselves (binds, pushes, draws, dispatches, fills, copies) are its methods in
//! `commands.rs`, each checked against the rendering state.
//!
//! Barriers, copies and dynamic state are its methods too, written beside what they serve.
//! Every barrier is derived by `crate::gpu::access` from what a step declares and recorded by
//! `declare.rs`: `declare` and
//! `transition` for images (`rec.declare(&mut [(image, access, contents), ..])`, one barrier
//! command taking them all there), `declare_buffers` for buffers, `declare_upload` for an
//! upload's levelled images, `host_readable` for what the host reads after the fence, and
//! `memory_barrier` where an engine's hooks bind what histencil cannot see. `apply` is in
//! `frame/state.rs`, `copy_image_to_buffer` in `frame/readback.rs`. Modelled on wgpu-hal's
//! `CommandEncoder` and Granite's `CommandBuffer`, which own `begin_render_pass` /
//! `end_render_pass` so pass state cannot be forgotten, and on kajiya's `record_pass_cb`, which
//! wraps each pass in its label: [`Recording::step`] does the label. A recording may also carry
//! a clock (`start_clock`, in `timing.rs`; the renderer's frame has one): then
//! `rec.pass(name, body)` is the label and a timestamp after the pass's commands in one call
//! (every pass of [`crate::passes::names`]: the G-buffer with its emissive draws, the forward
//! reference, the tiled classification and light lists, the lighting, the lightmaps, the alpha
//! pass, the tone map), which is both the frame's per-pass GPU time and the GPU-written marker
//! a stalled wait reports (`timing::progress_words`: the marks the GPU has written name the
//! passes it finished). The engine entry points record through the renderer's recording when
//! the renderer calls them, and through one of their own of the engine's command buffer
//! otherwise: a recording without a clock records the same commands, untimed.
//!
//! Methods take `&self`: the state is in `Cell`s, which makes a `Recording` `!Sync` (and the
//! clock's `Rc` `!Send`), so one thread records through it, as Vulkan's external
//! synchronisation of a command buffer asks; a
//! step's body records through the same shared reference it was handed, without reborrowing.

use crate::gpu::device::context::Context;
use ash::vk;
use std::cell::{Cell, RefCell};

/// Where a recording's passes write their end timestamps (`Recording::pass`): a timestamp
/// pool, how many marks it holds, and the names of the marks written so far (`start` first).
/// One recording's own: an entry point the renderer shares with engines records through the
/// renderer's recording (`record_tiled_with`, `record_emulating`, the lightmaps' `record_pass`),
/// so its passes are timed by this clock without one being lent.
pub(crate) struct PassClock {
    pub(super) pool: vk::QueryPool,
    pub(super) capacity: u32,
    pub(super) names: RefCell<Vec<&'static str>>,
}

/// A command buffer being recorded on one context's device.
pub(crate) struct Recording<'a> {
    ctx: &'a Context,
    cmd: vk::CommandBuffer,
    /// Dynamic rendering is open (begun through this recording and not yet ended).
    rendering: Cell<bool>,
    /// Debug labels opened through this recording and not yet closed.
    labels: Cell<u32>,
    /// The clock its timed passes write to, when it has one.
    pub(super) clock: Option<PassClock>,
}

impl<'a> Recording<'a> {
    /// Starts recording through `cmd`, outside rendering and labels.
    ///
    /// # Safety
    /// `cmd` is in the recording state, was allocated from `ctx`'s device on a queue family
    /// that supports what its users record (graphics for rendering and draws, compute for
    /// dispatches), and is outside any render pass or dynamic rendering; until this value is
    /// dropped only this value's users record into it.
    pub unsafe fn new(ctx: &'a Context, cmd: vk::CommandBuffer) -> Self {
        Self {
            ctx,
            cmd,
            rendering: Cell::new(false),
            labels: Cell::new(0),
            clock: None,
        }
    }

    /// The context the commands are recorded for.
    pub fn ctx(&self) -> &'a Context {
        self.ctx
    }

    /// The device the commands are recorded for.
    pub fn device(&self) -> &'a ash::Device {
        &self.ctx.device
    }

    /// The command buffer, for commands Vulkan allows outside rendering only (barriers,
    /// copies, fills, dispatches, query resets).
    pub fn outside(&self) -> vk::CommandBuffer {
        debug_assert!(!self.rendering.get(), "recorded inside rendering");
        self.cmd
    }

    /// The command buffer, for commands inside rendering (draws, clears of attachments).
    pub fn inside(&self) -> vk::CommandBuffer {
        debug_assert!(self.rendering.get(), "recorded outside rendering");
        self.cmd
    }

    /// The command buffer, for commands Vulkan allows inside and outside rendering alike
    /// (timestamps, binding pipelines and sets, push constants, dynamic state).
    pub fn any(&self) -> vk::CommandBuffer {
        self.cmd
    }

    /// Whether rendering is open.
    pub fn is_rendering(&self) -> bool {
        self.rendering.get()
    }

    /// Begins dynamic rendering as `info` says. Safe, as `transition` is: what it relies on is
    /// histencil's own bookkeeping (the `ImageRef` states), not a caller's promise about
    /// handles, which is what makes `bind_graphics` unsafe. Callers transitioned every attachment `info`
    /// names to the layout it is named with (`transition` on its `ImageRef`) and chose a render
    /// area inside the attachments.
    pub fn begin_rendering(&self, info: &vk::RenderingInfo) {
        let cmd = self.outside();
        // SAFETY: `cmd` records outside rendering (checked above in debug builds, and every
        // rendering is begun and ended here, so it is tracked); the attachments' layouts and
        // the render area are the callers' as said above; `info` outlives the call.
        unsafe { self.ctx.device.cmd_begin_rendering(cmd, info) };
        self.rendering.set(true);
    }

    /// Begins dynamic rendering over the whole `extent` of the attachments and sets the
    /// viewport and scissor to it: what every full-screen pass does.
    pub fn begin_rendering_over(
        &self,
        extent: vk::Extent2D,
        colors: &[vk::RenderingAttachmentInfo],
        depth_stencil: Option<&vk::RenderingAttachmentInfo>,
    ) {
        let area = vk::Rect2D::default().extent(extent);
        let mut info = vk::RenderingInfo::default()
            .render_area(area)
            .layer_count(1)
            .color_attachments(colors);
        if let Some(ds) = depth_stencil {
            info = info.depth_attachment(ds).stencil_attachment(ds);
        }
        self.begin_rendering(&info);
        self.set_viewport_and_scissor(area);
    }

    /// Sets the viewport (depth 0 to 1) and the scissor to `area`.
    pub fn set_viewport_and_scissor(&self, area: vk::Rect2D) {
        self.set_viewport(vk::Viewport {
            x: area.offset.x as f32,
            y: area.offset.y as f32,
            width: area.extent.width as f32,
            height: area.extent.height as f32,
            min_depth: 0.0,
            max_depth: 1.0,
        });
        self.set_scissor(area);
    }

    /// Sets the viewport. Safe: every pipeline histencil makes declares the viewport dynamic
    /// (`pipelines.rs`), and Vulkan allows it inside and outside rendering; callers keep it
    /// inside their attachments and its depths in 0 to 1.
    pub fn set_viewport(&self, viewport: vk::Viewport) {
        debug_assert!(
            viewport.width > 0.0
                && viewport.height > 0.0
                && (0.0..=1.0).contains(&viewport.min_depth)
                && (0.0..=1.0).contains(&viewport.max_depth),
            "an invalid viewport {viewport:?}"
        );
        // SAFETY: as said above; `viewport` outlives the call.
        unsafe { self.ctx.device.cmd_set_viewport(self.cmd, 0, &[viewport]) };
    }

    /// Sets the scissor, dynamic in every pipeline histencil makes; callers keep it inside
    /// their attachments.
    pub fn set_scissor(&self, area: vk::Rect2D) {
        // SAFETY: as for `set_viewport`.
        unsafe { self.ctx.device.cmd_set_scissor(self.cmd, 0, &[area]) };
    }

    /// Ends the rendering begun through this recording.
    pub fn end_rendering(&self) {
        let cmd = self.inside();
        // SAFETY: rendering is open on `cmd` (checked above in debug builds), begun by
        // `begin_rendering` on this recording.
        unsafe { self.ctx.device.cmd_end_rendering(cmd) };
        self.rendering.set(false);
    }

    /// Records `body` inside its own debug label region, `name`: a pass or a step of one. The
    /// context's step observer sees the label too (a hung worker's last line names it).
    pub fn step<R>(&self, name: &str, body: impl FnOnce(&Self) -> R) -> R {
        self.begin_label(name);
        let out = body(self);
        self.end_label();
        out
    }

    /// Opens a debug label region; [`Self::end_label`] closes it. Prefer [`Self::step`]; this
    /// pair is for regions that open and close as a loop goes (the lighting's, around its
    /// per-light labels, which open and close as the plan's steps change light).
    pub fn begin_label(&self, name: &str) {
        self.ctx.begin_label(self.cmd, name);
        if let Some(h) = self.hazards() {
            h.label(self.cmd, Some(name));
        }
        self.labels.set(self.labels.get() + 1);
    }

    /// Closes the innermost label region opened through this recording.
    pub fn end_label(&self) {
        debug_assert!(
            self.labels.get() > 0,
            "a label closed that was never opened"
        );
        self.ctx.end_label(self.cmd);
        if let Some(h) = self.hazards() {
            h.label(self.cmd, None);
        }
        self.labels.set(self.labels.get().saturating_sub(1));
    }

    /// The context's hazard check, when it has one: what the commands journal their buffer
    /// accesses and barriers to.
    pub(crate) fn hazards(&self) -> Option<&'a crate::gpu::device::hazards::Hazards> {
        self.ctx.hazards.get()
    }

    /// Tells the hazard check whether the next draws' and dispatches' atomics must run in order
    /// (a protocol across draws, as the hi-stencil statistics' stamps): then two of them need
    /// an execution dependency between them, where plain atomics need none.
    pub(crate) fn ordered_atomics(&self, ordered: bool) {
        if let Some(h) = self.hazards() {
            h.ordered_atomics(self.cmd, ordered);
        }
    }

    /// Records `body` through `outer` when given (the caller's recording of `cmd`, the
    /// renderer's, whose clock then times the body's passes), else through a recording of its
    /// own of `cmd` (an engine's buffer: untimed), finished after `body`. The one way the entry
    /// points an engine shares with the renderer record, so no clock is ever lent.
    ///
    /// # Safety
    /// Without `outer`, as [`Recording::new`] for `cmd` on `ctx`'s device; with it, `outer` is
    /// `cmd`'s one recording, outside rendering.
    pub(crate) unsafe fn through<R>(
        ctx: &'a Context,
        cmd: vk::CommandBuffer,
        outer: Option<&Recording<'_>>,
        body: impl FnOnce(&Recording<'_>) -> R,
    ) -> R {
        debug_assert!(
            outer.is_none_or(|r| r.any() == cmd),
            "another buffer's recording"
        );
        if let Some(rec) = outer {
            return body(rec);
        }
        // SAFETY: this fn's # Safety, without `outer`.
        let own = unsafe { Recording::new(ctx, cmd) };
        let out = body(&own);
        own.finish();
        out
    }

    /// Ends the recording, checking (in debug builds) that rendering and every label it opened
    /// were closed, as every caller of histencil's recording functions is promised. Returns
    /// the names of the marks its clock holds (`start`, then each timed pass), none without one.
    pub fn finish(self) -> Vec<&'static str> {
        debug_assert!(!self.rendering.get(), "a recording left rendering open");
        debug_assert_eq!(self.labels.get(), 0, "a recording left a label open");
        self.clock
            .map(|clock| clock.names.into_inner())
            .unwrap_or_default()
    }
}
