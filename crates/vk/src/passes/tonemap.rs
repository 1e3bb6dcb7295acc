//! HDR -> 8-bit display colour. [`Tonemap`] owns its pipeline and the set that samples the
//! renderer's HDR target; each frame it reads [`TonemapInputs`].

use super::{color_attachment, Load, CLEAR_BLACK};
use crate::gpu::access::{Contents, ImageAccess};
use crate::gpu::device::context::Context;
use crate::gpu::device::descriptors::{
    binding, one_set, pass_layouts, write_sampled_images, BindingDesc, BindingKind,
};
use crate::gpu::device::error::Result;
use crate::gpu::device::pipelines::{create_pipeline, Blend, PipelineDesc, VertexInput};
use crate::gpu::device::teardown::build;
use crate::gpu::encoder::recording::Recording;
use crate::gpu::frame::state::FULLSCREEN;
use crate::gpu::frame::targets::Targets;
use crate::shaders;
use ash::vk;

/// Set 1 of the tonemap pipeline (tonemap.frag).
pub(crate) const TONEMAP_SET: &[BindingDesc] = &[binding(0, BindingKind::SampledImage, "hdr")];

/// The tonemap pass, made once for one HDR target.
#[derive(Default)]
pub struct Tonemap {
    set_layout: vk::DescriptorSetLayout,
    pipeline_layout: vk::PipelineLayout,
    pool: vk::DescriptorPool,
    /// Samples the HDR target.
    set: vk::DescriptorSet,
    pipeline: vk::Pipeline,
}

/// What the tonemap pass reads in one frame besides the HDR target.
pub struct TonemapInputs {
    /// Set 0: the frame's uniforms (exposure).
    pub frame_set: vk::DescriptorSet,
    /// The size of the LDR target: the render area.
    pub extent: vk::Extent2D,
}

impl Tonemap {
    /// The pipeline writing `ldr_format` and the set sampling `hdr_view`; a failure half way
    /// frees what was made.
    pub fn new(
        ctx: &Context,
        frame_layout: vk::DescriptorSetLayout,
        ldr_format: vk::Format,
        hdr_view: vk::ImageView,
    ) -> Result<Self> {
        build(ctx, |t: &mut Self| {
            (t.set_layout, t.pipeline_layout) =
                pass_layouts(ctx, "tonemap", frame_layout, TONEMAP_SET)?;
            (t.pool, t.set) = one_set(ctx, "tonemap-set", t.set_layout, TONEMAP_SET)?;
            write_sampled_images(ctx, t.set, &[hdr_view]);
            let ldr = [ldr_format];
            t.pipeline = create_pipeline(
                ctx,
                &PipelineDesc {
                    name: "tonemap-pipeline",
                    vertex: ("fullscreen.vert", shaders::FULLSCREEN_VERT),
                    fragment: Some(("tonemap.frag", shaders::TONEMAP_FRAG)),
                    layout: t.pipeline_layout,
                    vertex_input: VertexInput::None,
                    color_formats: &ldr,
                    color_writes: true,
                    blend: Blend::Off,
                    depth_stencil_format: vk::Format::UNDEFINED,
                    depth_clamp: false,
                    specialization: &[],
                },
            )?;
            Ok(())
        })
    }

    /// Tonemaps `targets.hdr` into `targets.ldr`.
    pub(crate) fn record(&self, rec: &Recording, inputs: &TonemapInputs, targets: &mut Targets) {
        rec.pass(super::names::TONEMAP, |rec| {
            rec.declare(&mut [
                (
                    &mut targets.hdr,
                    ImageAccess::FragmentSampled,
                    Contents::Keep,
                ),
                (
                    &mut targets.ldr,
                    ImageAccess::ColorAttachment,
                    Contents::Discard,
                ),
            ]);
            let colors = [color_attachment(&targets.ldr, Load::Clear(CLEAR_BLACK))];
            rec.begin_rendering_over(inputs.extent, &colors, None);
            // SAFETY: the pipeline, layout and set were made by `new` from this device and live
            // as long as `self`, the pipeline with that layout (for the LDR target's format, the
            // rendering's); the frame set is of set 0's layout and `self.set` of set 1's,
            // sampling the HDR target, transitioned above for fragment reads.
            unsafe {
                let sets = [inputs.frame_set, self.set];
                rec.bind_graphics(self.pipeline, self.pipeline_layout, &sets);
            }
            rec.apply(&FULLSCREEN);
            // SAFETY: inside the rendering begun above, with the pipeline, its sets and the
            // dynamic state it reads bound and set; the triangle reads no vertex buffer.
            unsafe { rec.draw(3, 0) };
            rec.end_rendering();
        });
    }

    /// Frees the pipeline, the set's pool and the layouts; a second call does nothing.
    pub fn destroy(&mut self, ctx: &Context) {
        // SAFETY: the handles are null or were made by `new` from this device, and reset to
        // null after, so a second call destroys nothing. The GPU is done with them: the
        // renderer's Drop waits for the device first, and `build` and `Owned` destroy them
        // before any frame recorded.
        unsafe {
            ctx.device.destroy_pipeline(self.pipeline, None);
            ctx.device.destroy_descriptor_pool(self.pool, None);
            ctx.device
                .destroy_pipeline_layout(self.pipeline_layout, None);
            ctx.device
                .destroy_descriptor_set_layout(self.set_layout, None);
        }
        *self = Self::default();
    }
}

crate::gpu::device::teardown::destroy_by_method!(Tonemap);
