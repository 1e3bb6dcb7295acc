//! What a lighting is made for and what each frame gives it: the engine API's plain data.

use crate::lighting::hooks::{HookSets, LightHooks};
use crate::passes::light_pipelines::BrdfSource;
use crate::passes::tiled::{MixedTiles, TileClassify, TileSide};
use ash::vk;
use histencil_brdf::BrdfId;
use histencil_model::{FramePlan, StencilLayout, ViewDesc};
use histencil_scene::Light;

/// What a [`DeferredLighting`](super::DeferredLighting) is made for: fixed for its lifetime.
#[derive(Clone, Debug)]
pub struct LightingDesc {
    /// Where the culling bit, the BRDF field and the engine's bits sit in the stencil.
    pub layout: StencilLayout,
    /// The BRDF of each stencil slot, in slot order.
    pub brdfs: Vec<BrdfId>,
    /// The size of every target.
    pub extent: vk::Extent2D,
    /// The depth-stencil target's format (a format with a stencil aspect).
    pub depth_stencil_format: vk::Format,
    /// The HDR target's format: any colour format the device blends into.
    pub hdr_format: vk::Format,
    /// How many frames the caller records before it waits for the oldest (at least 1).
    pub frames_in_flight: u32,
    /// The most lights a frame may carry.
    pub max_lights: u32,
    /// Emulate console hi-stencil, which the PS3-like and 360-like plans use (and 360-like
    /// save/restore): a word per 8x8 tile and two bytes per pixel of scratch. Without it only
    /// plans for the native backend can be recorded.
    pub hi_stencil: bool,
    /// Where the light shaders get each pixel's surface and each light's visibility:
    /// histencil's G-buffer and no shadows, or the engine's hooks ([`crate::EngineHooks`]).
    pub hooks: LightHooks,
}

impl LightingDesc {
    /// The stencil slot of `brdf`: its index in [`LightingDesc::brdfs`].
    pub fn slot_of(&self, brdf: BrdfId) -> Option<u32> {
        self.brdfs.iter().position(|b| *b == brdf).map(|i| i as u32)
    }

    /// The stencil reference and write mask with which the engine's G-buffer pass draws a
    /// surface of `brdf` ([`gbuffer_stencil_reference`] of its slot); `None` for a BRDF the
    /// lighting is not made with (its pixels would match no light pass). One numbering for the
    /// engine: its materials and its decode hook (`Surface::brdf`) name BRDF ids, and the slot
    /// a BRDF's pixels carry in stencil comes from here, so the two cannot disagree.
    pub fn stencil_reference(&self, brdf: BrdfId) -> Option<(u8, u8)> {
        gbuffer_stencil_reference(&self.layout, self.slot_of(brdf)?)
    }

    /// The stencil write mask of every G-buffer draw, whatever its BRDF: the BRDF field and the
    /// culling bit ([`LightingDesc::stencil_reference`]'s mask, one for all). An engine can bake
    /// it into its G-buffer pipelines and set only the reference per draw
    /// (`VK_DYNAMIC_STATE_STENCIL_REFERENCE`). Clear these bits to 0 before the G-buffer pass;
    /// a pixel no surface covers keeps 0, slot 0's id, and is left unlit because the decode
    /// hook returns false there (histencil's does at the far plane).
    pub fn stencil_write_mask(&self) -> u8 {
        self.layout.brdf_mask() | self.layout.culling_mask()
    }
}

/// One frame's lighting.
#[derive(Clone, Copy, Debug)]
pub struct LightingFrame<'a> {
    /// Which frame-in-flight slot's buffers and sets this frame uses (`< frames_in_flight`).
    pub slot: u32,
    /// The camera, as the plan was made with it.
    pub view: &'a ViewDesc,
    /// The frame's lights; the plan's light inputs index them.
    pub lights: &'a [Light],
    /// The plan, from [`histencil_model::plan_frame`] on the same lights and view.
    pub plan: &'a FramePlan,
    /// Clear the HDR target to black first; otherwise light adds onto its contents.
    pub clear_hdr: bool,
    /// Write a GPU timestamp after every step ([`DeferredLighting::step_timings`](super::DeferredLighting::step_timings)).
    pub timestamps: bool,
    /// Where shade passes read each BRDF's value: its formula, or its material's look-up table
    /// (the talk's LUT technique; [`DeferredLighting::set_lut_tables`](super::DeferredLighting::set_lut_tables) first, and the G-buffer's
    /// material index names the table).
    pub brdf_source: BrdfSource,
    /// Count hi-stencil tiles tested and culled and fragments shaded
    /// ([`DeferredLighting::tile_stats`](super::DeferredLighting::tile_stats)); needs `LightingDesc::hi_stencil`.
    pub tile_stats: bool,
    /// The engine's sets for its hooks (none with histencil's built-in hooks).
    pub hook_sets: HookSets,
}

/// One frame lit by the tiled technique ([`DeferredLighting::record_tiled`](super::DeferredLighting::record_tiled)): no plan, no
/// stencil; the BRDF of each pixel comes from its surface.
#[derive(Clone, Copy, Debug)]
pub struct TiledFrame<'a> {
    /// Which frame-in-flight slot's buffers and sets this frame uses (`< frames_in_flight`).
    pub slot: u32,
    /// The camera.
    pub view: &'a ViewDesc,
    /// The frame's lights.
    pub lights: &'a [Light],
    /// Clear the HDR target to black first; otherwise light adds onto its contents.
    pub clear_hdr: bool,
    /// The tiles' side: [`TileSide::for_context`] picks 8x8 where the quirk table says it is faster,
    /// and 16x16 on a GPU.
    pub side: TileSide,
    /// What a tile of several BRDFs does.
    pub mixed: MixedTiles,
    /// How the classification's work is shaped (the same results either way):
    /// [`TileClassify::for_context`] picks the faster for the driver (the quirk table).
    pub classify: TileClassify,
    /// The engine's sets for its hooks (none with histencil's built-in hooks).
    pub hook_sets: HookSets,
}

/// The stencil reference with which an engine's G-buffer pass writes BRDF slot `slot`, and the
/// write mask: the BRDF field and the culling bit (which must be 0 when lighting starts), so the
/// engine's own bits are left as they are. `None` for a slot the layout does not have.
pub fn gbuffer_stencil_reference(layout: &StencilLayout, slot: u32) -> Option<(u8, u8)> {
    (slot < layout.brdfs_in_use()).then(|| {
        (
            layout.brdf_reference(slot),
            // LightingDesc::stencil_write_mask's, which has no layout of its own to take.
            layout.brdf_mask() | layout.culling_mask(),
        )
    })
}
