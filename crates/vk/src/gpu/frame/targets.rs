//! The frame's render targets, named after their role (the names show up in validation messages
//! and captures).

use crate::gpu::access::LightingTargets;
use crate::gpu::device::context::Context;
use crate::gpu::device::error::{Error, Result};
use crate::gpu::device::resources::Image;
use crate::gpu::device::teardown::build;
use ash::vk;

/// The G-buffer's formats, in binding order: albedo, normal-depth, material
/// (`crates/vk/shaders/include/gbuffer_write.glsl` says what each channel holds).
pub const GBUFFER_FORMATS: [vk::Format; 3] = [
    vk::Format::R16G16B16A16_SFLOAT, // gbuffer-albedo
    vk::Format::R32G32B32A32_SFLOAT, // gbuffer-normal-depth
    vk::Format::R32G32B32A32_SFLOAT, // gbuffer-material
];
/// The renderer's HDR target format (an engine's may differ).
pub const HDR_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;
pub const LDR_FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;

#[derive(Default)]
pub struct Targets {
    pub gbuffer: [Image; 3],
    pub depth_stencil: Image,
    pub hdr: Image,
    pub ldr: Image,
}

/// Checks a requested resolution against the device.
pub fn check_extent(ctx: &Context, width: u32, height: u32) -> Result<vk::Extent2D> {
    let bad = |reason: String| Error::BadResolution {
        width,
        height,
        reason,
    };
    if width == 0 || height == 0 {
        return Err(bad("width and height must be at least 1".into()));
    }
    let max = ctx.max_image_dimension;
    if width > max || height > max {
        return Err(bad(format!(
            "this device allows at most {max} pixels per side"
        )));
    }
    Ok(vk::Extent2D { width, height })
}

impl Targets {
    /// Every target at `extent`; a failure half way frees the targets made so far.
    pub fn new(ctx: &Context, extent: vk::Extent2D) -> Result<Self> {
        use vk::ImageUsageFlags as U;
        let gbuffer_usage = U::COLOR_ATTACHMENT | U::SAMPLED | U::TRANSFER_SRC;
        let names = ["gbuffer-albedo", "gbuffer-normal-depth", "gbuffer-material"];
        build(ctx, |t: &mut Self| {
            for ((slot, name), format) in t.gbuffer.iter_mut().zip(names).zip(GBUFFER_FORMATS) {
                *slot = Image::new(ctx, name, format, extent, gbuffer_usage)?;
            }
            t.depth_stencil = Image::new(
                ctx,
                "depth-stencil",
                ctx.depth_stencil_format,
                extent,
                U::DEPTH_STENCIL_ATTACHMENT | U::TRANSFER_SRC | U::SAMPLED,
            )?;
            t.hdr = Image::new(
                ctx,
                "hdr-color",
                HDR_FORMAT,
                extent,
                // STORAGE: the tiled technique adds its lights with compute shaders.
                U::COLOR_ATTACHMENT | U::SAMPLED | U::TRANSFER_SRC | U::STORAGE,
            )?;
            t.ldr = Image::new(
                ctx,
                "ldr-color",
                LDR_FORMAT,
                extent,
                U::COLOR_ATTACHMENT | U::TRANSFER_SRC,
            )?;
            Ok(())
        })
    }

    /// The targets the lighting records against, with their current states.
    pub fn lighting(&self) -> LightingTargets {
        LightingTargets {
            gbuffer: vec![*self.gbuffer[0], *self.gbuffer[1], *self.gbuffer[2]],
            depth_stencil: *self.depth_stencil,
            hdr: *self.hdr,
        }
    }

    /// Takes back the states the lighting left `lit` in.
    pub fn lit(&mut self, lit: &LightingTargets) {
        for (image, state) in self.gbuffer.iter_mut().zip(&lit.gbuffer) {
            image.state = state.state;
        }
        self.depth_stencil.state = lit.depth_stencil.state;
        self.hdr.state = lit.hdr.state;
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for image in self.gbuffer.iter_mut() {
            image.destroy(ctx);
        }
        self.depth_stencil.destroy(ctx);
        self.hdr.destroy(ctx);
        self.ldr.destroy(ctx);
    }
}

crate::gpu::device::teardown::destroy_by_method!(Targets);
