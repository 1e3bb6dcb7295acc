//! The encoder: a command buffer being recorded (`recording::Recording`), the barriers derived
//! from a step's declared accesses (`declare`), commands and compute dispatches, uploads and
//! meshes, and the frame clock (`timing`).

pub(crate) mod commands;
pub(crate) mod compute;
pub(crate) mod declare;
pub(crate) mod meshes;
pub(crate) mod recording;
pub(crate) mod timing;
pub(crate) mod upload;
