//! histencil-vk: the ash (Vulkan 1.3) deferred renderer and its forward reference.
//!
//! A frame is: G-buffer pass (surface attributes; each draw's BRDF slot into the stencil BRDF
//! bits), lighting pass (light volumes with the talk's stencil depth culling, additive into an
//! RGBA16F target), tonemap, readback. The forward reference draws the same scene with the same
//! light code (`crates/vk/shaders/include/light.glsl`) per pixel, and is the ground truth for error figures.
//!
//! Everything is named (objects, allocations) and every pass sits in a debug label; barriers are
//! derived in one place ([`access`]) from declared accesses. Tests run under the Khronos
//! validation layer with synchronisation validation, and any message fails them.

pub mod access;
mod alpha;
mod brdf_eval;
mod capture;
mod compute;
mod context;
mod debug;
mod deferred_lighting;
pub mod descriptors;
mod driver;
mod error;
pub mod gpu_types;
mod hi_stencil;
mod hooks;
#[cfg(feature = "tools")]
mod image_error;
mod lut;
mod materials;
mod meshes;
#[cfg(feature = "tools")]
mod output;
pub mod passes;
mod pipelines;
mod readback;
mod renderer;
mod requirements;
mod resources;
mod shader_consts;
mod spirv_bindings;
pub mod state;
mod targets;
mod teardown;
mod technique;
mod timing;
mod upload;

/// The compiled SPIR-V of every shader module (built by build.rs, never checked in).
pub mod shaders {
    include!(concat!(env!("OUT_DIR"), "/shaders.rs"));
}

pub use access::{aspect_of, ImageRef, ImageState, LightingTargets};
pub use alpha::{
    mesh_bounds, AlphaEntity, AlphaEntityKind, AlphaEntityRecord, AlphaLightmaps,
    AlphaLightmapsDesc, AlphaMode, LightmapFrame,
};
pub use brdf_eval::BrdfEvaluator;
pub use capture::SimulatorInputs;
pub use context::{BorrowedDevice, Context, ContextDesc, DepthStencilFormat};
pub use debug::{ValidationLog, ValidationMessage};
pub use deferred_lighting::{
    gbuffer_stencil_reference, DeferredLighting, LightingDesc, LightingFrame, TiledFrame,
};
pub use driver::{Canary, DriverInfo, CANARY_CALLS, CANARY_ID};
pub use error::{Error, Result};
pub use gpu_types::ProjectionError;
pub use histencil_model::{
    CostModel, DepthIdCosts, FlushPolicy, FrameChoice, TileStats, TiledCosts,
};
pub use hooks::{
    EngineHooks, HookSetLayout, HookSets, LightHooks, LightModules, DECODE_SET, VISIBILITY_SET,
};
#[cfg(feature = "tools")]
pub use image_error::{difference_image, masked_error, MaskedError};
pub use lut::{LutEvaluator, LutTables};
pub use materials::{
    mip_chain, plan_materials, srgb_to_linear, GpuMaterials, MaterialPlan, MaterialRecord, SetPlan,
    TextureKey,
};
#[cfg(feature = "tools")]
pub use output::{
    check_image_output, check_output_dir, check_output_file, image_format, save_image_as, save_png,
    write_atomically, ImageKind,
};
pub use passes::light_pipelines::BrdfSource;
pub use readback::{FrameImages, Readback};
pub use renderer::{Frame, Renderer, RendererDesc, DEFAULT_LUT_RESOLUTION};
pub use requirements::{DeviceRequirements, REQUIREMENTS};
pub use spirv_bindings::{reflect_bindings, ModuleBindings, Resource, ResourceKind};
pub use targets::{check_extent, GBUFFER_FORMATS};
pub use technique::{Backend, FrameDesc, MixedTiles, Shading, Technique, TileClassify, TileSide};
#[cfg(feature = "tools")]
pub use timing::median_of_sorted;
pub use timing::{FrameTimings, LightingBreakdown, LightmapTimings};
