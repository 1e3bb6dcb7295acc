//! HDR -> 8-bit display colour.

use super::{begin_rendering, color_attachment, Load, CLEAR_BLACK};
use crate::access::{transition, Contents, ImageAccess};
use crate::context::Context;
use crate::state::{apply, FULLSCREEN};
use crate::targets::Targets;
use ash::vk;

pub struct TonemapPass<'a> {
    pub ctx: &'a Context,
    pub cmd: vk::CommandBuffer,
    pub pipeline: vk::Pipeline,
    pub pipeline_layout: vk::PipelineLayout,
    pub sets: [vk::DescriptorSet; 2],
    pub extent: vk::Extent2D,
}

impl TonemapPass<'_> {
    pub fn record(&self, targets: &mut Targets) {
        let (ctx, cmd) = (self.ctx, self.cmd);
        ctx.begin_label(cmd, "tonemap");
        transition(
            ctx,
            cmd,
            &mut targets.hdr,
            ImageAccess::FragmentSampled,
            Contents::Keep,
        );
        transition(
            ctx,
            cmd,
            &mut targets.ldr,
            ImageAccess::ColorAttachment,
            Contents::Discard,
        );
        begin_rendering(
            ctx,
            cmd,
            self.extent,
            &[color_attachment(&targets.ldr, Load::Clear(CLEAR_BLACK))],
            None,
        );
        unsafe {
            ctx.device
                .cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.pipeline);
            ctx.device.cmd_bind_descriptor_sets(
                cmd,
                vk::PipelineBindPoint::GRAPHICS,
                self.pipeline_layout,
                0,
                &self.sets,
                &[],
            );
            apply(ctx, cmd, &FULLSCREEN);
            ctx.device.cmd_draw(cmd, 3, 1, 0, 0);
            ctx.device.cmd_end_rendering(cmd);
        }
        ctx.end_label(cmd);
    }
}
