//! The vocabulary of declared accesses and the barriers derived from them, pure: how a pass
//! uses an image next ([`ImageAccess`]) and where it stands ([`ImageState`]), turned into the
//! barrier that takes it there (`image_barrier`), whoever owns the image: histencil's own
//! targets and an engine's images handed in as [`ImageRef`]s go through the same code. Buffers
//! are declared likewise (`buffers.rs`). The encoder records what these derive
//! (`crate::gpu::encoder::declare`); no barrier is written anywhere else.

use ash::vk;

mod buffers;
pub use buffers::{buffer_access_info, BufferAccess};
pub(crate) use buffers::{hand_over, BufferUse, LeaveOut, BUFFER_WRITES};

/// Where an image stands: its layout and the last stages and accesses that touched it (the
/// source half of the next barrier).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImageState {
    /// The layout the image is in now.
    pub layout: vk::ImageLayout,
    /// The stages of its last use, which the next barrier waits for.
    pub stage: vk::PipelineStageFlags2,
    /// The accesses of its last use, which the next barrier makes available.
    pub access: vk::AccessFlags2,
}

impl ImageState {
    /// Not used yet: contents undefined, nothing to wait for.
    pub const UNDEFINED: ImageState = ImageState {
        layout: vk::ImageLayout::UNDEFINED,
        stage: vk::PipelineStageFlags2::NONE,
        access: vk::AccessFlags2::NONE,
    };

    /// The state an [`ImageAccess`] leaves an image in.
    pub fn after(access: ImageAccess) -> ImageState {
        let (layout, stage, access) = access_info(access);
        ImageState {
            layout,
            stage,
            access,
        }
    }
}

/// An image histencil records against without owning it: its handles, what it is, and its
/// current state. Recording functions take it `&mut` and leave the state the image is in after
/// the commands they recorded, which is what the caller's next barrier starts from.
///
/// One mip level, one array layer, every aspect of the format (depth and stencil both for a
/// depth-stencil format); `view` is a 2D view over the aspects histencil samples or attaches.
#[derive(Clone, Copy, Debug)]
pub struct ImageRef {
    /// The image barriers and copies name.
    pub image: vk::Image,
    /// The 2D view passes attach or sample.
    pub view: vk::ImageView,
    /// Its format, which decides the aspects ([`aspect_of`]).
    pub format: vk::Format,
    /// Its size in pixels.
    pub extent: vk::Extent2D,
    /// The usage it was created with (`VkImageCreateInfo::usage`): a recording that would use
    /// it otherwise is refused before anything is recorded, as Vulkan would not say until its
    /// barriers and views were already wrong.
    pub usage: vk::ImageUsageFlags,
    /// Where it stands now; updated by every recording that uses it.
    pub state: ImageState,
}

impl ImageRef {
    /// The aspects barriers and copies address: depth and stencil for a depth-stencil format,
    /// colour otherwise.
    pub fn aspect(&self) -> vk::ImageAspectFlags {
        aspect_of(self.format)
    }
}

/// The caller's images a frame is lit in, each with its current state. Recording leaves every
/// [`ImageRef::state`] as the recorded commands leave the image, for the caller's next barrier:
/// after the talk's light passes the G-buffer images sampled by fragment shaders and the
/// depth-stencil and HDR images attached; after the tiled technique
/// ([`crate::DeferredLighting::record_tiled`]) the G-buffer images sampled by compute shaders
/// and the HDR image written by them in `GENERAL`.
#[derive(Clone, Debug)]
pub struct LightingTargets {
    /// The images the decode hook reads, each barriered for shader reads
    /// (`SHADER_READ_ONLY_OPTIMAL`), usage `SAMPLED`. With histencil's built-in decode: albedo,
    /// normal-depth, material, in [`crate::GBUFFER_FORMATS`]. With an engine's decode hook
    /// ([`crate::LightHooks::Engine`]): the engine's own images, any number and formats, read
    /// through the engine's decode set.
    pub gbuffer: Vec<ImageRef>,
    /// The G-buffer pass's depth and stencil; usage `DEPTH_STENCIL_ATTACHMENT`, with
    /// `SAMPLED` for the hi-stencil emulation (its tile update reads the stencil through a
    /// stencil-aspect view) and where an engine's decode hook reads depth, and `TRANSFER_SRC`
    /// for 360-like save/restore (which copies the stencil out). With an engine's decode hook
    /// the light passes attach it in `DEPTH_READ_ONLY_STENCIL_ATTACHMENT_OPTIMAL`, so the decode
    /// may sample its depth aspect (through a depth-only view of the engine's); the tiled
    /// technique's kernels read it in the same layout.
    pub depth_stencil: ImageRef,
    /// Where light accumulates; usage `COLOR_ATTACHMENT`, and `STORAGE` in
    /// `R16G16B16A16_SFLOAT` for the tiled technique.
    pub hdr: ImageRef,
}

/// The one mip level and array layer histencil's images have, over `aspect`.
pub(crate) fn subresource_range(aspect: vk::ImageAspectFlags) -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange::default()
        .aspect_mask(aspect)
        .level_count(1)
        .layer_count(1)
}

/// Every aspect of `format`.
pub fn aspect_of(format: vk::Format) -> vk::ImageAspectFlags {
    use vk::Format as F;
    use vk::ImageAspectFlags as A;
    match format {
        F::D16_UNORM | F::X8_D24_UNORM_PACK32 | F::D32_SFLOAT => A::DEPTH,
        F::S8_UINT => A::STENCIL,
        F::D16_UNORM_S8_UINT | F::D24_UNORM_S8_UINT | F::D32_SFLOAT_S8_UINT => {
            A::DEPTH | A::STENCIL
        }
        _ => A::COLOR,
    }
}

/// How an image is used by the next commands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageAccess {
    /// Not used yet this frame; contents may be discarded.
    Nothing,
    /// Written (and blended) as a colour attachment.
    ColorAttachment,
    /// Depth and stencil tested and written as the depth-stencil attachment.
    DepthStencilAttachment,
    /// Stencil tested and written as the attachment while its depth aspect is read-only:
    /// depth tested, and sampled by fragment shaders through a depth-aspect view.
    StencilAttachmentDepthSampled,
    /// Read by fragment shaders.
    FragmentSampled,
    /// Read by compute shaders.
    ComputeSampled,
    /// Read and written by compute shaders as a storage image.
    ComputeStorage,
    /// Read and written by fragment shaders as a storage image (the depth-id technique's shade
    /// passes).
    FragmentStorage,
    /// Depth and stencil read-only, the stencil read by compute shaders through a
    /// stencil-aspect view (the hi-stencil tile update).
    ComputeDepthStencilSampled,
    /// The depth aspect read by compute shaders (an engine's decode hook in the tiled
    /// technique), in the layout the light passes use for it.
    ComputeDepthSampled,
    /// Source of a copy to a buffer.
    TransferSource,
}

impl ImageAccess {
    /// The image usage this access needs (`VkImageCreateInfo::usage`).
    pub fn usage(self) -> vk::ImageUsageFlags {
        use vk::ImageUsageFlags as U;
        match self {
            ImageAccess::Nothing => U::empty(),
            ImageAccess::ColorAttachment => U::COLOR_ATTACHMENT,
            ImageAccess::DepthStencilAttachment => U::DEPTH_STENCIL_ATTACHMENT,
            ImageAccess::StencilAttachmentDepthSampled => U::DEPTH_STENCIL_ATTACHMENT | U::SAMPLED,
            ImageAccess::FragmentSampled | ImageAccess::ComputeSampled => U::SAMPLED,
            // The read-only depth-stencil layouts are an attachment's: Vulkan allows barriers
            // into them only for images with DEPTH_STENCIL_ATTACHMENT usage.
            ImageAccess::ComputeDepthStencilSampled | ImageAccess::ComputeDepthSampled => {
                U::DEPTH_STENCIL_ATTACHMENT | U::SAMPLED
            }
            ImageAccess::ComputeStorage | ImageAccess::FragmentStorage => U::STORAGE,
            ImageAccess::TransferSource => U::TRANSFER_SRC,
        }
    }
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
        ImageAccess::StencilAttachmentDepthSampled => (
            vk::ImageLayout::DEPTH_READ_ONLY_STENCIL_ATTACHMENT_OPTIMAL,
            S::EARLY_FRAGMENT_TESTS | S::LATE_FRAGMENT_TESTS | S::FRAGMENT_SHADER,
            A::DEPTH_STENCIL_ATTACHMENT_READ | A::DEPTH_STENCIL_ATTACHMENT_WRITE | A::SHADER_READ,
        ),
        ImageAccess::FragmentSampled => (
            vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
            S::FRAGMENT_SHADER,
            // SHADER_READ rather than its sync2 refinement SHADER_SAMPLED_READ: the same
            // dependency, and the one the best-practices layer expects with this layout.
            A::SHADER_READ,
        ),
        ImageAccess::ComputeSampled => (
            vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
            S::COMPUTE_SHADER,
            A::SHADER_READ,
        ),
        ImageAccess::ComputeStorage => (
            vk::ImageLayout::GENERAL,
            S::COMPUTE_SHADER,
            A::SHADER_STORAGE_READ | A::SHADER_STORAGE_WRITE,
        ),
        ImageAccess::FragmentStorage => (
            vk::ImageLayout::GENERAL,
            S::FRAGMENT_SHADER,
            A::SHADER_STORAGE_READ | A::SHADER_STORAGE_WRITE,
        ),
        ImageAccess::ComputeDepthStencilSampled => (
            vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL,
            S::COMPUTE_SHADER,
            A::SHADER_SAMPLED_READ,
        ),
        ImageAccess::ComputeDepthSampled => (
            vk::ImageLayout::DEPTH_READ_ONLY_STENCIL_ATTACHMENT_OPTIMAL,
            S::COMPUTE_SHADER,
            A::SHADER_SAMPLED_READ,
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

/// An image a step uses and how: the step's barriers are derived from these
/// (`Recording::declare`), and the image's state follows.
pub(crate) type Use<'i> = (&'i mut ImageRef, ImageAccess, Contents);

/// Every image of `images` used as `access` with `contents`: a step's uses of a group of images
/// (the G-buffer's targets), to which it may add others before declaring them.
pub(crate) fn uses_of(
    images: &mut [ImageRef],
    access: ImageAccess,
    contents: Contents,
) -> Vec<Use<'_>> {
    images.iter_mut().map(|i| (i, access, contents)).collect()
}

/// The barrier that takes `image` from its current state to `next`, and the state it leaves.
pub(crate) fn image_barrier(
    image: &ImageRef,
    next: ImageAccess,
    contents: Contents,
) -> vk::ImageMemoryBarrier2<'static> {
    // The frame checks refuse targets without the usage their recording needs; an access here
    // that they did not foresee is histencil's bug.
    debug_assert!(
        image.usage.contains(next.usage()),
        "{next:?} on an image with usage {:?}: the frame checks missed it",
        image.usage
    );
    let ImageState {
        layout: old_layout,
        stage: src_stage,
        access: src_access,
    } = image.state;
    let (new_layout, dst_stage, dst_access) = access_info(next);
    let old_layout = match contents {
        Contents::Discard => vk::ImageLayout::UNDEFINED,
        Contents::Keep => old_layout,
    };
    vk::ImageMemoryBarrier2::default()
        .src_stage_mask(src_stage)
        .src_access_mask(src_access)
        .dst_stage_mask(dst_stage)
        .dst_access_mask(dst_access)
        .old_layout(old_layout)
        .new_layout(new_layout)
        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .image(image.image)
        .subresource_range(subresource_range(image.aspect()))
}

/// Where an upload takes its images (`Recording::declare_upload`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Upload {
    /// Before the copies: every level from UNDEFINED (nothing in it yet) to a copy destination.
    Copies,
    /// After them: to fragment shaders' sampling, and every buffer the copies wrote visible to
    /// the vertex, index, uniform and storage reads after.
    Reads,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each access's usage holds what its layout needs: Vulkan allows a barrier into a layout
    /// only for images with that layout's usage (VUID-VkImageMemoryBarrier2-oldLayout-01208 to
    /// -01212, -01658), so the frame checks built on `usage` refuse what the layer would.
    #[test]
    fn every_access_needs_the_usage_its_layout_requires() {
        use vk::{ImageLayout as L, ImageUsageFlags as U};
        let all = [
            ImageAccess::Nothing,
            ImageAccess::ColorAttachment,
            ImageAccess::DepthStencilAttachment,
            ImageAccess::StencilAttachmentDepthSampled,
            ImageAccess::FragmentSampled,
            ImageAccess::ComputeSampled,
            ImageAccess::ComputeStorage,
            ImageAccess::FragmentStorage,
            ImageAccess::ComputeDepthStencilSampled,
            ImageAccess::ComputeDepthSampled,
            ImageAccess::TransferSource,
        ];
        for access in all {
            let (layout, ..) = access_info(access);
            let required = match layout {
                L::UNDEFINED => U::empty(),
                L::COLOR_ATTACHMENT_OPTIMAL => U::COLOR_ATTACHMENT,
                L::DEPTH_STENCIL_ATTACHMENT_OPTIMAL => U::DEPTH_STENCIL_ATTACHMENT,
                L::DEPTH_STENCIL_READ_ONLY_OPTIMAL
                | L::DEPTH_READ_ONLY_STENCIL_ATTACHMENT_OPTIMAL => {
                    U::DEPTH_STENCIL_ATTACHMENT | U::SAMPLED
                }
                L::SHADER_READ_ONLY_OPTIMAL => U::SAMPLED,
                // GENERAL itself needs nothing; histencil uses it for storage images only.
                L::GENERAL => U::STORAGE,
                L::TRANSFER_SRC_OPTIMAL => U::TRANSFER_SRC,
                other => panic!("{access:?}: layout {other:?} not in this table"),
            };
            assert!(
                access.usage().contains(required),
                "{access:?}: {layout:?} needs {required:?}, usage() says {:?}",
                access.usage()
            );
        }
    }

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
