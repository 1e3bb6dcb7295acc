//! How what histencil makes is freed, also when making it fails half way.
//!
//! Resources are destroyed explicitly with the context (`destroy`), never by `Drop`, so
//! teardown order stays in the owner's hands; only the objects an engine holds (which keep
//! their context) free theirs on `Drop`, or leave them to the context while a frame they
//! recorded may still run ([`free_or_retire`]). Two helpers keep a failed creation from leaking
//! what its earlier steps made:
//! - [`build`] fills a value in place from its empty state, one step at a time, and destroys it
//!   when a step fails. It works because every `destroy` accepts a value only partly made:
//!   Vulkan's destroy calls take null handles, and an empty `Vec` frees nothing.
//! - [`Owned`] holds one finished part of a larger whole (a renderer's targets, its meshes) until
//!   the whole is made; dropped before [`Owned::keep`], it destroys its part.

use crate::gpu::device::context::Context;
use crate::gpu::device::error::{Error, Result};
use ash::vk;

/// A value made of Vulkan objects and allocations that frees them all. It must accept being
/// destroyed twice, and when only some of its parts exist.
pub(crate) trait Destroy {
    fn destroy(&mut self, ctx: &Context);
}

/// Several parts made one after another: each is destroyed.
impl<T: Destroy> Destroy for Vec<T> {
    fn destroy(&mut self, ctx: &Context) {
        for part in self.iter_mut() {
            part.destroy(ctx);
        }
        self.clear();
    }
}

/// Makes a `T` by running `steps` on its empty value. When a step fails, what the earlier ones
/// made is destroyed before the error is returned.
pub(crate) fn build<T: Default + Destroy>(
    ctx: &Context,
    steps: impl FnOnce(&mut T) -> Result<()>,
) -> Result<T> {
    let mut made = T::default();
    match steps(&mut made) {
        Ok(()) => Ok(made),
        Err(e) => {
            made.destroy(ctx);
            Err(e)
        }
    }
}

/// One finished part of something still being made: destroyed on drop unless kept.
pub(crate) struct Owned<'c, T: Destroy> {
    ctx: &'c Context,
    value: Option<T>,
}

impl<'c, T: Destroy> Owned<'c, T> {
    pub fn new(ctx: &'c Context, value: T) -> Self {
        Self {
            ctx,
            value: Some(value),
        }
    }

    /// The part, now the caller's to destroy.
    pub fn keep(mut self) -> T {
        self.value.take().expect("kept once")
    }
}

impl<T: Destroy> std::ops::Deref for Owned<'_, T> {
    type Target = T;
    fn deref(&self) -> &T {
        self.value.as_ref().expect("not yet kept")
    }
}

impl<T: Destroy> Drop for Owned<'_, T> {
    fn drop(&mut self) {
        if let Some(v) = self.value.as_mut() {
            v.destroy(self.ctx);
        }
    }
}

/// Implements [`Destroy`] by the types' own `destroy(&mut self, &Context)`.
macro_rules! destroy_by_method {
    ($($t:ty),* $(,)?) => {
        $(impl $crate::gpu::device::teardown::Destroy for $t {
            fn destroy(&mut self, ctx: &$crate::gpu::device::context::Context) {
                <$t>::destroy(self, ctx)
            }
        })*
    };
}
pub(crate) use destroy_by_method;

/// Whether an engine-facing object ([`crate::LutTables`]) may still be in use by the GPU when
/// it is dropped: from its making (any lighting may bind the tables) until its owner frees it
/// through its `unsafe fn destroy`, which promises the GPU is done.
#[derive(Default)]
pub(crate) struct InFlight(bool);

impl InFlight {
    pub fn mark(&mut self) {
        self.0 = true;
    }

    pub fn clear(&mut self) {
        self.0 = false;
    }

    pub fn any(&self) -> bool {
        self.0
    }
}

/// An engine-facing object's drop: runs `free` now, or, while the GPU may still use what it
/// frees (`in_use`), leaves it to the context ([`Context::retire`]), which frees it once the GPU
/// is known to be done. Histencil sees no fence and cannot know whether a command buffer it
/// recorded into was submitted, will be, or was dropped: a wait at the drop would not cover a
/// frame submitted after it (an engine that replaces its lighting between recording a frame and
/// submitting it), so nothing used by a frame in flight is freed before the context goes.
pub(crate) fn free_or_retire(
    ctx: &Context,
    in_use: bool,
    free: impl FnOnce(&Context) + Send + 'static,
) {
    if in_use {
        ctx.retire(Box::new(free));
    } else {
        free(ctx);
    }
}

/// Which frame-in-flight slots of an engine-facing owner (`DeferredLighting`,
/// `AlphaLightmaps`) hold a recorded frame the engine has not declared finished yet: histencil
/// submits nothing and sees no fence, so the engine says so (`slot_finished`), and until then
/// the slot is not recorded again, and the owner not resized or destroyed.
pub(crate) struct PendingSlots {
    /// Per slot, the command buffer its pending frame was recorded into; `None`: not pending.
    pending: Vec<Option<vk::CommandBuffer>>,
    /// The owner's name, for the refusals' advice (`DeferredLighting::slot_finished`).
    owner: &'static str,
    /// What a slot holds for its frame, for the refusals ("buffers and sets").
    holds: &'static str,
}

impl PendingSlots {
    /// `slots` slots, none pending.
    pub fn new(slots: u32, owner: &'static str, holds: &'static str) -> Self {
        Self {
            pending: vec![None; slots as usize],
            owner,
            holds,
        }
    }

    /// A frame was recorded into `slot` (in range: the owner checked it), in `cmd`.
    pub fn recorded(&mut self, slot: u32, cmd: vk::CommandBuffer) {
        self.pending[slot as usize] = Some(cmd);
    }

    /// The engine's `slot_finished(slot)`; a slot past the slots in flight is refused.
    pub fn finished(&mut self, slot: u32) -> Result<()> {
        let frames = self.pending.len();
        let pending = self.pending.get_mut(slot as usize).ok_or_else(|| {
            Error::BadFrame(format!(
                "slot_finished({slot}) of {frames} frames in flight"
            ))
        })?;
        *pending = None;
        Ok(())
    }

    /// Every slot finished: the owner's owner knows the GPU is done (histencil's renderer,
    /// after its device-wide wait).
    pub fn clear(&mut self) {
        self.pending.iter_mut().for_each(|p| *p = None);
    }

    /// Whether a slot is pending.
    pub fn any(&self) -> bool {
        self.pending.iter().any(Option::is_some)
    }

    /// Refuses `what` (a resize, a destroy) while a slot is pending, naming the slots.
    pub fn refuse_while_any(&self, what: &str) -> Result<()> {
        let slots: Vec<String> = (self.pending.iter().enumerate())
            .filter(|(_, pending)| pending.is_some())
            .map(|(i, _)| i.to_string())
            .collect();
        if slots.is_empty() {
            return Ok(());
        }
        Err(Error::InFlight(format!(
            "{what} while slot {} may still be read by the GPU: wait for those frames, and say \
             so with {}::slot_finished, first",
            slots.join(", "),
            self.owner
        )))
    }

    /// Refuses a recording of `slot` into `cmd` while the slot's last frame is pending (what
    /// the slot holds is that frame's until then), or while `cmd` is the command buffer of
    /// another slot's pending frame: an engine recording frame-in-flight k into the command
    /// buffer of frame j, whose slot k buffers would then be read under frame j's fence.
    pub fn refuse_slot(&self, slot: u32, cmd: vk::CommandBuffer) -> Result<()> {
        if self.pending.get(slot as usize).copied().flatten().is_some() {
            return Err(Error::InFlight(format!(
                "slot {slot} recorded again before {}::slot_finished({slot}) said the GPU \
                 finished its last frame: its {} are that frame's until then",
                self.owner, self.holds
            )));
        }
        if let Some(other) = self.pending.iter().position(|p| *p == Some(cmd)) {
            return Err(Error::InFlight(format!(
                "slot {slot} recorded into command buffer {cmd:?}, which holds slot {other}'s \
                 frame, still pending ({}::slot_finished({other}) has not said the GPU finished \
                 it): record each slot into the command buffer its own fence guards",
                self.owner
            )));
        }
        Ok(())
    }

    /// `value`'s destroy: refused while a slot is pending, with `value` handed back whole.
    pub fn destroy<T>(value: T, slots: impl Fn(&T) -> &PendingSlots) -> DestroyResult<T> {
        match slots(&value).refuse_while_any("destroy") {
            Ok(()) => Ok(()),
            Err(error) => Err(Box::new(StillInFlight { value, error })),
        }
    }
}

/// What an engine-facing owner's `destroy` returns.
pub(crate) type DestroyResult<T> = std::result::Result<(), Box<StillInFlight<T>>>;

/// What a refused `destroy` (of a [`crate::DeferredLighting`] or [`crate::AlphaLightmaps`])
/// gives back: the value, whole, and why.
pub struct StillInFlight<T> {
    /// What was not destroyed; dropping it leaves its objects to the context until the GPU is
    /// known to be done ([`Context::free_retired`], or the context's drop).
    pub value: T,
    /// [`Error::InFlight`], naming the slots.
    pub error: Error,
}

impl<T> std::fmt::Display for StillInFlight<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.error.fmt(f)
    }
}

/// The error alone: the value it holds need not be `Debug` (a lighting is not).
impl<T> std::fmt::Debug for StillInFlight<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StillInFlight")
            .field("error", &self.error)
            .finish_non_exhaustive()
    }
}

impl<T> std::error::Error for StillInFlight<T> {}
