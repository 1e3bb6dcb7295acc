//! How what histencil makes is freed, also when making it fails half way.
//!
//! Resources are destroyed explicitly with the context (`destroy`), never by `Drop`, so
//! teardown order stays in the owner's hands; only the objects an engine holds (which keep
//! their context) free theirs on `Drop`, waiting first as [`InFlight`] says. Two helpers keep a failed creation from leaking
//! what its earlier steps made:
//! - [`build`] fills a value in place from its empty state, one step at a time, and destroys it
//!   when a step fails. It works because every `destroy` accepts a value only partly made:
//!   Vulkan's destroy calls take null handles, and an empty `Vec` frees nothing.
//! - [`Owned`] holds one finished part of a larger whole (a renderer's targets, its meshes) until
//!   the whole is made; dropped before [`Owned::keep`], it destroys its part.

use crate::gpu::context::Context;
use crate::gpu::error::{Error, Result};

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
        $(impl $crate::gpu::teardown::Destroy for $t {
            fn destroy(&mut self, ctx: &$crate::gpu::context::Context) {
                <$t>::destroy(self, ctx)
            }
        })*
    };
}
pub(crate) use destroy_by_method;

/// Whether an engine-facing object ([`crate::DeferredLighting`], [`crate::AlphaLightmaps`],
/// [`crate::LutTables`]) may still be in use by the GPU when it is dropped: from its first
/// recording (tables: from their making, as any lighting may bind them) until its owner frees
/// it through its `unsafe fn destroy`, which promises the GPU is done.
///
/// Dropping an object in use waits for the device to go idle first. Vulkan counts that wait
/// as a use of every queue of the device, which an engine submitting from other threads cannot
/// allow; an object never recorded, or freed through `destroy`, does not wait.
#[derive(Default)]
pub(crate) struct InFlight(bool);

impl InFlight {
    pub fn mark(&mut self) {
        self.0 = true;
    }

    pub fn clear(&mut self) {
        self.0 = false;
    }

    /// Waits for the device to go idle if the object may still be in use.
    pub fn wait(&self, ctx: &Context) {
        if self.0 {
            // SAFETY: `vkDeviceWaitIdle` needs every queue of the device externally
            // synchronised. The callers are the engine-facing objects' Drops, whose condition
            // on a lent device is `Context::from_raw`'s # Safety (nothing else uses a queue
            // while one that recorded is dropped). On an owned context only histencil submits
            // (`submit_once`, a renderer's frame), and nothing here stops another thread
            // sharing the context from doing so during the wait.
            unsafe {
                let _ = ctx.device.device_wait_idle();
            }
        }
    }
}

/// Refuses `what` (a resize, a destroy) of `owner` (`DeferredLighting`, `AlphaLightmaps`) while
/// a slot holds a recorded frame not declared finished (`pending`, one flag a slot), naming the
/// slots: the engine said nothing of their fences yet, so the GPU may still read them.
pub(crate) fn refuse_in_flight(
    pending: impl Iterator<Item = bool>,
    what: &str,
    owner: &str,
) -> Result<()> {
    let slots: Vec<String> = (pending.enumerate())
        .filter(|(_, pending)| *pending)
        .map(|(i, _)| i.to_string())
        .collect();
    if slots.is_empty() {
        return Ok(());
    }
    Err(Error::InFlight(format!(
        "{what} while slot {} may still be read by the GPU: wait for those frames, and say so \
         with {owner}::slot_finished, first",
        slots.join(", ")
    )))
}

/// Refuses a recording into `slot` of `owner` while its last frame (`pending`) is not declared
/// finished: what the slot `holds` is that frame's until then.
pub(crate) fn refuse_slot_in_flight(
    pending: bool,
    slot: u32,
    owner: &str,
    holds: &str,
) -> Result<()> {
    if !pending {
        return Ok(());
    }
    Err(Error::InFlight(format!(
        "slot {slot} recorded again before {owner}::slot_finished({slot}) said the GPU finished \
         its last frame: its {holds} are that frame's until then"
    )))
}

/// Clears a slot's `pending` flag, as an engine's `slot_finished(slot)` declares it (`None`: a
/// slot past the `frames` in flight, refused).
pub(crate) fn declare_finished(pending: Option<&mut bool>, slot: u32, frames: usize) -> Result<()> {
    let pending = pending.ok_or_else(|| {
        Error::BadFrame(format!(
            "slot_finished({slot}) of {frames} frames in flight"
        ))
    })?;
    *pending = false;
    Ok(())
}
