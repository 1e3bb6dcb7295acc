//! One file per pass, one convention for all of them: a pass is an object made once that owns
//! its pipelines and the layouts and sets only it uses (`MeshPasses`, `Tonemap`, and outside
//! this folder `DeferredLighting`, `AlphaLightmaps` and the renderer's alpha pass), freed with
//! `destroy` (a creation that fails half way frees what it made); each frame it records from
//! one inputs struct (`MeshInputs`, `TonemapInputs`, `LightingFrame`, `LightmapFrame`,
//! `AlphaInputs`) through the caller's `Recording` (the encoder: it begins and ends the
//! pass's rendering, and `Recording::pass` gives the pass its label and, on a clock, its
//! time); no pass takes a bare command buffer, and the entry points an engine calls with its
//! own wrap it in one at once.
//! The lighting's
//! per-frame recording (`light_passes.rs`) and the light pipelines it creates per plan
//! (`light_pipelines.rs`) live here and belong to `DeferredLighting`.

pub(crate) mod depth_id;
pub mod geometry;
pub mod light_modules;
pub mod light_passes;
pub mod light_pipelines;
pub(crate) mod light_volumes;
pub mod names;
pub(crate) mod tiled;
pub mod tonemap;

pub(crate) use crate::gpu::frame::attachments::{
    begin_hdr_rendering, begin_hdr_rendering_as, clear_depth_stencil, color_attachment,
    depth_stencil_attachment, Load, CLEAR_BLACK,
};
