//! histencil's hazard check through C: an engine's debug build turns it on for a context and
//! tells it what it submits and waits for; every buffer histencil's commands use is then held
//! to Vulkan's synchronisation rule across the engine's frames in flight (the book's "The
//! hazard check"), and the findings are read back as text.

use crate::device::HistencilContext;
use crate::handles::{self, Kind};
use crate::{call, slice, Failure, HistencilResult};
use ash::vk;
use std::ffi::c_char;

/// Turns the hazard check on for `context`, for an engine's debug builds and tests: from here
/// on histencil journals the buffers its commands use and the barriers they record, and checks
/// each submission the engine tells it of (`histencil_note_submit`) against those not yet
/// waited for. Turn it on before creating lightings (what was made before is not known to it).
/// Findings are read with `histencil_context_hazards`. Costs CPU time on every recorded
/// command: not for release builds.
///
/// Errors: `INVALID_ARGUMENT` for a null or freed context.
///
/// Thread safety: not while another call uses this context.
///
/// # Safety
/// `context` is null or a handle from `histencil_context_create`.
#[no_mangle]
pub unsafe extern "C" fn histencil_context_check_hazards(
    context: *mut HistencilContext,
) -> HistencilResult {
    call(|| {
        // SAFETY: this fn's # Safety; the header's thread-safety rule.
        let held = unsafe { handles::get(context, Kind::Context, "context") }?;
        held.ctx.check_hazards(held.hazards.clone());
        Ok(())
    })
}

/// Tells the hazard check that `cmd` was begun (`vkBeginCommandBuffer`, or its pool reset):
/// what it recorded before is forgotten. Nothing where the check is off.
///
/// Errors: `INVALID_ARGUMENT` for a null or freed context.
///
/// Thread safety: as `histencil_context_check_hazards`.
///
/// # Safety
/// As `histencil_context_check_hazards`.
#[no_mangle]
pub unsafe extern "C" fn histencil_note_begin(
    context: *mut HistencilContext,
    cmd: vk::CommandBuffer,
) -> HistencilResult {
    call(|| {
        // SAFETY: this fn's # Safety.
        let held = unsafe { handles::get(context, Kind::Context, "context") }?;
        held.ctx.note_begin(cmd);
        Ok(())
    })
}

/// Tells the hazard check that the `count` command buffers at `cmds` were submitted, in this
/// order, signalling `fence` (`VK_NULL_HANDLE` for none): what histencil recorded in them is
/// checked against every submission not yet waited for. Nothing where the check is off.
///
/// Errors: `INVALID_ARGUMENT` for a null or freed context, or a null `cmds` with a count.
///
/// Thread safety: as `histencil_context_check_hazards`.
///
/// # Safety
/// As `histencil_context_check_hazards`; `cmds` is null or points at `count` handles.
#[no_mangle]
pub unsafe extern "C" fn histencil_note_submit(
    context: *mut HistencilContext,
    cmds: *const vk::CommandBuffer,
    count: u32,
    fence: vk::Fence,
) -> HistencilResult {
    call(|| {
        // SAFETY: this fn's # Safety.
        let held = unsafe { handles::get(context, Kind::Context, "context") }?;
        // SAFETY: this fn's # Safety.
        let cmds = unsafe { slice(cmds, count, "cmds") }?;
        held.ctx.note_submit(cmds, fence);
        Ok(())
    })
}

/// Tells the hazard check that the host saw `fence` signalled (`vkWaitForFences`), or with
/// `VK_NULL_HANDLE` that the queue went idle (`vkQueueWaitIdle`, `vkDeviceWaitIdle`): those
/// submissions are complete. Nothing where the check is off.
///
/// Errors: `INVALID_ARGUMENT` for a null or freed context.
///
/// Thread safety: as `histencil_context_check_hazards`.
///
/// # Safety
/// As `histencil_context_check_hazards`.
#[no_mangle]
pub unsafe extern "C" fn histencil_note_wait(
    context: *mut HistencilContext,
    fence: vk::Fence,
) -> HistencilResult {
    call(|| {
        // SAFETY: this fn's # Safety.
        let held = unsafe { handles::get(context, Kind::Context, "context") }?;
        if fence == vk::Fence::null() {
            held.ctx.note_idle();
        } else {
            held.ctx.note_wait(fence);
        }
        Ok(())
    })
}

/// The hazard check's findings so far: their number in `count` and, where `text` is not null,
/// as many of their bytes as fit in `capacity` (one finding a line, each naming the buffer and
/// both passes, NUL-terminated, cut at a character boundary); `needed` (when not null) receives
/// the bytes the whole text takes, its NUL included. A clean run: `count` 0 and "".
///
/// Errors: `INVALID_ARGUMENT` for a null or freed context, or a null `count`.
///
/// Thread safety: as `histencil_context_check_hazards`.
///
/// # Safety
/// As `histencil_context_check_hazards`; `count` is writable; `text` is null or has
/// `capacity` writable bytes; `needed` is null or writable.
#[no_mangle]
pub unsafe extern "C" fn histencil_context_hazards(
    context: *mut HistencilContext,
    count: *mut u32,
    text: *mut c_char,
    capacity: usize,
    needed: *mut usize,
) -> HistencilResult {
    call(|| {
        // SAFETY: this fn's # Safety.
        let held = unsafe { handles::get(context, Kind::Context, "context") }?;
        if count.is_null() {
            return Err(Failure::invalid("count is null"));
        }
        let findings = held.hazards.problems();
        let all = findings.join("\n");
        // SAFETY: checked non-null; this fn's # Safety makes it writable.
        unsafe { count.write(findings.len() as u32) };
        if !needed.is_null() {
            // SAFETY: non-null, and writable by this fn's # Safety.
            unsafe { needed.write(all.len() + 1) };
        }
        if !text.is_null() && capacity > 0 {
            let mut end = all.len().min(capacity - 1);
            while !all.is_char_boundary(end) {
                end -= 1;
            }
            // SAFETY: `text` has `capacity` writable bytes (this fn's # Safety); `end + 1`
            // is at most `capacity`.
            unsafe {
                std::ptr::copy_nonoverlapping(all.as_ptr(), text.cast::<u8>(), end);
                text.add(end).write(0);
            }
        }
        Ok(())
    })
}
