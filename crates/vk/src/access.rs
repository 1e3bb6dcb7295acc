//! Declared image accesses and the one place barriers are derived from them. A pass says how it
//! will use an image next; `transition` turns "last access -> next access" into a barrier.

use crate::context::Context;
use crate::resources::{subresource_range, Image};
use ash::vk;

/// How an image is used by the next commands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageAccess {
    /// Not used yet this frame; contents may be discarded.
    Nothing,
    /// Written (and blended) as a colour attachment.
    ColorAttachment,
    /// Depth and stencil tested and written as the depth-stencil attachment.
    DepthStencilAttachment,
    /// Read by fragment shaders.
    FragmentSampled,
    /// Source of a copy to a buffer.
    TransferSource,
}

/// The layout, stages and access mask of an [`ImageAccess`]. Pure, so it is unit-tested.
pub fn access_info(
    access: ImageAccess,
) -> (vk::ImageLayout, vk::PipelineStageFlags2, vk::AccessFlags2) {
    use vk::{AccessFlags2 as A, PipelineStageFlags2 as S};
    match access {
        ImageAccess::Nothing => (vk::ImageLayout::UNDEFINED, S::NONE, A::NONE),
        ImageAccess::ColorAttachment => (
            vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
            S::COLOR_ATTACHMENT_OUTPUT,
            A::COLOR_ATTACHMENT_READ | A::COLOR_ATTACHMENT_WRITE,
        ),
        ImageAccess::DepthStencilAttachment => (
            vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
            S::EARLY_FRAGMENT_TESTS | S::LATE_FRAGMENT_TESTS,
            A::DEPTH_STENCIL_ATTACHMENT_READ | A::DEPTH_STENCIL_ATTACHMENT_WRITE,
        ),
        ImageAccess::FragmentSampled => (
            vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
            S::FRAGMENT_SHADER,
            // SHADER_READ rather than its sync2 refinement SHADER_SAMPLED_READ: the same
            // dependency, and the one the best-practices layer expects with this layout.
            A::SHADER_READ,
        ),
        ImageAccess::TransferSource => (
            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
            S::COPY,
            A::TRANSFER_READ,
        ),
    }
}

/// Whether a transition keeps an image's contents.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Contents {
    /// The next access overwrites everything: the layout goes from UNDEFINED.
    Discard,
    Keep,
}

/// Records the barrier that takes `image` from its last access to `next`.
pub(crate) fn transition(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    image: &mut Image,
    next: ImageAccess,
    contents: Contents,
) {
    let (old_layout, src_stage, src_access) = access_info(image.last_access);
    let (new_layout, dst_stage, dst_access) = access_info(next);
    let old_layout = match contents {
        Contents::Discard => vk::ImageLayout::UNDEFINED,
        Contents::Keep => old_layout,
    };
    let barrier = vk::ImageMemoryBarrier2::default()
        .src_stage_mask(src_stage)
        .src_access_mask(src_access)
        .dst_stage_mask(dst_stage)
        .dst_access_mask(dst_access)
        .old_layout(old_layout)
        .new_layout(new_layout)
        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .image(image.handle)
        .subresource_range(subresource_range(image.aspect));
    let barriers = [barrier];
    let dependency = vk::DependencyInfo::default().image_memory_barriers(&barriers);
    unsafe { ctx.device.cmd_pipeline_barrier2(cmd, &dependency) };
    image.last_access = next;
}

/// A global memory barrier: every write recorded before is visible to every access after.
///
/// The hi-stencil emulation and split light passes hand buffers and attachments between
/// fragment shaders, attachments, copies and compute many times a frame; one broad barrier
/// between those phases is simpler to get right than a precise one per hand-over, and costs the
/// same on a driver that serialises them anyway.
///
/// The stages are the ones histencil records (named rather than `ALL_COMMANDS`, which the
/// best-practices layer flags); synchronisation validation in every test run would report a
/// hazard through a stage missing here.
pub(crate) fn memory_barrier(ctx: &Context, cmd: vk::CommandBuffer) {
    use vk::PipelineStageFlags2 as S;
    let stages = S::VERTEX_INPUT
        | S::VERTEX_SHADER
        | S::EARLY_FRAGMENT_TESTS
        | S::FRAGMENT_SHADER
        | S::LATE_FRAGMENT_TESTS
        | S::COLOR_ATTACHMENT_OUTPUT
        | S::COMPUTE_SHADER
        | S::ALL_TRANSFER;
    let barrier = [vk::MemoryBarrier2::default()
        .src_stage_mask(stages)
        .src_access_mask(vk::AccessFlags2::MEMORY_WRITE)
        .dst_stage_mask(stages)
        .dst_access_mask(vk::AccessFlags2::MEMORY_READ | vk::AccessFlags2::MEMORY_WRITE)];
    let dependency = vk::DependencyInfo::default().memory_barriers(&barrier);
    unsafe { ctx.device.cmd_pipeline_barrier2(cmd, &dependency) };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_access_but_nothing_has_a_real_layout_and_stage() {
        for a in [
            ImageAccess::ColorAttachment,
            ImageAccess::DepthStencilAttachment,
            ImageAccess::FragmentSampled,
            ImageAccess::TransferSource,
        ] {
            let (layout, stage, access) = access_info(a);
            assert_ne!(layout, vk::ImageLayout::UNDEFINED, "{a:?}");
            assert!(!stage.is_empty() && !access.is_empty(), "{a:?}");
        }
        assert_eq!(
            access_info(ImageAccess::Nothing).0,
            vk::ImageLayout::UNDEFINED
        );
    }

    #[test]
    fn reads_are_read_only_accesses() {
        let (_, _, a) = access_info(ImageAccess::FragmentSampled);
        assert!(!a
            .intersects(vk::AccessFlags2::SHADER_WRITE | vk::AccessFlags2::COLOR_ATTACHMENT_WRITE));
        let (_, _, a) = access_info(ImageAccess::TransferSource);
        assert_eq!(a, vk::AccessFlags2::TRANSFER_READ);
    }
}
