//! histencil for engines: the one crate an engine depends on.
//!
//! The talk's many-BRDF deferred lighting (the BRDF id in stencil bits, each light volume drawn
//! once per BRDF it touches under hierarchical stencil) and per-entity lightmaps for translucent
//! objects and particles, recorded into the engine's own command buffers on its own Vulkan 1.3
//! device. What an engine writes is re-exported here by name; the crates behind it stay
//! reachable as modules ([`brdf`], [`model`], [`scene`], [`alpha`], [`vk`]) for the rest.
//!
//! A frame, in order (README "Use it in your engine"; `examples/engine` is a whole engine):
//! 1. Lend the device once: [`Context::from_raw`] with a [`BorrowedDevice`] made with
//!    [`REQUIREMENTS`].
//! 2. Make the lighting once: [`DeferredLighting::new`] with a [`LightingDesc`] (stencil
//!    [`StencilLayout`], BRDF ids, formats, frames in flight, [`LightHooks`] for an engine's own
//!    G-buffer decode and shadows, compiled by `histencil-build`).
//! 3. Per frame, plan on plain data ([`plan_frame`] with [`PlanInputs`] and [`PlanSettings`]) and
//!    record ([`DeferredLighting::record`] with a [`LightingFrame`] and [`LightingTargets`]).
//! 4. Translucent entities: [`plan_entities`] then [`AlphaLightmaps::record`].
//!
//! Not here: histencil's own renderer, lab and file helpers (`histencil-vk`'s `tools`
//! feature, the `histencil` command line).

pub use histencil_alpha as alpha;
pub use histencil_brdf as brdf;
pub use histencil_model as model;
pub use histencil_scene as scene;
pub use histencil_vk as vk;

// BRDFs and lights.
pub use histencil_brdf::{Brdf, BrdfId};
pub use histencil_scene::{Light, LightKind, Material, Mesh, ParticleLayout, ParticleSystem};

// Planning (no Vulkan).
pub use histencil_model::{
    plan_frame, Aabb, DepthConvention, FarPlane, FlushPolicy, FramePlan, LightShape, Perspective,
    PlanError, PlanInputs, PlanSettings, StencilBits, StencilLayout, TechniqueChoice, View,
    ViewDesc,
};

// The device, the lighting, the hooks.
pub use histencil_vk::{
    aspect_of, gbuffer_stencil_reference, Backend, BorrowedDevice, BrdfSource, Context,
    DeferredLighting, DepthStencilFormat, DeviceRequirements, EngineHooks, Error, HookSetLayout,
    HookSets, ImageRef, ImageState, LightHooks, LightModules, LightingBreakdown, LightingDesc,
    LightingFrame, LightingTargets, LutTables, MixedTiles, Result, TileClassify, TileSide,
    TileStats, TiledFrame, ValidationLog, ValidationMessage, GBUFFER_FORMATS, REQUIREMENTS,
};

// Lightmaps for translucent entities.
pub use histencil_alpha::{plan_entities, ChoiceSettings, Viewer};
pub use histencil_vk::{
    mesh_bounds, AlphaEntity, AlphaEntityKind, AlphaLightmaps, AlphaLightmapsDesc, LightmapFrame,
    LightmapTimings,
};
