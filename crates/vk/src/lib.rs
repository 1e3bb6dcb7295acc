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

#![warn(missing_docs)]

// The layers, each recording through the ones below it: the device layer; the passes (one file
// per pass or technique) and the hi-stencil emulation; the engine API (`DeferredLighting`, its
// hooks, `AlphaLightmaps`); histencil's own renderer; and the tools its command line and lab use.
mod alpha;
mod brdf_modules;
pub mod gpu;
mod hi_stencil;
mod lighting;
pub mod passes;
mod renderer;
mod shader_consts;
#[cfg(feature = "files")]
mod shader_file;
pub mod shader_layouts;
mod tools;

// The device layer's public modules, at the crate's root where engines and tests find them.
pub use gpu::access;
pub use gpu::device::descriptors;
pub use gpu::frame::{gpu_types, state};

/// The compiled SPIR-V of every shader module (built by build.rs, never checked in).
pub mod shaders {
    include!(concat!(env!("OUT_DIR"), "/shaders.rs"));
}

pub use access::{aspect_of, ImageRef, ImageState, LightingTargets};
pub use alpha::{
    max_lightmap_side, mesh_bounds, AlphaEntity, AlphaEntityKind, AlphaEntityRecord,
    AlphaLightmaps, AlphaLightmapsDesc, AlphaMode, LightmapFrame,
};
pub use brdf_modules::{
    compile as compile_brdf_set, compile_with_hooks as compile_brdf_set_with_hooks, lut_refusal,
    probe_finite as probe_brdfs, probe_materials, BrdfModules,
};
pub use gpu::device::canary::{Canary, CANARY_CALLS};
pub use gpu::device::context::{
    BorrowedDevice, Context, ContextDesc, DepthStencilFormat, StepObserver,
};
pub use gpu::device::debug::CANARY_ID;
pub use gpu::device::debug::{ValidationLog, ValidationMessage};
pub use gpu::device::driver::DriverInfo;
pub use gpu::device::error::{Cause, Error, Result};
#[doc(hidden)]
pub use gpu::device::hazards::{omit_hand_over, HandOver, Omitted};
pub use gpu::device::limits::{describe as describe_limits, DeviceLimits, Limit, Need, NEEDS};
pub use gpu::device::quirks::{Quirk, QuirkRule, Quirks, QUIRKS};
pub use gpu::device::requirements::{DeviceRequirements, REQUIREMENTS};
pub use gpu::device::spirv_bindings::{reflect_bindings, ModuleBindings, Resource, ResourceKind};
pub use gpu::device::teardown::StillInFlight;
#[cfg(feature = "tools")]
pub use gpu::encoder::timing::median_of_sorted;
pub use gpu::encoder::timing::{FrameTimings, LightingBreakdown, LightmapTimings};
pub use gpu::frame::readback::{FrameImages, Readback};
pub use gpu::frame::targets::{check_extent, GBUFFER_FORMATS};
pub use gpu_types::ProjectionError;
pub use histencil_model::{
    CostModel, DepthIdCosts, FlushPolicy, FrameChoice, SlotWeights, TileStats, TiledCosts,
};
pub use lighting::hooks::{
    BrdfParams, EngineHooks, HookSetLayout, HookSets, LightHooks, LightModules, DECODE_SET,
    VISIBILITY_SET,
};
pub use lighting::lut::{LutEvaluator, LutTables};
pub use lighting::{
    frame_inputs_problem, gbuffer_stencil_reference, DeferredLighting, LightingDesc, LightingFrame,
    StencilCheck, StencilReport, TiledFrame, TILED_HDR_FORMATS,
};
pub use passes::light_pipelines::BrdfSource;
pub use renderer::capture::SimulatorInputs;
pub use renderer::materials::{
    mip_chain, plan_materials, srgb_to_linear, GpuMaterials, MaterialPlan, MaterialRecord, SetPlan,
    TextureKey,
};
pub use renderer::platform::Platform;
pub use renderer::technique::{
    Backend, FrameDesc, MixedTiles, Shading, Technique, TileClassify, TileSide,
};
pub use renderer::{Frame, Renderer, RendererDesc, DEFAULT_LUT_RESOLUTION};
#[cfg(feature = "files")]
pub use shader_file::{read_shader_file, write_shader_file, ShaderFile};
pub use tools::brdf_eval::{BrdfEvaluator, TintedCase};
#[cfg(feature = "tools")]
pub use tools::image_error::{difference_image, masked_error, MaskedError};
#[cfg(feature = "tools")]
pub use tools::output::{
    check_image_output, check_output_dir, check_output_file, image_format, save_image_as, save_png,
    write_atomically, ImageKind,
};
