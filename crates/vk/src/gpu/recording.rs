//! A command buffer histencil records into, and what it knows of its state: the one place the
//! state a recording needs is promised ([`Recording::new`], unsafe), and where whether dynamic
//! rendering is open is tracked, so that a function that must record outside rendering (a
//! barrier, a copy, a fill, a dispatch) or inside it (a draw) says so by asking for the command
//! buffer that way ([`Recording::outside`], [`Recording::inside`]) and a debug build checks it.
//! Modelled on wgpu-hal's `CommandEncoder`, whose docs state what each call needs of the
//! encoder's state.

use crate::gpu::context::Context;
use ash::vk;
use std::cell::Cell;

/// A command buffer being recorded on one context's device.
pub(crate) struct Recording<'a> {
    ctx: &'a Context,
    cmd: vk::CommandBuffer,
    /// Dynamic rendering is open (begun through this recording and not yet ended).
    rendering: Cell<bool>,
}

impl<'a> Recording<'a> {
    /// Starts tracking `cmd`, outside rendering.
    ///
    /// # Safety
    /// `cmd` is in the recording state, was allocated from `ctx`'s device on a queue family
    /// that supports what its users record (graphics for rendering and draws, compute for
    /// dispatches), and is outside any render pass or dynamic rendering; until this
    /// value is dropped only this value's users record into it, and they begin and end
    /// rendering through [`Recording::began_rendering`] and [`Recording::ended_rendering`].
    pub unsafe fn new(ctx: &'a Context, cmd: vk::CommandBuffer) -> Self {
        Self {
            ctx,
            cmd,
            rendering: Cell::new(false),
        }
    }

    /// The context the commands are recorded for.
    pub fn ctx(&self) -> &'a Context {
        self.ctx
    }

    /// The command buffer, for commands Vulkan allows outside rendering only (barriers,
    /// copies, fills, dispatches, query resets, beginning rendering).
    pub fn outside(&self) -> vk::CommandBuffer {
        debug_assert!(!self.rendering.get(), "recorded inside rendering");
        self.cmd
    }

    /// The command buffer, for commands inside rendering (draws, ending rendering).
    pub fn inside(&self) -> vk::CommandBuffer {
        debug_assert!(self.rendering.get(), "recorded outside rendering");
        self.cmd
    }

    /// The command buffer, for commands Vulkan allows inside and outside rendering alike
    /// (debug labels, timestamps, binding pipelines and sets, dynamic state).
    pub fn any(&self) -> vk::CommandBuffer {
        self.cmd
    }

    /// Whether rendering is open.
    pub fn is_rendering(&self) -> bool {
        self.rendering.get()
    }

    /// Notes that the caller began rendering on [`Self::outside`]'s command buffer.
    pub fn began_rendering(&self) {
        debug_assert!(!self.rendering.get(), "rendering begun twice");
        self.rendering.set(true);
    }

    /// Notes that the caller ended rendering on [`Self::inside`]'s command buffer.
    pub fn ended_rendering(&self) {
        debug_assert!(self.rendering.get(), "rendering ended while not open");
        self.rendering.set(false);
    }

    /// Ends the tracking, checking (in debug builds) that rendering was left closed, as every
    /// caller of histencil's recording functions is promised.
    pub fn finish(self) {
        debug_assert!(!self.rendering.get(), "a recording left rendering open");
    }
}
