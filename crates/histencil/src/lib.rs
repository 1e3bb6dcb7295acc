//! histencil for engines: the one crate an engine depends on.
//!
//! The talk's many-BRDF deferred lighting (the BRDF id in stencil bits, each light volume drawn
//! once per BRDF it touches under hierarchical stencil) and per-entity lightmaps for translucent
//! objects and particles, recorded into the engine's own command buffers on its own Vulkan 1.3
//! device. What an engine writes is re-exported here by name; the crates behind it stay
//! reachable as modules ([`brdf`], [`model`], [`scene`], [`alpha`], [`vk`]) for the rest.
//!
//! A frame, in order (the book's "Engine integration: a lit frame", `docs/src/engine/index.md`;
//! `examples/minimal` lights one frame of its own G-buffer, `examples/engine` is a whole engine):
//! 1. Lend the device once: [`Context::from_raw`] with a [`BorrowedDevice`] made with
//!    [`REQUIREMENTS`].
//! 2. Make the lighting once: [`DeferredLighting::new`] with a [`LightingDesc`] (stencil
//!    [`StencilLayout`], BRDF ids, formats, frames in flight, [`LightHooks`] for an engine's own
//!    G-buffer decode and shadows, compiled by `histencil-build`).
//! 3. Per frame, plan on plain data ([`plan_frame`] with [`PlanInputs`] and [`PlanSettings`]) and
//!    record ([`DeferredLighting::record`] with a [`LightingFrame`] and [`LightingTargets`]);
//!    once the engine's fence says a frame finished, [`DeferredLighting::slot_finished`] with its
//!    slot (a slot still in flight is refused).
//! 4. Translucent entities: [`plan_entities`] then [`AlphaLightmaps::record`].
//!
//! Steps 1 to 3, given what an engine has: its device as `lent`, a recording command buffer
//! `cmd`, its camera `view` and `lights`, its `brdfs` with the world boxes (`bounds`) of the
//! objects drawn with each, and its images, the G-buffer already written in the built-in layout
//! ([`GBUFFER_FORMATS`]):
//! ```no_run
//! # use ash::vk;
//! # use histencil::prelude::*;
//! # unsafe fn light_a_frame(
//! #     lent: BorrowedDevice,
//! #     cmd: vk::CommandBuffer,
//! #     view: &ViewDesc,
//! #     lights: &[Light],
//! #     brdfs: Vec<BrdfId>,
//! #     bounds: &[Vec<Aabb>],
//! #     gbuffer: Vec<ImageRef>,
//! #     depth_stencil: ImageRef,
//! #     hdr: ImageRef,
//! # ) -> std::result::Result<(), Box<dyn std::error::Error>> {
//! // Once: lend the device (made with REQUIREMENTS' features), make the lighting.
//! // SAFETY: `lent` holds the engine's live handles, made and kept (outliving `ctx`) as
//! // `Context::from_raw`'s # Safety asks.
//! let ctx = unsafe { Context::from_raw(lent)? };
//! let layout = StencilLayout::new(brdfs.len() as u32, 0)?;
//! let desc = LightingDesc {
//!     layout,
//!     brdfs,
//!     extent: hdr.extent,
//!     depth_stencil_format: depth_stencil.format,
//!     hdr_format: hdr.format,
//!     frames_in_flight: 2,
//!     max_lights: 64,
//!     hi_stencil: false,
//!     hooks: LightHooks::Builtin,
//! };
//! let mut lighting = DeferredLighting::new(&ctx, &desc)?;
//! // The G-buffer pass draws the surfaces of each BRDF with its stencil reference and mask.
//! let (_reference, _write_mask) = desc.stencil_reference(desc.brdfs[0]).ok_or("unknown BRDF")?;
//!
//! // Every frame, after the G-buffer pass: plan on plain data, record into `cmd`.
//! let shapes: Vec<LightShape> = lights.iter().map(Light::shape).collect();
//! let inputs = PlanInputs { lights: &shapes, brdf_bounds: bounds, view: &View::new(view)? };
//! let settings = PlanSettings {
//!     technique: TechniqueChoice::Stencil,
//!     caps: Backend::Native.platform().caps(),
//!     flush: FlushPolicy::Auto,
//! };
//! let plan = plan_frame(&layout, &inputs, &settings)?;
//! let mut targets = LightingTargets { gbuffer, depth_stencil, hdr };
//! let frame = LightingFrame {
//!     slot: 0, // frame number % frames_in_flight
//!     view,
//!     lights,
//!     plan: &plan,
//!     clear_hdr: true,
//!     timestamps: false,
//!     brdf_source: BrdfSource::Formula,
//!     tile_stats: false,
//!     hook_sets: HookSets::default(),
//! };
//! // SAFETY: `cmd` is recording, outside any render pass, on the lent device; the images'
//! // states are those the engine's barriers left; slot 0 has not been recorded before.
//! unsafe { lighting.record(cmd, &frame, &mut targets)? };
//! // Each `targets` image's `state` is where the commands leave it: the engine's next
//! // barrier starts there. Submitting and waiting are the engine's; once this frame's fence
//! // is signalled: `lighting.slot_finished(frame.slot)?`, before the slot is recorded again.
//! # Ok(())
//! # }
//! ```
//!
//! Not here: histencil's own renderer, lab and file helpers (`histencil-vk`'s `tools`
//! feature, the `histencil` command line).

#![warn(missing_docs)]

pub use histencil_alpha as alpha;
pub use histencil_brdf as brdf;
pub use histencil_model as model;
pub use histencil_scene as scene;
pub use histencil_vk as vk;

/// Every type an engine names, and nothing else: `use histencil::prelude::*;` brings no module
/// (`vk`, `model`, `scene`, ...) and no `Result` into the engine's own namespace, where they
/// would meet its own `vk` (ash's), `model` crate or `Result`. The crate root re-exports all of
/// it too, beside the modules and [`Result`].
pub mod prelude {
    // BRDFs (histencil's and an engine's own) and lights.
    pub use histencil_brdf::{Brdf, BrdfId, BrdfSet, EngineBrdfSpec, EngineParam, MaterialRows};
    pub use histencil_scene::{
        Falloff, Light, LightKind, Material, Mesh, ParticleLayout, ParticleSystem,
    };
    pub use histencil_vk::{compile_brdf_set, probe_brdfs, probe_materials, BrdfModules};

    // Planning (no Vulkan).
    pub use histencil_model::{
        plan_frame, Aabb, DepthConvention, FarPlane, FlushPolicy, FramePlan, LightShape,
        Perspective, PlanError, PlanInputs, PlanSettings, StencilBits, StencilLayout,
        TechniqueChoice, View, ViewDesc,
    };

    // The device, the lighting, the hooks.
    pub use histencil_vk::{
        aspect_of, gbuffer_stencil_reference, Backend, BorrowedDevice, BrdfParams, BrdfSource,
        Cause, Context, DeferredLighting, DepthStencilFormat, DeviceRequirements, EngineHooks,
        Error, HookSetLayout, HookSets, ImageRef, ImageState, LightHooks, LightModules,
        LightingBreakdown, LightingDesc, LightingFrame, LightingTargets, LutTables, MixedTiles,
        StencilCheck, StencilReport, StillInFlight, TileClassify, TileSide, TileStats, TiledFrame,
        ValidationLog, ValidationMessage, GBUFFER_FORMATS, REQUIREMENTS,
    };

    // Lightmaps for translucent entities.
    pub use histencil_alpha::{plan_entities, ChoiceSettings, Viewer};
    pub use histencil_vk::{
        mesh_bounds, AlphaEntity, AlphaEntityKind, AlphaLightmaps, AlphaLightmapsDesc,
        LightmapFrame, LightmapTimings,
    };
}

pub use histencil_vk::Result;
pub use prelude::*;
