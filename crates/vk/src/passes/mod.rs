//! One file per pass, one convention for all of them: a pass is an object made once that owns
//! its pipelines and the layouts and sets only it uses (`MeshPasses`, `Tonemap`, and outside
//! this folder `DeferredLighting`, `AlphaLightmaps` and the renderer's alpha pass), freed with
//! `destroy` (a creation that fails half way frees what it made); each frame it records from
//! one inputs struct (`MeshInputs`, `TonemapInputs`, `LightingFrame`, `LightmapFrame`,
//! `AlphaInputs`) into the caller's command buffer, inside its own debug label. The lighting's
//! per-frame recording (`lighting.rs`) and the light pipelines it creates per plan
//! (`light_pipelines.rs`) live here and belong to `DeferredLighting`.

pub(crate) mod depth_id;
pub mod geometry;
pub mod light_modules;
pub mod light_pipelines;
pub mod lighting;
pub(crate) mod tiled;
pub mod tonemap;

use crate::gpu::access::{transition, Contents, ImageAccess, ImageRef};
use crate::gpu::context::Context;
use ash::vk;
use histencil_model::DepthConvention;

pub(crate) use crate::gpu::attachments::{
    attachment, color_attachment, depth_stencil_attachment, Load,
};

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

/// Begins dynamic rendering over the whole `extent` and sets viewport and scissor.
pub(crate) fn begin_rendering(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    extent: vk::Extent2D,
    colors: &[vk::RenderingAttachmentInfo],
    depth_stencil: Option<&vk::RenderingAttachmentInfo>,
) {
    let area = vk::Rect2D::default().extent(extent);
    let mut info = vk::RenderingInfo::default()
        .render_area(area)
        .layer_count(1)
        .color_attachments(colors);
    if let Some(ds) = depth_stencil {
        info = info.depth_attachment(ds).stencil_attachment(ds);
    }
    let viewport = vk::Viewport {
        x: 0.0,
        y: 0.0,
        width: extent.width as f32,
        height: extent.height as f32,
        min_depth: 0.0,
        max_depth: 1.0,
    };
    // SAFETY: `cmd` is recording outside rendering: each pass begins here after the one before
    // ended its own, and the callers' contracts say `cmd` records. They transitioned every
    // attachment to the layout it is named with, and `extent` (non-zero) is theirs: the render
    // area, viewport and scissor lie inside them.
    unsafe {
        ctx.device.cmd_begin_rendering(cmd, &info);
        ctx.device.cmd_set_viewport(cmd, 0, &[viewport]);
        ctx.device.cmd_set_scissor(cmd, 0, &[area]);
    }
}

/// Discards `image`'s contents and begins rendering into it alone, cleared to `clear`, over its
/// whole extent.
pub(crate) fn begin_cleared(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    image: &mut ImageRef,
    clear: vk::ClearValue,
) {
    begin_all_cleared(ctx, cmd, &mut [image], clear);
}

/// Discards the contents of `images` (colour images of one extent, attachments 0, 1, ... in
/// order) and begins rendering into them, each cleared to `clear`.
pub(crate) fn begin_all_cleared(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    images: &mut [&mut ImageRef],
    clear: vk::ClearValue,
) {
    for image in images.iter_mut() {
        transition(
            ctx,
            cmd,
            image,
            ImageAccess::ColorAttachment,
            Contents::Discard,
        );
    }
    let colors: Vec<_> = images
        .iter()
        .map(|image| color_attachment(image, Load::Clear(clear)))
        .collect();
    begin_rendering(ctx, cmd, images[0].extent, &colors, None);
}

/// Begins rendering into the HDR target and the depth-stencil target, each cleared or kept as
/// `hdr` and `depth` say (the forward pass clears both; lighting keeps the G-buffer's depth and
/// clears HDR once, keeping both when a split pass resumes).
pub(crate) fn begin_hdr_rendering(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    attachments: (&mut ImageRef, &mut ImageRef),
    extent: vk::Extent2D,
    hdr: Load,
    depth: Load,
) {
    let access = ImageAccess::DepthStencilAttachment;
    begin_hdr_rendering_as(ctx, cmd, attachments, extent, (hdr, depth), access);
}

/// [`begin_hdr_rendering`] with the depth-stencil attached for `depth_access`: the
/// read-write attachment, or read-only depth beside a written stencil (the lighting pass when
/// an engine's decode hook samples depth).
pub(crate) fn begin_hdr_rendering_as(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    (hdr_image, depth_stencil): (&mut ImageRef, &mut ImageRef),
    extent: vk::Extent2D,
    (hdr, depth): (Load, Load),
    depth_access: ImageAccess,
) {
    let contents = |load| match load {
        Load::Clear(_) => Contents::Discard,
        Load::Keep => Contents::Keep,
    };
    transition(
        ctx,
        cmd,
        hdr_image,
        ImageAccess::ColorAttachment,
        contents(hdr),
    );
    transition(ctx, cmd, depth_stencil, depth_access, contents(depth));
    let colors = [color_attachment(hdr_image, hdr)];
    let ds = attachment(depth_stencil, depth_stencil.state.layout, depth);
    begin_rendering(ctx, cmd, extent, &colors, Some(&ds));
}
