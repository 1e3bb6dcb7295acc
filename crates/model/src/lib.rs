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
//! `0xF0`. The BRDF field's width is derived from the number of BRDFs a scene uses, never
//! hard-coded; an engine that keeps its own data in some stencil bits puts the culling bit and the
//! BRDF field wherever its bits are not ([`StencilLayout::with_positions`]).
//!
//! # What this crate decides
//! - [`plan_frame`]: the whole frame's plan from plain inputs an engine has at hand
//!   ([`PlanInputs`]: light shapes, per-BRDF world boxes, a [`View`] from its own matrices with
//!   standard or reversed depth and a finite or infinite far plane), with one [`PlanSettings`]
//!   value per frame. No GPU, so every decision is testable on the CPU;
//! - [`StencilLayout`]: where the bits sit, derived from the BRDF count, at the engine's positions;
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
//! Today's AMD GPUs ([`amd`], modelled from AMD's driver sources, not measured on AMD hardware)
//! keep hierarchical stencil on their own, with no plan step: two masked pretests per frame
//! (GFX9-11) or each tile's AND and OR of its stencil values (GFX12); they run the native plan,
//! and [`Simulator::run_with`] counts what they would reject.

#![warn(missing_docs)]

pub mod amd;
mod backend;
mod chooser;
#[cfg(feature = "files")]
mod costs_json;
pub mod depth_bounds;
pub mod depth_id;
mod footprint;
mod frame;
mod layout;
mod light_shape;
mod plan;
mod planner;
mod sim;
mod state;
mod synthetic;
mod tiled_costs;
mod tiles;
mod view;

pub use backend::{Native, PlatformBackend, PlatformCaps, Ps3Like, X360Like};
pub use chooser::{CostModel, SlotWeights, TalkFigures};
#[cfg(feature = "files")]
pub use costs_json::{
    brdf_weights_from_json, CostsError, COST_FIELDS, DEPTH_ID_FIELDS, TILED_FIELDS,
};
pub use depth_bounds::DepthRange;
pub use footprint::{Footprint, Span};
pub use frame::{
    insert_flushes, write_test_dependencies, FlushPolicy, FramePlan, PlannedLight, Step,
};
pub use layout::{LayoutError, StencilBits, StencilLayout};
pub use plan::{
    plan_light, Geometry, LightCase, LightRequest, LightTechnique, Pass, PassKind, PlanError,
    Shader,
};
pub use planner::{
    plan_frame, Aabb, LightShape, PlanInputs, PlanSettings, PlannedFor, TechniqueChoice,
    MAX_SPOT_ANGLE, VOLUME_OVERSHOOT,
};
pub use sim::{LightShading, SimResult, Simulator, SoftTarget, NOT_SHADED};
pub use state::{
    CompareOp, CullMode, DepthState, FaceStencil, HiStencilState, PassState, StencilOp,
};
pub use synthetic::{SyntheticDesc, SyntheticFrame};
pub use tiled_costs::{DepthIdCosts, FrameChoice, TiledCosts};
pub use tiles::{TileStats, TileSurface};
pub use view::{DepthConvention, FarPlane, NdcRect, Perspective, View, ViewDesc, ViewError};
