//! The depth-id technique, as Bevy's deferred renderer lights its lighting passes
//! (`bevy_pbr/src/deferred/mod.rs`, `bevy_core_pipeline/src/deferred/copy_lighting_id.rs`):
//! instead of the BRDF id in stencil bits, each pixel's BRDF slot is copied into a 16-bit unorm
//! depth image (`depth_id_copy.frag`; 16 bits because 8-bit ids compared wrong on some GPUs,
//! Bevy PR #10304), then each BRDF of the frame is one full-screen triangle drawn at its slot's
//! depth with compare EQUAL (`depth_id_shade.frag`). The depth test is the whole selection, so a
//! GPU's hierarchical depth rejects whole tiles holding no pixel of the pass's BRDF before a
//! fragment runs, which is what the talk asks of hierarchical stencil, with no stencil bits
//! spent and nothing to flush.
//!
//! Each pixel adds its tile's lights: the tiled technique's classification and light lists run
//! first (`passes/tiled.rs`, whose sets and buffers this binds), and the shade pass adds the
//! same sum as the tiled kernels (`tile_light_sum.glsl`), so the two techniques' images agree
//! bit for bit and differ only in how a BRDF's pixels are found: listed tiles dispatched by
//! compute, against rasterised full-screen passes the depth test selects. llvmpipe has no
//! hierarchical depth (its depth test runs per pixel, after the fragment is rasterised), so
//! what the EQUAL test saves on a GPU is modelled in the simulator
//! (`histencil_model::depth_id_stats`), not timed here.

use crate::gpu::access::{uses_of, BufferAccess, Contents, ImageAccess, LightingTargets};
use crate::gpu::device::context::Context;
use crate::gpu::device::descriptors::create_pipeline_layout;
use crate::gpu::device::error::Result;
use crate::gpu::device::pipelines::{create_pipeline, Blend, PipelineDesc, VertexInput};
use crate::gpu::device::resources::{Buffer, Image};
use crate::gpu::device::teardown::{build, Destroy};
use crate::gpu::encoder::recording::Recording;
use crate::passes::light_modules::LightModules;
use crate::passes::{depth_stencil_attachment, Load};
use crate::shaders;
use ash::vk;
use histencil_brdf::BrdfId;
use histencil_model::{CompareOp, CullMode, DepthState, PassState};

/// The id image's format: every Vulkan device renders to 16-bit unorm depth.
pub const ID_FORMAT: vk::Format = vk::Format::D16_UNORM;

/// The id image's code of BRDF slot `slot` (`depth_id_copy.frag` writes `(slot + 1) / 65535`):
/// the model's, which reads the image back (`histencil_model::depth_id`).
pub fn depth_code(slot: usize) -> u16 {
    histencil_model::depth_id::slot_id(slot as u32)
}

/// The depth a slot's shade pass draws at: its code as a unorm value, computed as the copy
/// computes it, so both round to the same 16-bit code.
fn depth_of(slot: usize) -> f32 {
    f32::from(depth_code(slot)) / f32::from(u16::MAX)
}

/// What a [`DepthIdPass`] is made for.
pub(crate) struct DepthIdDesc<'a> {
    pub extent: vk::Extent2D,
    /// The side of the tiles whose light lists the shade passes read.
    pub tile_side: u32,
    /// The BRDF of each slot.
    pub brdfs: &'a [BrdfId],
    pub frames_in_flight: u32,
    /// The light shaders: histencil's, or an engine's compiled with its hooks.
    pub modules: &'a LightModules,
    /// The set layouts, as the tiled technique's pipelines bind them (sets 0 to 2, then the
    /// filler and the visibility hook's, if any), each visible to the fragment stage.
    pub set_layouts: &'a [vk::DescriptorSetLayout],
    /// Bytes of the tiled technique's push constants, which the fragment shaders read.
    pub push_bytes: u32,
}

/// The id copy and one shade pipeline per BRDF slot, and an id image per frame-in-flight slot.
#[derive(Default)]
pub(crate) struct DepthIdPass {
    pipeline_layout: vk::PipelineLayout,
    copy: vk::Pipeline,
    shade: Vec<vk::Pipeline>,
    ids: Vec<Image>,
}

impl Destroy for DepthIdPass {
    fn destroy(&mut self, ctx: &Context) {
        let d = &ctx.device;
        // SAFETY: every handle is null or was made by `new` from this device, and is nulled (or
        // drained) as it goes, so a second call destroys nothing. The GPU is done with them:
        // `build` destroys after a failed `new` (nothing recorded), the lighting's Drop after
        // its slots finished or the device went idle.
        unsafe {
            for p in self.shade.drain(..).chain([self.copy]) {
                d.destroy_pipeline(p, None);
            }
            self.copy = vk::Pipeline::null();
            d.destroy_pipeline_layout(self.pipeline_layout, None);
            self.pipeline_layout = vk::PipelineLayout::null();
        }
        for image in &mut self.ids {
            image.destroy(ctx);
        }
        self.ids.clear();
    }
}

/// `slots` id images of `extent`; a failure frees those made.
fn id_images(ctx: &Context, extent: vk::Extent2D, slots: u32) -> Result<Vec<Image>> {
    let mut images = Vec::new();
    for slot in 0..slots {
        let name = format!("depth-id-image-{slot}");
        // Copied out for the statistics (`Renderer::depth_id_stats`).
        let usage =
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC;
        match Image::new(ctx, &name, ID_FORMAT, extent, usage) {
            Ok(image) => images.push(image),
            Err(e) => {
                for mut image in images {
                    image.destroy(ctx);
                }
                return Err(e);
            }
        }
    }
    Ok(images)
}

impl DepthIdPass {
    /// The pipeline layout, the pipelines and the id images; a failure half way frees what was
    /// made.
    pub fn new(ctx: &Context, desc: &DepthIdDesc) -> Result<Self> {
        build(ctx, |p: &mut Self| {
            let fragment = vk::ShaderStageFlags::FRAGMENT;
            p.pipeline_layout = create_pipeline_layout(
                ctx,
                "depth-id-pipeline-layout",
                desc.set_layouts,
                fragment,
                desc.push_bytes,
            )?;
            let pipeline = |name: &str, fragment: (&str, &[u8]), constants: &[u32]| {
                create_pipeline(
                    ctx,
                    &PipelineDesc {
                        name,
                        vertex: ("fullscreen.vert", shaders::FULLSCREEN_VERT),
                        fragment: Some(fragment),
                        layout: p.pipeline_layout,
                        vertex_input: VertexInput::None,
                        color_formats: &[],
                        color_writes: false,
                        blend: Blend::Off,
                        depth_stencil_format: ID_FORMAT,
                        depth_clamp: false,
                        specialization: constants,
                    },
                )
            };
            let copy = ("depth_id_copy.frag", desc.modules.depth_id_copy);
            p.copy = pipeline("depth-id-copy-pipeline", copy, &[])?;
            let shade = ("depth_id_shade.frag", desc.modules.depth_id_shade);
            for brdf in desc.brdfs {
                let name = format!("depth-id-shade-{}-pipeline", brdf.name());
                let constants = [brdf.index(), desc.tile_side];
                p.shade.push(pipeline(&name, shade, &constants)?);
            }
            p.ids = id_images(ctx, desc.extent, desc.frames_in_flight)?;
            Ok(())
        })
    }

    /// The id images for a new `extent`, the pipelines kept; a failure leaves the images as they
    /// were. The GPU has finished every frame that used them.
    pub fn resize(&mut self, ctx: &Context, extent: vk::Extent2D) -> Result<()> {
        let fresh = id_images(ctx, extent, self.ids.len() as u32)?;
        for mut old in std::mem::replace(&mut self.ids, fresh) {
            old.destroy(ctx);
        }
        Ok(())
    }

    /// Records a copy of frame-in-flight `slot`'s id image (as its last frame left it) into
    /// `buffer`, 2 bytes per pixel, for [`crate::Renderer`]'s statistics.
    pub fn copy_ids(&mut self, rec: &Recording, slot: u32, buffer: &Buffer) {
        let image = &mut self.ids[slot as usize];
        rec.copy_image_to_buffer(image, vk::ImageAspectFlags::DEPTH, buffer);
    }

    /// The pipelines this pass holds.
    pub fn pipeline_count(&self) -> usize {
        1 + self.shade.len()
    }

    /// Records the id copy and each slot's shade pass after the tiled technique's
    /// classification and light lists in `cmd` (`bound`: the sets 0 to 2 they bound, then the
    /// visibility hook's set; `push`: their push constants), into frame-in-flight `slot`'s id
    /// image, reading `tile_buffers` (the tiled technique's). The surfaces are read by fragment shaders (with `depth_sampled`, the depth aspect
    /// of the depth-stencil image too) and the HDR target stored to by them, left in `GENERAL`.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &mut self,
        rec: &Recording,
        slot: u32,
        bound: ([vk::DescriptorSet; 3], Option<vk::DescriptorSet>),
        push: &[u8],
        targets: &mut LightingTargets,
        depth_sampled: bool,
        tile_buffers: [vk::Buffer; 4],
    ) {
        rec.step("depth-id", |rec| {
            // The tile buffers the classification and light lists wrote, read by the shade
            // passes' fragment shaders (the images by their transitions below).
            rec.declare_buffers(&tile_buffers.map(|b| (b, BufferAccess::FragmentRead)));
            let keep = Contents::Keep;
            let sampled = ImageAccess::FragmentSampled;
            let mut uses = uses_of(&mut targets.gbuffer, sampled, keep);
            if depth_sampled {
                let access = ImageAccess::StencilAttachmentDepthSampled;
                uses.push((&mut targets.depth_stencil, access, keep));
            }
            uses.push((&mut targets.hdr, ImageAccess::FragmentStorage, keep));
            let ids = &mut self.ids[slot as usize];
            uses.push((ids, ImageAccess::DepthStencilAttachment, Contents::Discard));
            rec.declare(&mut uses);
            let ids = &self.ids[slot as usize];
            let far = vk::ClearValue {
                depth_stencil: vk::ClearDepthStencilValue {
                    depth: 1.0,
                    stencil: 0,
                },
            };
            let attachment = depth_stencil_attachment(ids, Load::Clear(far));
            let extent = ids.extent;
            let area = vk::Rect2D::default().extent(extent);
            let info = vk::RenderingInfo::default()
                .render_area(area)
                .layer_count(1)
                .depth_attachment(&attachment);
            let graphics = vk::PipelineBindPoint::GRAPHICS;
            let layout = self.pipeline_layout;
            let (sets, visibility) = bound;
            // The id image was just transitioned to a depth attachment and `info` names only it,
            // over its extent.
            rec.begin_rendering(&info);
            rec.set_scissor(area);
            // SAFETY: the sets match the layout `new` made from `DepthIdDesc::set_layouts` (sets
            // 0 to 2, and 4 only when the hooks have a visibility layout); `push` is the tiled
            // technique's `PUSH_BYTES`, the layout's fragment range.
            unsafe {
                rec.bind_sets(graphics, layout, 0, &sets);
                if let Some(set) = visibility {
                    rec.bind_sets(graphics, layout, 4, &[set]);
                }
                rec.push(layout, vk::ShaderStageFlags::FRAGMENT, 0, push);
            }
            let viewport = |depth: Option<f32>| vk::Viewport {
                x: 0.0,
                y: 0.0,
                width: extent.width as f32,
                height: extent.height as f32,
                min_depth: depth.unwrap_or(0.0),
                max_depth: depth.unwrap_or(1.0),
            };
            let state = |compare, write| PassState {
                cull: CullMode::None,
                depth: DepthState {
                    compare: Some(compare),
                    write,
                },
                front: None,
                back: None,
                color_write: false,
                hi_stencil: None,
                depth_bounds: false,
            };
            // The copy: every surface pixel's slot as its depth (the shader writes the depth).
            rec.step("depth-id-copy", |rec| {
                rec.apply(&state(CompareOp::Always, true));
                rec.set_viewport(viewport(None));
                // SAFETY: inside the rendering begun above, with sets, push constants, scissor,
                // viewport and the pass state bound or set; the copy pipeline was made by `new`
                // for a depth-only `ID_FORMAT` attachment, this one; the full-screen triangle
                // reads no vertex buffer.
                unsafe {
                    rec.bind_pipeline(graphics, self.copy);
                    rec.draw(3, 0);
                }
            });
            // Each slot's pass at its depth: a viewport of no depth range pins every fragment
            // there. Depth attachment accesses are ordered within the rendering, so the passes
            // see the copy's depths without a barrier.
            rec.apply(&state(CompareOp::Equal, false));
            for (s, pipeline) in self.shade.iter().enumerate() {
                rec.step(&format!("depth-id-shade-{s}"), |rec| {
                    // The viewport's depth is one in [0, 1].
                    rec.set_viewport(viewport(Some(depth_of(s))));
                    // SAFETY: as for the copy above.
                    unsafe {
                        rec.bind_pipeline(graphics, *pipeline);
                        rec.draw(3, 0);
                    }
                });
            }
            rec.end_rendering();
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_slot_has_its_own_code_and_none_is_the_clear_value() {
        let codes: Vec<u16> = (0..32).map(depth_code).collect();
        assert!(codes.iter().all(|&c| c != 0 && c != u16::MAX));
        assert!(codes.windows(2).all(|w| w[0] < w[1]));
        // The shade pass's depth rounds to the code the copy writes.
        for slot in 0..32 {
            let unorm = (depth_of(slot) * f32::from(u16::MAX)).round() as u16;
            assert_eq!(unorm, depth_code(slot));
        }
    }
}
