//! histencil-model: everything about stencil bits and hi-stencil that can be decided without a GPU.
//!
//! # The talk's algorithm, in short
//! A deferred renderer normally runs one light shader for every pixel a light touches, so every
//! pixel gets the same BRDF. To allow several BRDFs without paying for a branch in every light
//! shader, each pixel's BRDF id is written into stencil bits by the G-buffer pass. Each light
//! volume is then drawn once per BRDF it actually touches, each time masked by stencil so only the
//! pixels of that BRDF run that BRDF's light shader.
//!
//! The same stencil byte already serves light *depth culling*: back faces of the light volume mark
//! a culling bit where the surface lies behind the volume, front faces shade where the bit is
//! clear, back faces clear it again. The talk packs both into one byte:
//!
//! ```text
//!   bit:   7   6   5   4 | 3   2   1 | 0
//!          preserved     | BRDF id   | culling
//!          (engine data) |           |
//! ```
//!
//! With 8 BRDFs in use: `culling_mask = 0x01`, `brdf_mask = 0x0E`, `brdf_shift = 1`, preserved
//! `0xF0`. The layout here is derived from the number of BRDFs a scene uses, never hard-coded.

//!
//! # What this crate decides
//! - [`StencilLayout`]: where the bits sit, derived from the BRDF count;
//! - [`plan_light`] / [`FramePlan`]: the ordered passes of every light with their full
//!   [`PassState`], for a [`PlatformBackend`] described as data ([`PlatformCaps`]);
//! - [`insert_flushes`]: when the hi-stencil surface must be flushed ([`FlushPolicy`]);
//! - [`Simulator`]: runs a plan on a software depth + stencil buffer with hi-stencil tiles
//!   ([`TileSurface`]); the oracle for the GPU;
//! - [`CostModel`]: stencil, branching or single-BRDF per light.
//!
//! # Platforms
//! The 360's hi-stencil compares all 8 bits: engine data in the preserved bits makes tiles fail
//! that should pass, so the 360-like backend zeroes those bits as it goes (setup and cleanup
//! write `!brdf_mask`), optionally saving and restoring them. The PS3's hi-stencil has a read
//! mask and leaves them alone. Native Vulkan has per-pixel compare masks and nothing to emulate.

mod backend;
mod chooser;
mod footprint;
mod frame;
mod layout;
mod plan;
mod sim;
mod state;
mod synthetic;
mod tiles;

pub use backend::{Native, PlatformBackend, PlatformCaps, Ps3Like, X360Like};
pub use chooser::{CostModel, TalkFigures};
pub use footprint::{Footprint, Span};
pub use frame::{insert_flushes, write_test_dependencies, FlushPolicy, FramePlan, Step};
pub use layout::{LayoutError, StencilLayout};
pub use plan::{
    plan_light, Geometry, LightCase, LightRequest, LightTechnique, Pass, PassKind, PlanError,
    Shader,
};
pub use sim::{LightShading, SimResult, Simulator, SoftTarget, NOT_SHADED};
pub use state::{
    CompareOp, CullMode, DepthState, FaceStencil, HiStencilState, PassState, StencilOp,
};
pub use synthetic::{SyntheticDesc, SyntheticFrame};
pub use tiles::{TileStats, TileSurface};
