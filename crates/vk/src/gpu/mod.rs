//! The device layer, in four rooms, each importing only the rooms listed before it:
//!
//! - [`access`]: the vocabulary of declared accesses, images' and buffers', and the barriers
//!   and hand-overs derived from them; pure, so it is unit-tested, and it holds no Vulkan object.
//! - `device`: the device histencil borrows or owns and what lives as long as it: memory and
//!   images, descriptors and pipelines, the driver's facts, limits and quirks, validation
//!   messages, the hazard check, and teardown that survives a creation failing half way.
//! - `encoder`: recording commands (`encoder::recording::Recording`), which every pass goes
//!   through: its steps, labels and timed spans, the barriers its declarations derive, uploads,
//!   the frame clock.
//! - `frame`: the frame contract every pass shares: the frame set (`FRAME_SET`,
//!   `FrameUniforms`, `GpuLight`), the G-buffer's targets, the ways a pass begins rendering,
//!   the common pass states and push range, and reading a frame back.
//!
//! Everything above it (the passes, the emulation, the engine API, the renderer) records
//! through the encoder and it imports nothing from above. Each pass keeps its own sets' tables
//! and push blocks (`crate::shader_layouts` gathers them).

pub mod access;
pub(crate) mod device;
pub(crate) mod encoder;
pub(crate) mod frame;
