//! The validation canary. A validation verdict rests on the layer reporting what it finds, and
//! the layer reads settings from the environment and from `vk_layer_settings.txt` that can
//! silence it (a message-id filter, a duplicate-message limit, disabled checks).
//! [`Context::validation_canary`] makes one known invalid call on purpose, [`CANARY_CALLS`]
//! times, and counts what came back: anything short of every call reported means the verdict
//! cannot be trusted.

use crate::gpu::device::context::Context;
use crate::gpu::device::debug::CANARY_ID;
use ash::vk;
use std::fmt;

/// How many times the canary makes its invalid call: more than the layer's default duplicate
/// limit (10 in the layer's manifest), so a limit in force shows as missing reports.
pub const CANARY_CALLS: usize = 12;

/// What the canary saw.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Canary {
    /// Invalid calls made.
    pub calls: usize,
    /// Of them, reported by the layer with [`CANARY_ID`].
    pub reported: usize,
}

impl Canary {
    /// Every call was reported: the layer is listening and repeats itself.
    pub fn heard(&self) -> bool {
        self.reported >= self.calls
    }
}

impl fmt::Display for Canary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} of {} deliberate {CANARY_ID} calls reported by the validation layer",
            self.reported, self.calls
        )
    }
}

impl Context {
    /// Makes [`CANARY_CALLS`] deliberately invalid `vkCreateBuffer` calls (size zero) and counts
    /// the validation messages with [`CANARY_ID`] that arrived for them. Their messages stay in
    /// the log: take a mark after this call. On a context without validation (or a lent one,
    /// whose messages go to the engine's messenger) `reported` is 0.
    ///
    /// The layer is asked to stop each call it reports (histencil's messenger returns TRUE for
    /// [`CANARY_ID`], and the layer then returns `VK_ERROR_VALIDATION_FAILED_EXT`). A muted layer
    /// reports nothing and so passes the call on: the driver sees a buffer of size zero, which
    /// the drivers tried (lavapipe 22.3.6 and 25.0.7) create; it is destroyed at once.
    pub fn validation_canary(&self) -> Canary {
        let log = self.validation_log();
        let mark = log.len();
        let info = vk::BufferCreateInfo::default()
            .size(0)
            .usage(vk::BufferUsageFlags::STORAGE_BUFFER)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        for _ in 0..CANARY_CALLS {
            // SAFETY: invalid on purpose (size zero). A listening layer stops it; a muted one
            // passes it to the driver, and a buffer made of it is destroyed before any use.
            if let Ok(buffer) = unsafe { self.device.create_buffer(&info, None) } {
                // SAFETY: the buffer was just made, never bound or used.
                unsafe { self.device.destroy_buffer(buffer, None) };
            }
        }
        let reported = log.since(mark).iter().filter(|m| m.id == CANARY_ID).count();
        Canary {
            calls: CANARY_CALLS,
            reported,
        }
    }
}
