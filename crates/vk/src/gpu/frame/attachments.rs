//! A rendering attachment from an image histencil renders into: its view, the layout the
//! attachment is in, and how rendering starts with it (cleared or kept); and the ways the passes
//! begin rendering into their targets through the encoder. Below the passes, so the hi-stencil
//! emulation's touch draw and the alpha passes use them as the passes do.

use crate::gpu::access::{Contents, ImageAccess, ImageRef, Use};
use crate::gpu::encoder::recording::Recording;
use ash::vk;
use histencil_model::DepthConvention;

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

pub(crate) const CLEAR_BLACK: vk::ClearValue = vk::ClearValue {
    color: vk::ClearColorValue { float32: [0.0; 4] },
};

/// The depth-stencil clear: the far plane's depth, stencil 0.
pub(crate) fn clear_depth_stencil(depth: DepthConvention) -> vk::ClearValue {
    vk::ClearValue {
        depth_stencil: vk::ClearDepthStencilValue {
            depth: depth.far(),
            stencil: 0,
        },
    }
}

/// Discards `image`'s contents and begins rendering into it alone, cleared to `clear`, over its
/// whole extent.
pub(crate) fn begin_cleared(rec: &Recording, image: &mut ImageRef, clear: vk::ClearValue) {
    begin_all_cleared(rec, &mut [image], clear);
}

/// Discards the contents of `images` (colour images of one extent, attachments 0, 1, ... in
/// order) and begins rendering into them, each cleared to `clear`.
pub(crate) fn begin_all_cleared(
    rec: &Recording,
    images: &mut [&mut ImageRef],
    clear: vk::ClearValue,
) {
    let mut uses: Vec<Use> = images
        .iter_mut()
        .map(|image| {
            (
                &mut **image,
                ImageAccess::ColorAttachment,
                Contents::Discard,
            )
        })
        .collect();
    rec.declare(&mut uses);
    let colors: Vec<_> = images
        .iter()
        .map(|image| color_attachment(image, Load::Clear(clear)))
        .collect();
    rec.begin_rendering_over(images[0].extent, &colors, None);
}

/// Begins rendering into the HDR target and the depth-stencil target, each cleared or kept as
/// `hdr` and `depth` say (the forward pass clears both; lighting keeps the G-buffer's depth and
/// clears HDR once, keeping both when a split pass resumes).
pub(crate) fn begin_hdr_rendering(
    rec: &Recording,
    attachments: (&mut ImageRef, &mut ImageRef),
    extent: vk::Extent2D,
    hdr: Load,
    depth: Load,
) {
    let access = ImageAccess::DepthStencilAttachment;
    begin_hdr_rendering_as(rec, attachments, extent, (hdr, depth), access);
}

/// [`begin_hdr_rendering`] with the depth-stencil attached for `depth_access`: the
/// read-write attachment, or read-only depth beside a written stencil (the lighting pass when
/// an engine's decode hook samples depth).
pub(crate) fn begin_hdr_rendering_as(
    rec: &Recording,
    (hdr_image, depth_stencil): (&mut ImageRef, &mut ImageRef),
    extent: vk::Extent2D,
    (hdr, depth): (Load, Load),
    depth_access: ImageAccess,
) {
    let contents = |load| match load {
        Load::Clear(_) => Contents::Discard,
        Load::Keep => Contents::Keep,
    };
    rec.declare(&mut [
        (&mut *hdr_image, ImageAccess::ColorAttachment, contents(hdr)),
        (&mut *depth_stencil, depth_access, contents(depth)),
    ]);
    let colors = [color_attachment(hdr_image, hdr)];
    let ds = attachment(depth_stencil, depth_stencil.state.layout, depth);
    rec.begin_rendering_over(extent, &colors, Some(&ds));
}
