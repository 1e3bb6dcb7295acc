//! histencil-lab: what `histencil compare`, `sweep` and `calibrate` run, as a library an engine's
//! own tooling can call. Every speed figure comes with its error against the forward reference,
//! measured in the same run on the same device.
//!
//! - [`compare`]: the talk's table (lighting time with 1, 2, 3 BRDFs per technique and platform
//!   backend, overhead against the 1-BRDF time), the per-BRDF pass breakdown, and a light-size
//!   sweep showing where branching overtakes stencil and whether adaptive follows the better one.
//! - [`sweep`]: speed against error for one setting (LUT resolution, lightmap resolution,
//!   hi-stencil tile size), with its Pareto front.
//! - [`demo`]: a short tour of the talk on one scene (`histencil demo`, `tools/demo`): the
//!   techniques and backends side by side with their times, errors and hi-stencil statistics,
//!   and a contact sheet of the frames, the stencil byte and the talk's failures.
//! - [`scale`]: a scene at scale: its load time and device memory, and G-buffer, lighting and
//!   frame time of stencil (native, PS3-like) and branching, each with its error.
//! - [`calibrate()`]: this device's per-pass overhead, branch tax and shade cost, the
//!   [`CostModel`](histencil_vk::CostModel) that the adaptive technique chooses with.

mod alpha_reference;
pub mod calibrate;
pub mod compare;
mod contact_sheet;
pub mod demo;
mod image_error;
mod measure;
mod plot;
pub mod scale;
pub mod stats;
pub mod steady;
pub mod sweep;
pub mod todays_gpus;
mod variants;

pub use alpha_reference::AlphaReference;
pub use calibrate::{calibrate, calibrate_with, read_brdf_weights, read_costs, Calibration};
pub use compare::{run_compare, CompareReport, CompareSettings, MAX_ROUNDS};
pub use demo::{run_demo, DemoReport, DemoSettings, FailureAndFix};
pub use image_error::{image_error, ImageError};
pub use measure::Timing;
pub use scale::{run_scale, ScaleReport, ScaleSettings};
pub use sweep::{run_sweep, SweepParam, SweepReport};
pub use variants::{light_size_scene, with_brdf_count};

/// Why a lab run failed.
#[derive(Debug, thiserror::Error)]
pub enum LabError {
    #[error(transparent)]
    Vulkan(#[from] histencil_vk::Error),
    #[error(transparent)]
    Scene(#[from] histencil_scene::SceneError),
    #[error("cannot draw plot {path}: {problem}")]
    Plot { path: String, problem: String },
    #[error("cost model {path}: {problem}")]
    Costs { path: String, problem: String },
    #[error("{0}")]
    Settings(String),
}

pub type Result<T, E = LabError> = std::result::Result<T, E>;

/// Writes `value` as pretty JSON to `path`.
pub(crate) fn write_json(path: &std::path::Path, value: &serde_json::Value) -> Result<()> {
    let text = serde_json::to_string_pretty(value).expect("JSON values serialise");
    write_file(path, text.as_bytes())
}

/// Writes `bytes` to `path` whole or not at all ([`histencil_vk::write_atomically`]).
pub(crate) fn write_file(path: &std::path::Path, bytes: &[u8]) -> Result<()> {
    Ok(histencil_vk::write_atomically(path, bytes)?)
}
