//! Copying the frame's images back to the host: tonemapped colour, HDR colour and the raw stencil.

use crate::gpu::access::ImageRef;
use crate::gpu::access::{Contents, ImageAccess};
use crate::gpu::device::context::Context;
use crate::gpu::device::error::Result;
use crate::gpu::device::resources::Buffer;
use crate::gpu::device::teardown::build;
use crate::gpu::encoder::recording::Recording;
use crate::gpu::frame::targets::Targets;
use ash::vk;
use histencil_brdf::BrdfId;
use image::{GrayImage, Rgba32FImage, RgbaImage};

/// Which images a frame copies back.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Readback {
    /// The tonemapped colour ([`FrameImages::ldr`]).
    pub ldr: bool,
    /// The linear HDR colour ([`FrameImages::hdr`]).
    pub hdr: bool,
    /// The stencil after lighting ([`FrameImages::stencil`]).
    pub stencil: bool,
    /// The BRDF id the G-buffer stored per pixel (deferred only).
    pub brdf_ids: bool,
}

impl Readback {
    /// Nothing: a frame only timed, or whose images stay on the GPU.
    pub const NONE: Self = Self {
        ldr: false,
        hdr: false,
        stencil: false,
        brdf_ids: false,
    };
    /// Every image, for checks that compare them all.
    pub const ALL: Self = Self {
        ldr: true,
        hdr: true,
        stencil: true,
        brdf_ids: true,
    };
}

/// The images a frame copied back.
#[derive(Default)]
pub struct FrameImages {
    /// Tonemapped, sRGB-encoded colour.
    pub ldr: Option<RgbaImage>,
    /// Linear HDR colour (the lighting result before tonemapping).
    pub hdr: Option<Rgba32FImage>,
    /// The raw stencil byte of every pixel after the lighting pass.
    pub stencil: Option<GrayImage>,
    /// Per pixel (row-major), the BRDF the G-buffer pass stored; `None` where nothing was drawn.
    pub brdf_ids: Option<Vec<Option<BrdfId>>>,
}

impl Recording<'_> {
    /// Copies one aspect of the whole of `image` into `buffer`, tightly packed.
    pub(crate) fn copy_image_to_buffer(
        &self,
        image: &mut ImageRef,
        aspect: vk::ImageAspectFlags,
        buffer: &Buffer,
    ) {
        self.transition(image, ImageAccess::TransferSource, Contents::Keep);
        self.journal_transfer("copy from image", &[], &[buffer.handle]);
        let region = vk::BufferImageCopy::default()
            .image_subresource(
                vk::ImageSubresourceLayers::default()
                    .aspect_mask(aspect)
                    .layer_count(1),
            )
            .image_extent(vk::Extent3D {
                width: image.extent.width,
                height: image.extent.height,
                depth: 1,
            });
        // SAFETY: the recording's command buffer is recording outside rendering (a renderer's frame or
        // capture, or an engine's under `record`'s # Safety). The transition just put `image` in
        // TRANSFER_SRC_OPTIMAL; `aspect` is one aspect of its format, and every caller's `buffer`
        // has TRANSFER_DST usage and room for the whole extent at that aspect's texel size
        // (`ReadbackBuffers::new` and the like).
        unsafe {
            self.device().cmd_copy_image_to_buffer(
                self.outside(),
                image.image,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                buffer.handle,
                &[region],
            )
        };
    }
}

#[derive(Default)]
pub(crate) struct ReadbackBuffers {
    extent: vk::Extent2D,
    ldr: Buffer,
    hdr: Buffer,
    stencil: Buffer,
    material: Buffer,
}

impl ReadbackBuffers {
    pub fn new(ctx: &Context, extent: vk::Extent2D) -> Result<Self> {
        let pixels = u64::from(extent.width) * u64::from(extent.height);
        let buffer = |name, bytes_per_pixel| Buffer::readback(ctx, name, pixels * bytes_per_pixel);
        build(ctx, |r: &mut Self| {
            r.extent = extent;
            r.ldr = buffer("ldr-readback", 4)?;
            r.hdr = buffer("hdr-readback", 8)?;
            r.stencil = buffer("stencil-readback", 1)?;
            r.material = buffer("gbuffer-material-readback", 16)?;
            Ok(())
        })
    }

    pub fn record(&self, rec: &Recording, targets: &mut Targets, what: Readback) {
        if what == Readback::NONE {
            return;
        }
        rec.step("readback", |rec| {
            let color = vk::ImageAspectFlags::COLOR;
            if what.ldr {
                rec.copy_image_to_buffer(&mut targets.ldr, color, &self.ldr);
            }
            if what.hdr {
                rec.copy_image_to_buffer(&mut targets.hdr, color, &self.hdr);
            }
            if what.stencil {
                let stencil = vk::ImageAspectFlags::STENCIL;
                rec.copy_image_to_buffer(&mut targets.depth_stencil, stencil, &self.stencil);
            }
            if what.brdf_ids {
                rec.copy_image_to_buffer(&mut targets.gbuffer[2], color, &self.material);
            }
            rec.host_readable(vk::PipelineStageFlags2::COPY);
        });
    }

    /// The images `what` asks for; BRDF ids are named by `set`, the renderer's.
    pub fn read(&self, what: Readback, set: &histencil_brdf::BrdfSet) -> Result<FrameImages> {
        let (w, h) = (self.extent.width, self.extent.height);
        let mut images = FrameImages::default();
        if what.ldr {
            images.ldr = RgbaImage::from_raw(w, h, self.ldr.read().to_vec());
        }
        if what.hdr {
            let floats: Vec<f32> = self
                .hdr
                .read()
                .chunks_exact(2)
                .map(|b| {
                    histencil_brdf::half_float::f16_bits_to_f32(u16::from_le_bytes([b[0], b[1]]))
                })
                .collect();
            images.hdr = Rgba32FImage::from_raw(w, h, floats);
        }
        if what.stencil {
            images.stencil = GrayImage::from_raw(w, h, self.stencil.read().to_vec());
        }
        if what.brdf_ids {
            // gbuffer-material is RGBA32F with the BRDF id in w, cleared to -1 (no geometry).
            let by_index: Vec<Option<BrdfId>> = (0..histencil_brdf::MODEL_IDS)
                .map(|i| set.by_index(i))
                .collect();
            let ids = self
                .material
                .read()
                .chunks_exact(16)
                .map(|texel| {
                    let id = f32::from_le_bytes([texel[12], texel[13], texel[14], texel[15]]);
                    (id >= 0.0)
                        .then(|| by_index.get(id as usize).copied().flatten())
                        .flatten()
                })
                .collect();
            images.brdf_ids = Some(ids);
        }
        Ok(images)
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.ldr.destroy(ctx);
        self.hdr.destroy(ctx);
        self.stencil.destroy(ctx);
        self.material.destroy(ctx);
    }
}

crate::gpu::device::teardown::destroy_by_method!(ReadbackBuffers);
