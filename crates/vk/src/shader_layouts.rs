//! Every shader module and the pipeline layout it is used with, gathered from the passes that own
//! the sets (each pass keeps its own set's table beside the code that writes it; the sets every
//! pass shares, the frame's and the G-buffer's, are `gpu::device::descriptors`'). The reflection
//! test (`tests/reflection.rs`) holds every module's SPIR-V to its layout here. A layout is its
//! sets in order: set N is element N.

use crate::alpha::lightmaps::ALPHA_SET;
use crate::alpha::ALPHA_LIGHTMAP_SET;
use crate::gpu::device::descriptors::{BindingDesc, FRAME_SET, GBUFFER_SET};
use crate::hi_stencil::{HI_STENCIL_SET, HI_STENCIL_UPDATE_SET};
use crate::lighting::lut::{LUT_EVAL_SET, LUT_SET};
use crate::passes::geometry::MATERIAL_SET;
use crate::passes::tiled::TILED_SET;
use crate::passes::tonemap::TONEMAP_SET;
use crate::tools::brdf_eval::BRDF_EVAL_SET;

/// The mesh pipelines: G-buffer, forward reference and emissive.
pub const MESH_LAYOUT: &[&[BindingDesc]] = &[FRAME_SET, MATERIAL_SET];
/// The light pipelines: deferred and LUT lights, hi-stencil count, stencil restore, footprint.
pub const LIGHTING_LAYOUT: &[&[BindingDesc]] = &[FRAME_SET, GBUFFER_SET, HI_STENCIL_SET, LUT_SET];
/// The tonemap pass.
pub const TONEMAP_LAYOUT: &[&[BindingDesc]] = &[FRAME_SET, TONEMAP_SET];
/// The BRDF evaluator's compute pipeline.
pub const BRDF_EVAL_LAYOUT: &[&[BindingDesc]] = &[BRDF_EVAL_SET];
/// The hi-stencil tile update's compute pipeline.
pub const HI_STENCIL_UPDATE_LAYOUT: &[&[BindingDesc]] = &[HI_STENCIL_UPDATE_SET];
/// The table lookup evaluator's compute pipeline.
pub const LUT_EVAL_LAYOUT: &[&[BindingDesc]] = &[LUT_EVAL_SET];
/// The alpha pass: translucent objects and particles.
pub const ALPHA_LAYOUT: &[&[BindingDesc]] = &[FRAME_SET, ALPHA_SET, ALPHA_LIGHTMAP_SET];
/// The lightmap pass renders into the atlas, so it does not bind it.
pub const LIGHTMAP_LAYOUT: &[&[BindingDesc]] = &[FRAME_SET, ALPHA_SET];
/// The tiled technique's compute passes and the depth-id technique's copy and shade.
pub const TILED_LAYOUT: &[&[BindingDesc]] = &[FRAME_SET, GBUFFER_SET, TILED_SET];

/// Every shader module and the pipeline layout it is used with.
pub const SHADER_LAYOUTS: &[(&str, &[&[BindingDesc]])] = &[
    ("mesh.vert", MESH_LAYOUT),
    ("gbuffer.frag", MESH_LAYOUT),
    ("forward.frag", MESH_LAYOUT),
    ("emissive.frag", MESH_LAYOUT),
    ("light_volume.vert", LIGHTING_LAYOUT),
    ("deferred_light.frag", LIGHTING_LAYOUT),
    ("lut_light.frag", LIGHTING_LAYOUT),
    ("hi_stencil_count.frag", LIGHTING_LAYOUT),
    ("restore_preserved.frag", LIGHTING_LAYOUT),
    ("footprint.frag", LIGHTING_LAYOUT),
    ("hi_stencil_update.comp", HI_STENCIL_UPDATE_LAYOUT),
    ("fullscreen.vert", LIGHTING_LAYOUT),
    ("tonemap.frag", TONEMAP_LAYOUT),
    ("brdf_eval.comp", BRDF_EVAL_LAYOUT),
    ("lut_eval.comp", LUT_EVAL_LAYOUT),
    ("lightmap.frag", LIGHTMAP_LAYOUT),
    ("lightmap_directional.frag", LIGHTMAP_LAYOUT),
    ("alpha_object.vert", ALPHA_LAYOUT),
    ("alpha_object.frag", ALPHA_LAYOUT),
    ("particle.vert", ALPHA_LAYOUT),
    ("particle.frag", ALPHA_LAYOUT),
    ("tile_classify.comp", TILED_LAYOUT),
    ("tile_lights.comp", TILED_LAYOUT),
    ("tile_shade.comp", TILED_LAYOUT),
    ("tile_classify_8.comp", TILED_LAYOUT),
    ("tile_shade_8.comp", TILED_LAYOUT),
    ("depth_id_copy.frag", TILED_LAYOUT),
    ("depth_id_shade.frag", TILED_LAYOUT),
];
