//! One file per pass, one convention for all of them: a pass is an object made once that owns
//! its pipelines and the layouts and sets only it uses (`MeshPasses`, `Tonemap`, and outside
//! this folder `DeferredLighting`, `AlphaLightmaps` and the renderer's alpha pass), freed with
//! `destroy` (a creation that fails half way frees what it made); each frame it records from
//! one inputs struct (`MeshInputs`, `TonemapInputs`, `LightingFrame`, `LightmapFrame`,
//! `AlphaInputs`) through the caller's `Recording` (the encoder: it begins and ends the
//! pass's rendering and opens its label, `Recording::step`), never a bare command buffer; the
//! public entry points an engine calls with its own command buffer wrap it in one at once.
//! The lighting's
//! per-frame recording (`lighting.rs`) and the light pipelines it creates per plan
//! (`light_pipelines.rs`) live here and belong to `DeferredLighting`.

pub(crate) mod depth_id;
pub mod geometry;
pub mod light_modules;
pub mod light_pipelines;
pub mod lighting;
pub(crate) mod tiled;
pub mod tonemap;

use crate::gpu::access::{Contents, ImageAccess, ImageRef};
use crate::gpu::recording::Recording;
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
    for image in images.iter_mut() {
        rec.transition(image, ImageAccess::ColorAttachment, Contents::Discard);
    }
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
    rec.transition(hdr_image, ImageAccess::ColorAttachment, contents(hdr));
    rec.transition(depth_stencil, depth_access, contents(depth));
    let colors = [color_attachment(hdr_image, hdr)];
    let ds = attachment(depth_stencil, depth_stencil.state.layout, depth);
    rec.begin_rendering_over(extent, &colors, Some(&ds));
}
