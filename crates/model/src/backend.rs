//! Platform behaviour as documented data.
//!
//! The plan builder (`plan.rs`) reads only [`PlatformCaps`]; nothing else in the crate asks which
//! platform it is on. A new platform is a new value of that struct.

use crate::state::CompareOp;

/// What the stencil hardware of a platform can do, and how the plan treats the engine's
/// preserved stencil bits there.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PlatformCaps {
    /// A coarse per-tile stencil surface exists. Without it, masking is per pixel only and
    /// the plan has no mask passes (the per-pixel stencil test selects the BRDF directly).
    pub hi_stencil: bool,
    /// The hi-stencil compare honours a read mask. Without one (360-like) it compares all 8
    /// bits, so culling and preserved bits must be zero wherever a tile has to pass.
    pub hi_stencil_read_mask: bool,
    /// Compare functions the hi-stencil supports. 360-like: only `Equal` and `NotEqual`.
    pub hi_stencil_compares: &'static [CompareOp],
    /// Setup and cleanup also zero the preserved bits (the talk's fix: pass op ZERO, write mask
    /// `!brdf_mask`), destroying them wherever a light volume is drawn.
    pub zero_preserved_as_we_go: bool,
    /// The frame saves the preserved bits before lighting and restores them afterwards: two
    /// extra steps, the restore costing one full-screen pass per preserved bit.
    pub save_restore_preserved: bool,
}

/// A platform's stencil behaviour.
pub trait PlatformBackend {
    /// A short kebab-case name for reports ("360-like").
    fn name(&self) -> &'static str;
    /// The platform's stencil behaviour as data: what the planner reads instead of branching on
    /// the platform.
    fn caps(&self) -> PlatformCaps;
}

/// Xbox 360-like: hi-stencil without a read mask, only EQUAL / NOTEQUAL.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct X360Like {
    /// The talk's fix. Switching it off with non-zero preserved bits reproduces the talk's
    /// failure: tiles whose pixels carry engine data are culled and never lit.
    pub zero_preserved: bool,
    /// Save the preserved bits before lighting and restore them after.
    pub save_restore: bool,
}

impl Default for X360Like {
    fn default() -> Self {
        Self {
            zero_preserved: true,
            save_restore: false,
        }
    }
}

impl PlatformBackend for X360Like {
    fn name(&self) -> &'static str {
        "360-like"
    }

    fn caps(&self) -> PlatformCaps {
        PlatformCaps {
            hi_stencil: true,
            hi_stencil_read_mask: false,
            hi_stencil_compares: &[CompareOp::Equal, CompareOp::NotEqual],
            zero_preserved_as_we_go: self.zero_preserved,
            save_restore_preserved: self.save_restore,
        }
    }
}

/// PS3-like: hi-stencil (zcull) with a read mask, so the preserved bits never need touching.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Ps3Like;

impl PlatformBackend for Ps3Like {
    fn name(&self) -> &'static str {
        "ps3-like"
    }

    fn caps(&self) -> PlatformCaps {
        PlatformCaps {
            hi_stencil: true,
            hi_stencil_read_mask: true,
            hi_stencil_compares: &[
                CompareOp::Equal,
                CompareOp::NotEqual,
                CompareOp::Less,
                CompareOp::LessOrEqual,
                CompareOp::Greater,
                CompareOp::GreaterOrEqual,
            ],
            zero_preserved_as_we_go: false,
            save_restore_preserved: false,
        }
    }
}

/// Plain Vulkan: per-pixel stencil with compare masks, no hi-stencil emulation. Whatever
/// coarse culling the GPU does is invisible to the API and needs no flushes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Native;

impl PlatformBackend for Native {
    fn name(&self) -> &'static str {
        "native"
    }

    fn caps(&self) -> PlatformCaps {
        PlatformCaps {
            hi_stencil: false,
            hi_stencil_read_mask: false,
            hi_stencil_compares: &[],
            zero_preserved_as_we_go: false,
            save_restore_preserved: false,
        }
    }
}
