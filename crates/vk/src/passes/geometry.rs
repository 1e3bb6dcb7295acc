//! The mesh passes: the G-buffer pass (surface attributes, BRDF id into the stencil BRDF bits),
//! the forward reference (every object lit by every light, per pixel) and the emission after
//! the G-buffer pass. [`MeshPasses`] owns their pipelines; each frame they draw [`MeshInputs`].

use super::{
    begin_hdr_rendering, clear_depth_stencil, color_attachment, depth_stencil_attachment, Load,
    CLEAR_BLACK,
};
use crate::gpu::access::{uses_of, Contents, ImageAccess, LightingTargets};
use crate::gpu::device::context::Context;
use crate::gpu::device::descriptors::{binding, pass_layouts, BindingDesc, BindingKind};
use crate::gpu::device::error::Result;
use crate::gpu::device::pipelines::{create_pipeline, Blend, PipelineDesc, VertexInput};
use crate::gpu::device::teardown::build;
use crate::gpu::encoder::meshes::Meshes;
use crate::gpu::encoder::recording::Recording;
use crate::gpu::frame::gpu_types::PUSH_CONSTANT_BYTES;
use crate::gpu::frame::state::{oriented, with_stencil, OPAQUE};
use crate::shaders;
use ash::vk;
use bytemuck::{Pod, Zeroable};
use glam::Mat4;
use histencil_model::{
    CompareOp, CullMode, DepthConvention, DepthState, FaceStencil, PassState, StencilLayout,
    StencilOp,
};
use histencil_scene::Material;
use histencil_scene::Scene;

/// `Draw` push constants in draw.glsl.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub struct DrawPush {
    /// Object to world.
    pub model: [[f32; 4]; 4],
    /// rgb: the material's tint; w: its material index (the LUT technique's table).
    pub tint: [f32; 4],
    /// xyz: the BRDF's packed parameters; w: its model index.
    pub params: [f32; 4],
}

impl DrawPush {
    /// `material_index` is the material's LUT table (the G-buffer stores it for the LUT
    /// technique).
    pub fn new(model: Mat4, material: &Material, material_index: u32) -> Self {
        let p = material.brdf.packed_params();
        Self {
            model: model.to_cols_array_2d(),
            tint: material.tint.extend(material_index as f32).to_array(),
            params: [
                p[0] as f32,
                p[1] as f32,
                p[2] as f32,
                material.brdf.model_index() as f32,
            ],
        }
    }
}

// Every pipeline layout's push range is `Draw`'s size.
const _: () = assert!(std::mem::size_of::<DrawPush>() as u32 == PUSH_CONSTANT_BYTES);

/// Set 1 of the mesh pipelines (include/material.glsl): a material's map record, its three
/// maps and their samplers.
pub(crate) const MATERIAL_SET: &[BindingDesc] = &[
    binding(0, BindingKind::UniformBuffer, "material_maps"),
    binding(1, BindingKind::SampledImage, "map_base_color"),
    binding(2, BindingKind::SampledImage, "map_normal"),
    binding(3, BindingKind::SampledImage, "map_metallic_roughness"),
    binding(4, BindingKind::SampledImage, "map_emissive"),
    binding(5, BindingKind::Sampler, "sampler_base_color"),
    binding(6, BindingKind::Sampler, "sampler_normal"),
    binding(7, BindingKind::Sampler, "sampler_metallic_roughness"),
    binding(8, BindingKind::Sampler, "sampler_emissive"),
];

/// The mesh passes, made once: the G-buffer, forward and emission pipelines, their pipeline
/// layout (set 0 the frame, set 1 an object's material) and the material set layout.
#[derive(Default)]
pub struct MeshPasses {
    /// Set 1 of the mesh pipelines; the sets are the materials' (`materials.rs`).
    pub material_layout: vk::DescriptorSetLayout,
    pipeline_layout: vk::PipelineLayout,
    gbuffer: vk::Pipeline,
    forward: vk::Pipeline,
    /// Emitted radiance into the HDR target after the G-buffer pass (equal depth).
    emissive: vk::Pipeline,
}

/// The formats the mesh passes render to.
pub struct MeshFormats {
    /// The G-buffer's colour attachments, in binding order ([`crate::GBUFFER_FORMATS`]).
    pub gbuffer: [vk::Format; 3],
    /// The HDR target the forward and emission passes write.
    pub hdr: vk::Format,
    /// The depth-stencil the device was given or chose.
    pub depth_stencil: vk::Format,
}

/// What the mesh passes draw in one frame.
pub struct MeshInputs<'a> {
    /// The objects drawn, with their transforms and materials.
    pub scene: &'a Scene,
    /// The built-in shapes and the scene's imported meshes the objects are drawn with.
    pub meshes: &'a Meshes,
    /// Set 0: the frame's uniforms and lights.
    pub frame_set: vk::DescriptorSet,
    /// Each object's material set (set 1: its texture maps), in `Scene::objects` order.
    pub material_sets: &'a [vk::DescriptorSet],
    /// Each object's material index (its LUT table), stored in the G-buffer.
    pub material_indices: &'a [u32],
    /// The size of the targets: the render area and viewport.
    pub extent: vk::Extent2D,
    /// Which end of depth is near: the depth test and the clear follow it.
    pub depth: DepthConvention,
}

/// What the G-buffer pass writes into the stencil: each object's BRDF slot into the layout's
/// BRDF bits, the engine's pattern into its preserved bits.
pub struct GbufferStencil<'a> {
    /// Where the BRDF and preserved bits sit.
    pub layout: &'a StencilLayout,
    /// Each object's BRDF slot, in `Scene::objects` order.
    pub slots: &'a [u32],
    /// The engine's bits for the preserved stencil bits; bits outside
    /// `StencilLayout::preserved_mask` are dropped.
    pub preserved_pattern: u8,
}

/// The stencil state with which the G-buffer pass writes `slot` (a BRDF's index among those in
/// use) into the BRDF bits and the engine's `preserved_pattern` into the preserved bits; the
/// culling bit stays 0. `None` when there is nothing to write (one BRDF, no pattern): the clear
/// already left 0.
pub fn gbuffer_stencil(
    layout: &StencilLayout,
    slot: u32,
    preserved_pattern: u8,
) -> Option<FaceStencil> {
    // With one BRDF there are no BRDF bits and slot 0's reference is 0.
    let value = layout.brdf_reference(slot) | (preserved_pattern & layout.preserved_mask());
    (layout.has_brdf_bits() || value != 0).then_some(FaceStencil::writing(
        !layout.culling_mask(),
        value,
        StencilOp::Replace,
        StencilOp::Keep,
    ))
}

impl MeshPasses {
    /// The pipelines and layouts, the forward reference shading with `forward` (`forward.frag`
    /// as histencil builds it, or compiled for a BRDF set); a failure half way frees what was
    /// made.
    pub fn new(
        ctx: &Context,
        frame_layout: vk::DescriptorSetLayout,
        formats: &MeshFormats,
        forward: &'static [u8],
    ) -> Result<Self> {
        build(ctx, |p: &mut Self| {
            (p.material_layout, p.pipeline_layout) =
                pass_layouts(ctx, "mesh", frame_layout, MATERIAL_SET)?;
            let hdr = [formats.hdr];
            let base = PipelineDesc {
                name: "",
                vertex: ("mesh.vert", shaders::MESH_VERT),
                fragment: None,
                layout: p.pipeline_layout,
                vertex_input: VertexInput::Mesh,
                color_formats: &hdr,
                color_writes: true,
                blend: Blend::Off,
                depth_stencil_format: formats.depth_stencil,
                depth_clamp: false,
                specialization: &[],
            };
            let fragment = |name, spirv| PipelineDesc {
                name,
                fragment: Some(spirv),
                ..base
            };
            p.gbuffer = create_pipeline(
                ctx,
                &PipelineDesc {
                    color_formats: &formats.gbuffer,
                    ..fragment("gbuffer-pipeline", ("gbuffer.frag", shaders::GBUFFER_FRAG))
                },
            )?;
            p.forward = create_pipeline(
                ctx,
                &fragment("forward-pipeline", ("forward.frag", forward)),
            )?;
            p.emissive = create_pipeline(
                ctx,
                &fragment(
                    "emissive-pipeline",
                    ("emissive.frag", shaders::EMISSIVE_FRAG),
                ),
            )?;
            Ok(())
        })
    }

    fn draw<'a>(
        &self,
        rec: &'a Recording<'a>,
        pipeline: vk::Pipeline,
        inputs: &'a MeshInputs<'a>,
    ) -> Draw<'a> {
        Draw {
            rec,
            pipeline,
            pipeline_layout: self.pipeline_layout,
            inputs,
        }
    }

    /// Writes the G-buffer and each draw's BRDF slot into the stencil BRDF bits. Part of the
    /// pass [`names::GBUFFER`](super::names::GBUFFER), which its caller records
    /// (`Renderer::record_gbuffer_into`, with the emissive draws where a frame has them).
    pub(crate) fn record_gbuffer(
        &self,
        rec: &Recording,
        inputs: &MeshInputs,
        stencil: &GbufferStencil,
        targets: &mut LightingTargets,
    ) {
        let (color, discard) = (ImageAccess::ColorAttachment, Contents::Discard);
        let mut uses = uses_of(&mut targets.gbuffer, color, discard);
        let ds = ImageAccess::DepthStencilAttachment;
        uses.push((&mut targets.depth_stencil, ds, discard));
        rec.declare(&mut uses);
        // The material target's w (BRDF id) is cleared to -1: "no geometry here".
        let no_brdf = vk::ClearValue {
            color: vk::ClearColorValue {
                float32: [0.0, 0.0, 0.0, -1.0],
            },
        };
        let clears = [CLEAR_BLACK, CLEAR_BLACK, no_brdf];
        let colors: Vec<_> = targets
            .gbuffer
            .iter()
            .zip(clears)
            .map(|(i, clear)| color_attachment(i, Load::Clear(clear)))
            .collect();
        let depth = inputs.depth;
        let clear = Load::Clear(clear_depth_stencil(depth));
        let ds = depth_stencil_attachment(&targets.depth_stencil, clear);
        rec.begin_rendering_over(inputs.extent, &colors, Some(&ds));
        let GbufferStencil {
            layout,
            slots,
            preserved_pattern,
        } = *stencil;
        self.draw(rec, self.gbuffer, inputs).objects(|i| {
            Some(match gbuffer_stencil(layout, slots[i], preserved_pattern) {
                Some(s) => with_stencil(oriented(OPAQUE, depth), s),
                None => oriented(OPAQUE, depth),
            })
        });
        rec.end_rendering();
    }

    /// The forward reference: lit HDR colour straight from the meshes.
    pub(crate) fn record_forward(
        &self,
        rec: &Recording,
        inputs: &MeshInputs,
        targets: &mut LightingTargets,
    ) {
        let depth = Load::Clear(clear_depth_stencil(inputs.depth));
        let opaque = oriented(OPAQUE, inputs.depth);
        rec.pass(super::names::FORWARD, |rec| {
            let draw = self.draw(rec, self.forward, inputs);
            draw.hdr_pass(targets, depth, |_| Some(opaque));
        });
    }

    /// After the G-buffer pass (whose depth it reads): clears the HDR target and writes the
    /// radiance of every emitting object where that object is the visible surface (depth at or
    /// in front of the stored one: the same vertex stage computes it again, and no driver
    /// decorates `gl_Position` invariant without complaint; nothing written but colour), so
    /// the light passes add onto it and emission counts once.
    pub(crate) fn record_emissive(
        &self,
        rec: &Recording,
        inputs: &MeshInputs,
        targets: &mut LightingTargets,
    ) {
        let visible = oriented(VISIBLE_AGAIN, inputs.depth);
        let objects = &inputs.scene.objects;
        rec.step("emissive", |rec| {
            let draw = self.draw(rec, self.emissive, inputs);
            draw.hdr_pass(targets, Load::Keep, |i| {
                objects[i].material.emits().then_some(visible)
            });
        });
    }

    /// Frees the pipelines and layouts; a second call does nothing.
    pub fn destroy(&mut self, ctx: &Context) {
        // SAFETY: the handles are null or were made by `new` from this device, and reset to
        // null after, so a second call destroys nothing. The GPU is done with them: the
        // renderer's Drop waits for the device first, and `build` and `Owned` destroy them
        // before any frame recorded.
        unsafe {
            for p in [self.gbuffer, self.forward, self.emissive] {
                ctx.device.destroy_pipeline(p, None);
            }
            ctx.device
                .destroy_pipeline_layout(self.pipeline_layout, None);
            ctx.device
                .destroy_descriptor_set_layout(self.material_layout, None);
        }
        *self = Self::default();
    }
}

crate::gpu::device::teardown::destroy_by_method!(MeshPasses);

/// One mesh pass being recorded: a pipeline and the frame's inputs.
struct Draw<'a> {
    rec: &'a Recording<'a>,
    pipeline: vk::Pipeline,
    pipeline_layout: vk::PipelineLayout,
    inputs: &'a MeshInputs<'a>,
}

impl Draw<'_> {
    /// Draws the objects `state_of` gives a state, each with its material set and push
    /// constants.
    fn objects(&self, state_of: impl Fn(usize) -> Option<PassState>) {
        let (rec, inputs) = (self.rec, self.inputs);
        // SAFETY: the recording is inside the rendering the pass began (`record_gbuffer`,
        // `hdr_pass`) into attachments of the formats the pipeline was made for (`MeshFormats`;
        // `Renderer::record_gbuffer` checks an engine's images). The pipeline and layout were
        // made by `new` and live as long as `self`; the frame set is of set 0's layout.
        unsafe { rec.bind_graphics(self.pipeline, self.pipeline_layout, &[inputs.frame_set]) };
        let mut bound = None;
        for (i, object) in inputs.scene.objects.iter().enumerate() {
            let Some(mut state) = state_of(i) else {
                continue;
            };
            if object.material.double_sided {
                state.cull = CullMode::None;
            }
            rec.apply(&state);
            let set = inputs.material_sets[i];
            if bound != Some(set) {
                bound = Some(set);
                // SAFETY: as above; `set` is the object's material set, allocated from
                // `material_layout`, set 1 of this layout (`GpuMaterials::new`).
                unsafe {
                    let graphics = vk::PipelineBindPoint::GRAPHICS;
                    rec.bind_sets(graphics, self.pipeline_layout, 1, &[set]);
                }
            }
            let push = DrawPush::new(
                object.transform,
                &object.material,
                inputs.material_indices[i],
            );
            // SAFETY: as above; the push is `DrawPush` at offset 0, the layout's graphics-stage
            // range (`PUSH_CONSTANT_BYTES` is its size).
            unsafe {
                let stages = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT;
                rec.push(self.pipeline_layout, stages, 0, bytemuck::bytes_of(&push));
            }
            inputs.meshes.shape(object.shape).draw(rec);
        }
    }

    /// Draws into the cleared HDR target and the depth-stencil (`depth`: cleared or kept) the
    /// objects `state_of` gives a state; unlabelled, inside its caller's pass or step.
    fn hdr_pass(
        &self,
        targets: &mut LightingTargets,
        depth: Load,
        state_of: impl Fn(usize) -> Option<PassState>,
    ) {
        let rec = self.rec;
        let attachments = (&mut targets.hdr, &mut targets.depth_stencil);
        let (extent, hdr) = (self.inputs.extent, Load::Clear(CLEAR_BLACK));
        begin_hdr_rendering(rec, attachments, extent, hdr, depth);
        self.objects(state_of);
        rec.end_rendering();
    }
}

/// The visible surface again: depth at or in front of what the G-buffer pass wrote, nothing
/// written but colour.
const VISIBLE_AGAIN: PassState = PassState {
    depth: DepthState {
        compare: Some(CompareOp::LessOrEqual),
        write: false,
    },
    ..OPAQUE
};

#[cfg(test)]
mod tests {
    use super::*;
    use histencil_model::CompareOp;

    #[test]
    fn gbuffer_writes_only_brdf_bits() {
        let layout = StencilLayout::new(3, 0).unwrap();
        let s = gbuffer_stencil(&layout, 2, 0).unwrap();
        assert_eq!(s.write_mask, 0xFE);
        assert_eq!(s.reference, 0x04);
        assert_eq!(s.compare, CompareOp::Always);
        // The pattern lands in the preserved bits only, never in the culling or BRDF bits.
        assert_eq!(
            gbuffer_stencil(&layout, 1, 0xFF).unwrap().reference,
            0xF8 | 0x02
        );
        let single = StencilLayout::new(1, 0).unwrap();
        assert!(gbuffer_stencil(&single, 0, 0).is_none());
        assert_eq!(gbuffer_stencil(&single, 0, 0xA1).unwrap().reference, 0xA0);
    }
}
