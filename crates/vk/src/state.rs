//! Per-draw depth / stencil / cull state as plain data, and its one translation to Vulkan dynamic
//! state. The light passes of the talk are written as constants of this type in
//! `passes/lighting.rs`, so the state of every pass can be read (and tested) without a GPU.

use crate::context::Context;
use ash::vk;

/// Stencil test and update for both faces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StencilState {
    pub compare: vk::CompareOp,
    pub compare_mask: u8,
    pub write_mask: u8,
    pub reference: u8,
    pub pass: vk::StencilOp,
    pub fail: vk::StencilOp,
    pub depth_fail: vk::StencilOp,
}

impl StencilState {
    /// Writes `reference` into the bits of `write_mask` wherever the depth test passes.
    pub const fn replace(reference: u8, write_mask: u8) -> Self {
        Self {
            compare: vk::CompareOp::ALWAYS,
            compare_mask: 0xFF,
            write_mask,
            reference,
            pass: vk::StencilOp::REPLACE,
            fail: vk::StencilOp::KEEP,
            depth_fail: vk::StencilOp::KEEP,
        }
    }

    /// Passes where `stencil & compare_mask == reference`; writes nothing.
    pub const fn test_equal(reference: u8, compare_mask: u8) -> Self {
        Self {
            compare: vk::CompareOp::EQUAL,
            compare_mask,
            write_mask: 0,
            reference,
            pass: vk::StencilOp::KEEP,
            fail: vk::StencilOp::KEEP,
            depth_fail: vk::StencilOp::KEEP,
        }
    }
}

/// Everything a draw sets as dynamic state, besides viewport and scissor.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DrawState {
    pub cull: vk::CullModeFlags,
    /// `None` disables the depth test.
    pub depth_compare: Option<vk::CompareOp>,
    pub depth_write: bool,
    /// `None` disables the stencil test.
    pub stencil: Option<StencilState>,
}

impl DrawState {
    /// Opaque geometry: back-face culling, depth LESS with writes.
    pub const OPAQUE: Self = Self {
        cull: vk::CullModeFlags::BACK,
        depth_compare: Some(vk::CompareOp::LESS),
        depth_write: true,
        stencil: None,
    };

    /// No depth or stencil at all (tonemap).
    pub const FULLSCREEN: Self = Self {
        cull: vk::CullModeFlags::NONE,
        depth_compare: None,
        depth_write: false,
        stencil: None,
    };

    pub fn with_stencil(self, stencil: StencilState) -> Self {
        Self {
            stencil: Some(stencil),
            ..self
        }
    }

    /// Records this state into `cmd`.
    pub(crate) fn apply(&self, ctx: &Context, cmd: vk::CommandBuffer) {
        let d = &ctx.device;
        let face = vk::StencilFaceFlags::FRONT_AND_BACK;
        let s = self.stencil.unwrap_or(StencilState::test_equal(0, 0));
        unsafe {
            d.cmd_set_cull_mode(cmd, self.cull);
            d.cmd_set_depth_test_enable(cmd, self.depth_compare.is_some());
            d.cmd_set_depth_compare_op(cmd, self.depth_compare.unwrap_or(vk::CompareOp::ALWAYS));
            d.cmd_set_depth_write_enable(cmd, self.depth_write);
            d.cmd_set_stencil_test_enable(cmd, self.stencil.is_some());
            d.cmd_set_stencil_op(cmd, face, s.fail, s.pass, s.depth_fail, s.compare);
            d.cmd_set_stencil_compare_mask(cmd, face, u32::from(s.compare_mask));
            d.cmd_set_stencil_write_mask(cmd, face, u32::from(s.write_mask));
            d.cmd_set_stencil_reference(cmd, face, u32::from(s.reference));
        }
    }
}
