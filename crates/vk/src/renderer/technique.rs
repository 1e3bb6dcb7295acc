//! What a renderer frame is: forward or deferred, the deferred frame's lighting technique (the
//! talk's, and the ones it is compared with), the platform behaviour the plan follows, and the
//! frame description that carries them.

use crate::alpha::AlphaMode;
use crate::gpu::frame::readback::Readback;
use crate::passes::light_pipelines::BrdfSource;
use crate::passes::names;
pub use crate::passes::tiled::{MixedTiles, TileClassify, TileSide};
use histencil_model::{
    CostModel, DepthConvention, FlushPolicy, Native, PlanSettings, PlatformBackend, Ps3Like,
    TechniqueChoice, X360Like,
};

/// The platform whose stencil and hi-stencil behaviour the lighting plan follows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Backend {
    /// 360-like: hi-stencil without a read mask. `zero_preserved` zeroes the engine's preserved
    /// bits as lights draw (the talk's fix); without it, hi-stencil fails on preserved bits.
    /// `save_restore` (with zeroing) copies them aside before lighting and writes them back after.
    X360 {
        /// Zero the preserved bits as lights draw (the talk's fix).
        zero_preserved: bool,
        /// Save the preserved bits before lighting and restore them after (with zeroing).
        save_restore: bool,
    },
    /// PS3-like: hi-stencil with a read mask; preserved bits survive.
    Ps3,
    /// Plain Vulkan: no hi-stencil.
    Native,
    /// AMD GFX9-11 (Vega, RDNA 1-3) with two hierarchical-stencil pretests bound, as AMD's
    /// driver layer PAL allows and no Vulkan driver does (`histencil_model::amd`): the native
    /// plan, with the GPU's per-tile may-pass bits emulated (`crate::hi_stencil::amd`).
    AmdPretest,
    /// AMD GFX12 (RDNA 4): the native plan, with the GPU's per-tile AND and OR of the stencil
    /// emulated.
    AmdAndOr,
    /// GFX12's tiles with a rule broken on purpose (a known-wrong case, no GPU): a test's read
    /// mask ignored, so engine bits in the preserved stencil bits reject tiles that hold
    /// passing pixels, the 360's failure (`histencil_model::amd::AndOrTiles::unmasked`).
    AmdAndOrUnmasked,
}

impl Backend {
    /// The model's platform: its name for reports and the caps the planner reads.
    pub fn platform(self) -> Box<dyn PlatformBackend> {
        match self {
            Backend::X360 {
                zero_preserved,
                save_restore,
            } => Box::new(X360Like {
                zero_preserved,
                save_restore,
            }),
            Backend::Ps3 => Box::new(Ps3Like),
            Backend::Native => Box::new(Native),
            Backend::AmdPretest => Box::new(histencil_model::amd::AmdPretest),
            Backend::AmdAndOr | Backend::AmdAndOrUnmasked => {
                Box::new(histencil_model::amd::AmdAndOr)
            }
        }
    }

    /// Whether the GPU keeps a hierarchical stencil of its own, which no plan step drives (the
    /// AMD platforms).
    pub fn has_gpu_hierarchy(self) -> bool {
        matches!(
            self,
            Backend::AmdPretest | Backend::AmdAndOr | Backend::AmdAndOrUnmasked
        )
    }
}

/// What a frame draws: the forward reference, or a G-buffer lit by a deferred technique. Forward
/// is a frame of its own (no G-buffer, no stencil, no lighting plan), not one more lighting
/// technique: what only deferred frames have hangs off [`Shading::Deferred`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shading {
    /// The forward reference: every object lit by every light per pixel, in one pass.
    Forward,
    /// The G-buffer pass, then the lighting passes of a technique.
    Deferred(Technique),
}

impl From<Technique> for Shading {
    fn from(technique: Technique) -> Self {
        Shading::Deferred(technique)
    }
}

impl Shading {
    /// The deferred frame's lighting technique; `None` for the forward frame.
    pub fn technique(self) -> Option<Technique> {
        match self {
            Shading::Forward => None,
            Shading::Deferred(technique) => Some(technique),
        }
    }

    /// The timed pass that lights the frame ([`crate::FrameTimings::pass_ms`]): `forward`, or
    /// `lighting` after the G-buffer.
    pub fn lighting_pass(self) -> &'static str {
        match self {
            Shading::Forward => names::FORWARD,
            Shading::Deferred(_) => names::LIGHTING,
        }
    }

    /// Every timed pass the frame's lighting may take: [`Shading::lighting_pass`], after the
    /// tiled technique's classification (`tile-classify`) and light lists (`tile-lights`) for
    /// that technique and for the adaptive one, which may light a frame tiled (a frame times
    /// only the passes it ran).
    pub fn lighting_passes(self) -> &'static [&'static str] {
        match self {
            Shading::Forward => &[names::FORWARD],
            Shading::Deferred(
                Technique::Tiled { .. } | Technique::DepthId { .. } | Technique::Adaptive { .. },
            ) => &[names::TILE_CLASSIFY, names::TILE_LIGHTS, names::LIGHTING],
            Shading::Deferred(_) => &[names::LIGHTING],
        }
    }
}

/// How a deferred frame's G-buffer is lit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Technique {
    /// The talk's technique: each light volume drawn once per BRDF it touches, masked by the
    /// BRDF id in the stencil, with one shader per BRDF.
    Stencil {
        /// The platform whose stencil and hi-stencil behaviour the plan follows.
        backend: Backend,
        /// When hi-stencil writes are flushed for later tests.
        flush: FlushPolicy,
    },
    /// One uber light shader branching on the G-buffer's BRDF id; one draw per light.
    Branching {
        /// The platform whose stencil and hi-stencil behaviour the plan follows.
        backend: Backend,
        /// When hi-stencil writes are flushed for later tests.
        flush: FlushPolicy,
    },
    /// Stencil or branching per light, whichever the renderer's [`CostModel`] predicts cheaper
    /// for the light's screen coverage and BRDF count (the talk's "tiny lights? try branching");
    /// or the whole frame tiled where costs measured on the device predict that surely cheaper
    /// than the plan ([`crate::Renderer::resolve`]).
    Adaptive {
        /// The platform whose stencil and hi-stencil behaviour the plan follows.
        backend: Backend,
        /// When hi-stencil writes are flushed for later tests.
        flush: FlushPolicy,
    },
    /// The talk's third option: one draw per light, as branching, with every BRDF read from its
    /// material's look-up table ([`crate::RendererDesc::lut_resolution`]) instead of its formula.
    /// Approximate: its error against forward falls with the table resolution.
    Lut {
        /// The platform whose stencil and hi-stencil behaviour the plan follows.
        backend: Backend,
        /// When hi-stencil writes are flushed for later tests.
        flush: FlushPolicy,
    },
    /// Today's engines' way (Unity HDRP's material tiles, UE5 Substrate's classification,
    /// Battlefield 3's tiled light lists): a compute pass classifies each tile by the BRDFs
    /// its pixels use and their depth range, a second lists the lights that can reach each
    /// tile, then one indirect dispatch per BRDF shades that BRDF's tiles with a kernel specialised to it, each pixel once by its
    /// own BRDF with its tile's lights (`passes/tiled.rs`). No stencil, no hi-stencil: the same
    /// on every platform. `mixed` says how tiles of several BRDFs are shaded, `side` how big a
    /// tile is.
    Tiled {
        /// How tiles that hold several BRDFs are shaded.
        mixed: MixedTiles,
        /// The tile's side.
        side: TileSide,
    },
    /// What Bevy's deferred renderer ships instead of stencil ids: each pixel's BRDF slot copied
    /// into a 16-bit depth image, then one full-screen pass per BRDF drawn at its slot's depth
    /// with compare EQUAL, so hierarchical depth rejects other BRDFs' tiles; each pixel adds
    /// its tile's lights from the tiled technique's light lists (`passes/depth_id.rs`). The
    /// same image as [`Technique::Tiled`], bit for bit. `side` is the light lists' tile.
    DepthId {
        /// The light lists' tile side.
        side: TileSide,
    },
}

impl Technique {
    /// Plain deferred shading: branching, no hi-stencil.
    pub const DEFERRED: Technique = Technique::Branching {
        backend: Backend::Native,
        flush: FlushPolicy::Auto,
    };

    /// What the planner is asked for. `costs` gives the adaptive technique's cost model for a
    /// backend.
    pub(crate) fn plan_settings(self, costs: impl FnOnce(Backend) -> CostModel) -> PlanSettings {
        let (technique, backend, flush) = match self {
            Technique::Stencil { backend, flush } => (TechniqueChoice::Stencil, backend, flush),
            Technique::Branching { backend, flush } => (TechniqueChoice::Branching, backend, flush),
            Technique::Adaptive { backend, flush } => {
                (TechniqueChoice::Adaptive(costs(backend)), backend, flush)
            }
            // Planned as branching: one draw per light, whatever the pixel's BRDF.
            Technique::Lut { backend, flush } => (TechniqueChoice::Branching, backend, flush),
            // Not planned: the classification decides on the GPU. The branching plan is what
            // the statistics and checks of a plan see.
            Technique::Tiled { .. } | Technique::DepthId { .. } => (
                TechniqueChoice::Branching,
                Backend::Native,
                FlushPolicy::Auto,
            ),
        };
        PlanSettings {
            technique,
            caps: backend.platform().caps(),
            flush,
        }
    }

    /// Whether frames of this technique record a lighting plan (the tiled and depth-id
    /// techniques classify on the GPU instead: no plan steps, no hi-stencil).
    pub fn records_plan(self) -> bool {
        !matches!(self, Technique::Tiled { .. } | Technique::DepthId { .. })
    }

    /// The platform behaviour the frame's plan follows (native for the tiled and depth-id
    /// techniques, which have none).
    pub fn backend(self) -> Backend {
        match self {
            Technique::Stencil { backend, .. }
            | Technique::Branching { backend, .. }
            | Technique::Adaptive { backend, .. }
            | Technique::Lut { backend, .. } => backend,
            Technique::Tiled { .. } | Technique::DepthId { .. } => Backend::Native,
        }
    }

    pub(crate) fn brdf_source(self) -> BrdfSource {
        match self {
            Technique::Lut { .. } => BrdfSource::Table,
            _ => BrdfSource::Formula,
        }
    }
}

/// One frame of the renderer: what to render and how, as one value (rather than settings that
/// stick to the renderer). What stays on the renderer rebuilds resources when it changes (LUT
/// resolution, lightmap sides) or is calibration (the cost model).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameDesc {
    /// Forward, or deferred with a lighting technique.
    pub shading: Shading,
    /// Which images to copy back.
    pub readback: Readback,
    /// Which end of depth is near in the renderer's depth buffer: its G-buffer, forward and
    /// alpha passes and the lighting plan follow it, as an engine's reversed-Z frame would.
    pub depth: DepthConvention,
    /// Project with the far plane at infinity (the camera's `far` unused).
    pub infinite_far: bool,
    /// How the alpha pass lights translucent objects and particles.
    pub alpha: AlphaMode,
    /// The engine's bits the G-buffer pass writes into the preserved stencil bits (only those
    /// of `StencilLayout::preserved_mask` are kept).
    pub preserved_pattern: u8,
    /// Time every lighting step and report the talk's pass groups
    /// (`FrameTimings::lighting`). Off by default: timestamps between draws can serialise them.
    pub pass_timing: bool,
    /// Count hi-stencil statistics (`Frame::tile_stats`): tiles tested and culled, fragments
    /// shaded, flushes. Off by default: counting adds a draw per hi-stencil test and an atomic
    /// per shaded fragment.
    pub tile_stats: bool,
}

/// A technique's deferred frame with everything else at its default and nothing read back (what
/// timing loops take).
impl From<Technique> for FrameDesc {
    fn from(technique: Technique) -> Self {
        FrameDesc::new(technique, Readback::NONE)
    }
}

/// A forward or deferred frame with everything else at its default and nothing read back.
impl From<Shading> for FrameDesc {
    fn from(shading: Shading) -> Self {
        FrameDesc::new(shading, Readback::NONE)
    }
}

impl FrameDesc {
    /// The frame of `shading` (a [`Technique`] for a deferred frame, or [`Shading::Forward`])
    /// with standard depth and the camera's far plane, alpha lightmaps, no preserved pattern, no
    /// step timing or statistics.
    pub fn new(shading: impl Into<Shading>, readback: Readback) -> Self {
        Self {
            shading: shading.into(),
            readback,
            depth: DepthConvention::Standard,
            infinite_far: false,
            alpha: AlphaMode::default(),
            preserved_pattern: 0,
            pass_timing: false,
            tile_stats: false,
        }
    }
}
