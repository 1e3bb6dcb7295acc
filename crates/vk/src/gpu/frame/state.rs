//! The one translation from histencil-model's pass state (plain data, also executed by the CPU
//! simulator) to Vulkan dynamic state. Every draw of every pass goes through `apply`, so what
//! the GPU does and what the model simulates cannot drift apart.
//!
//! Hi-stencil state is not Vulkan state: the GPU tile surface that emulates it is recorded by
//! the lighting pass, not here.

use crate::gpu::encoder::recording::Recording;
use ash::vk;
use histencil_model::{
    CompareOp, CullMode, DepthConvention, DepthRange, DepthState, FaceStencil, PassState, StencilOp,
};

/// The Vulkan compare op (also the value the hi-stencil emulation's shaders compare by).
pub fn compare_op(op: CompareOp) -> vk::CompareOp {
    match op {
        CompareOp::Never => vk::CompareOp::NEVER,
        CompareOp::Less => vk::CompareOp::LESS,
        CompareOp::Equal => vk::CompareOp::EQUAL,
        CompareOp::LessOrEqual => vk::CompareOp::LESS_OR_EQUAL,
        CompareOp::Greater => vk::CompareOp::GREATER,
        CompareOp::NotEqual => vk::CompareOp::NOT_EQUAL,
        CompareOp::GreaterOrEqual => vk::CompareOp::GREATER_OR_EQUAL,
        CompareOp::Always => vk::CompareOp::ALWAYS,
    }
}

/// The Vulkan stencil op.
pub fn stencil_op(op: StencilOp) -> vk::StencilOp {
    match op {
        StencilOp::Keep => vk::StencilOp::KEEP,
        StencilOp::Zero => vk::StencilOp::ZERO,
        StencilOp::Replace => vk::StencilOp::REPLACE,
        StencilOp::IncrementAndClamp => vk::StencilOp::INCREMENT_AND_CLAMP,
    }
}

/// The Vulkan cull mode.
pub fn cull_mode(cull: CullMode) -> vk::CullModeFlags {
    match cull {
        CullMode::None => vk::CullModeFlags::NONE,
        CullMode::Front => vk::CullModeFlags::FRONT,
        CullMode::Back => vk::CullModeFlags::BACK,
    }
}

/// Opaque geometry: back faces culled, depth LESS with writes, no stencil.
pub const OPAQUE: PassState = PassState {
    cull: CullMode::Back,
    depth: DepthState {
        compare: Some(CompareOp::Less),
        write: true,
    },
    front: None,
    back: None,
    color_write: true,
    hi_stencil: None,
    depth_bounds: false,
};

/// A full-screen pass with no depth or stencil (tonemap).
pub const FULLSCREEN: PassState = PassState {
    cull: CullMode::None,
    depth: DepthState::OFF,
    front: None,
    back: None,
    color_write: true,
    hi_stencil: None,
    depth_bounds: false,
};

/// `state`, written for standard depth, with its depth compare as `depth` spells it.
pub fn oriented(state: PassState, depth: DepthConvention) -> PassState {
    PassState {
        depth: DepthState {
            compare: state.depth.compare.map(|op| depth.orient(op)),
            ..state.depth
        },
        ..state
    }
}

/// `state` with `face` on both faces.
pub fn with_stencil(state: PassState, face: FaceStencil) -> PassState {
    PassState {
        front: Some(face),
        back: Some(face),
        ..state
    }
}

impl Recording<'_> {
    /// Records `state` as dynamic state. A face without stencil state passes and keeps (the
    /// stencil test is one switch for both faces in Vulkan). Colour writes are pipeline state:
    /// the caller binds a pipeline that matches `state.color_write`. Without the depth bounds
    /// test ([`Self::apply_bounded`] for a light's passes).
    pub(crate) fn apply(&self, state: &PassState) {
        self.apply_bounded(state, None);
    }

    /// [`Self::apply`], where `bounds` is the depth range a pass with `state.depth_bounds` is confined to
    /// (its light's, from the plan) when the device has the depth bounds test enabled; every other
    /// draw runs without the test.
    pub(crate) fn apply_bounded(&self, state: &PassState, bounds: Option<DepthRange>) {
        let (ctx, d, cmd) = (self.ctx(), self.device(), self.any());
        let enabled = state.front.is_some() || state.back.is_some();
        if ctx.depth_bounds {
            let bounds = bounds.filter(|_| state.depth_bounds);
            // SAFETY: the recording's command buffer is recording on this device. `depthBounds` is enabled
            // (`ctx.depth_bounds` is set only where `Context::new` enabled it). The bounds must lie
            // in [0, 1] (no VK_EXT_depth_range_unrestricted): `FramePlan::with_depth_bounds`
            // clamps its ranges so; a hand-made plan's public `depth_range` is not checked here.
            unsafe {
                d.cmd_set_depth_bounds_test_enable(cmd, bounds.is_some());
                if let Some(b) = bounds {
                    d.cmd_set_depth_bounds(cmd, b.min, b.max);
                }
            }
        }
        // SAFETY: the recording's command buffer is recording on this device (the renderer's, or an engine's
        // under `record`'s # Safety). These commands set core Vulkan 1.3 dynamic state and take
        // only plain values; the masks and reference widen from the model's 8-bit ones.
        unsafe {
            d.cmd_set_cull_mode(cmd, cull_mode(state.cull));
            d.cmd_set_depth_test_enable(cmd, state.depth.compare.is_some());
            d.cmd_set_depth_compare_op(
                cmd,
                compare_op(state.depth.compare.unwrap_or(CompareOp::Always)),
            );
            d.cmd_set_depth_write_enable(cmd, state.depth.write);
            d.cmd_set_stencil_test_enable(cmd, enabled);
            for (flags, face) in [
                (vk::StencilFaceFlags::FRONT, state.front),
                (vk::StencilFaceFlags::BACK, state.back),
            ] {
                let s = face.unwrap_or(FaceStencil::DISABLED);
                d.cmd_set_stencil_op(
                    cmd,
                    flags,
                    stencil_op(s.fail),
                    stencil_op(s.pass),
                    stencil_op(s.depth_fail),
                    compare_op(s.compare),
                );
                d.cmd_set_stencil_compare_mask(cmd, flags, u32::from(s.compare_mask));
                d.cmd_set_stencil_write_mask(cmd, flags, u32::from(s.write_mask));
                d.cmd_set_stencil_reference(cmd, flags, u32::from(s.reference));
            }
        }
    }
}
