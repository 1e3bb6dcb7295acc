//! The frame contract every pass shares: the frame set's types and the push range
//! (`gpu_types`), the G-buffer's and HDR targets (`targets`), the ways a pass begins rendering
//! (`attachments`), the common pass states (`state`), and reading a frame back (`readback`).

pub(crate) mod attachments;
pub mod gpu_types;
pub(crate) mod readback;
pub mod state;
pub(crate) mod targets;
