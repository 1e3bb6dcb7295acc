//! A rendering attachment from an image histencil renders into: its view, the layout the
//! attachment is in, and how rendering starts with it (cleared or kept). Below the passes, so
//! the hi-stencil emulation's touch draw uses it as the passes do.

use crate::gpu::access::ImageRef;
use ash::vk;

/// How a pass treats an attachment at the start of rendering.
#[derive(Clone, Copy)]
pub(crate) enum Load {
    Clear(vk::ClearValue),
    Keep,
}

/// `image` as a colour attachment.
pub(crate) fn color_attachment(
    image: &ImageRef,
    load: Load,
) -> vk::RenderingAttachmentInfo<'static> {
    attachment(image, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, load)
}

/// `image` as the depth-stencil attachment, depth and stencil both written.
pub(crate) fn depth_stencil_attachment(
    image: &ImageRef,
    load: Load,
) -> vk::RenderingAttachmentInfo<'static> {
    attachment(
        image,
        vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
        load,
    )
}

/// `image` attached in `layout`, loaded as `load` says and stored.
pub(crate) fn attachment(
    image: &ImageRef,
    layout: vk::ImageLayout,
    load: Load,
) -> vk::RenderingAttachmentInfo<'static> {
    let (op, clear) = match load {
        Load::Clear(v) => (vk::AttachmentLoadOp::CLEAR, v),
        Load::Keep => (vk::AttachmentLoadOp::LOAD, vk::ClearValue::default()),
    };
    vk::RenderingAttachmentInfo::default()
        .image_view(image.view)
        .image_layout(layout)
        .load_op(op)
        .store_op(vk::AttachmentStoreOp::STORE)
        .clear_value(clear)
}
