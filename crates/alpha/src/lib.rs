//! histencil-alpha: the talk's second technique, as far as it can be decided without a GPU.
//!
//! Alpha objects and particle systems cannot be lit by the deferred pass (they are not in the
//! G-buffer). The talk lights them on the GPU every frame instead: each entity owns a region of
//! one shared atlas holding its light probes (baked positions for objects; interpolated
//! positions for particle systems), every light that reaches the entity is rendered into that
//! region with the deferred pass's light code, and the alpha pass samples the result.
//!
//! # What this crate decides
//! - [`Atlas`]: where each entity's region sits, allocated and freed as entities come and go
//!   (a shelf allocator, etagere), with a guard band against filtering across regions and a
//!   documented downgrade when the atlas is full;
//! - [`side_for_coverage`]: how many texels an entity's size on screen can show;
//! - [`choose_parameters`]: how many slices and texels it needs, from a CPU estimate of the
//!   lightmap's error against per-pixel lighting;
//! - [`plan_regions`] (and [`plan_layout`] for a scene): every entity's region shape (a square for objects and billboards, a row
//!   of slices, a grid of motes, a line of texels for ribbons) packed into an atlas sized to fit;
//! - [`bake_probes`]: a translucent mesh's probes (position and normal per texel of its region),
//!   rasterised from its lightmap UV layout;
//! - [`fit_frame`]: the camera-facing probe quad (and slices) around a particle system;
//! - [`sprite_vertices`] and [`back_to_front`]: the alpha pass's geometry and blending order.

#![warn(missing_docs)]

mod atlas;
mod bake;
mod entity;
mod estimate;
mod layout;
mod plan;
mod probes;
mod sizing;
mod sprites;

pub use atlas::{Allocation, Atlas, AtlasError, Region, RegionId};
pub use bake::{bake_probes, BakedProbes, Probe};
pub use entity::{mesh_bounds, scene_alpha_entities, AlphaEntity, AlphaEntityKind, ProbeMeshes};
pub use estimate::{
    choose_parameters, coverage_side, estimate, Estimate, ParameterKind, Parameters, DEFAULT_TARGET,
};
pub use layout::{
    bounding_sphere, check_forced_side, dust_grid, entities, entity_problem, plan_regions,
    projected_diameter, region_shape, EntityDesc, EntityKey, EntityKind, EntityRegion, LayoutError,
    LightmapLayout, RegionShape, Viewer, ATLAS_PADDING, MAX_ATLAS_SIDE, MAX_FORCED_SIDE,
    START_ATLAS_SIDE,
};
pub use plan::{plan_entities, plan_layout, AlphaPlan, ChoiceSettings};
pub use probes::{back_to_front, camera_axes, fit_frame, particle_bounds, probe_point, ProbeFrame};
pub use sizing::{side_for_coverage, MAX_SIDE, MIN_SIDE, PIXELS_PER_TEXEL};
pub use sprites::{sprite_vertices, SpriteVertex};
