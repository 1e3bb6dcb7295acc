//! The device layer: the device histencil borrows or owns, memory and images, barriers derived
//! from declared accesses, descriptors, pipelines, readback and upload, timing, names and
//! validation messages, and teardown that survives a creation failing half way. Everything
//! above it (the passes, the emulation, the engine API, the renderer) records through it
//! (`recording::Recording`, the encoder) and it imports nothing from above. Of the passes'
//! data it keeps what they share: the frame set (`FRAME_SET`, `FrameUniforms`, `GpuLight`),
//! the G-buffer's contract (`GBUFFER_SET`, `access::LightingTargets`, the renderer's
//! `targets`), the ways a pass begins rendering (`attachments`), the common pass states and
//! push range, and the timings' types; each pass keeps its own sets' tables and push blocks
//! (`crate::shader_layouts` gathers them).

pub mod access;
pub(crate) mod attachments;
pub(crate) mod commands;
pub(crate) mod compute;
pub(crate) mod context;
pub(crate) mod debug;
pub mod descriptors;
pub(crate) mod driver;
pub(crate) mod error;
pub mod gpu_types;
pub(crate) mod hazards;
pub(crate) mod limits;
pub(crate) mod meshes;
pub(crate) mod pipelines;
pub(crate) mod quirks;
pub(crate) mod readback;
pub(crate) mod recording;
pub(crate) mod requirements;
pub(crate) mod resources;
pub(crate) mod spirv_bindings;
pub mod state;
pub(crate) mod targets;
pub(crate) mod teardown;
pub(crate) mod timing;
pub(crate) mod upload;
