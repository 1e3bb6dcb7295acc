//! The mesh passes: the G-buffer pass (surface attributes, BRDF id into the stencil BRDF bits) and
//! the forward reference (every object lit by every light, per pixel).

use super::{
    begin_hdr_rendering, begin_rendering, clear_depth_stencil, color_attachment,
    depth_stencil_attachment, Load, CLEAR_BLACK,
};
use crate::access::{transition, Contents, ImageAccess, LightingTargets};
use crate::context::Context;
use crate::gpu_types::DrawPush;
use crate::meshes::Meshes;
use crate::state::{apply, oriented, with_stencil, OPAQUE};
use ash::vk;
use histencil_model::{
    CompareOp, DepthConvention, DepthState, FaceStencil, PassState, StencilLayout, StencilOp,
};
use histencil_scene::Scene;

pub struct GeometryPass<'a> {
    pub ctx: &'a Context,
    pub cmd: vk::CommandBuffer,
    pub scene: &'a Scene,
    pub meshes: &'a Meshes,
    pub pipeline: vk::Pipeline,
    pub pipeline_layout: vk::PipelineLayout,
    pub frame_set: vk::DescriptorSet,
    /// Each object's material set (set 1: its texture maps), in `Scene::objects` order.
    pub material_sets: &'a [vk::DescriptorSet],
    pub extent: vk::Extent2D,
    /// Each object's material index (its LUT table), stored in the G-buffer.
    pub material_indices: &'a [u32],
    /// Which end of depth is near: the depth test and the clear follow it.
    pub depth: DepthConvention,
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

impl GeometryPass<'_> {
    /// Draws the objects `state_of` gives a state, each with its material set and push
    /// constants.
    fn draw_objects(&self, state_of: impl Fn(usize) -> Option<PassState>) {
        let d = &self.ctx.device;
        unsafe {
            d.cmd_bind_pipeline(self.cmd, vk::PipelineBindPoint::GRAPHICS, self.pipeline);
            d.cmd_bind_descriptor_sets(
                self.cmd,
                vk::PipelineBindPoint::GRAPHICS,
                self.pipeline_layout,
                0,
                &[self.frame_set],
                &[],
            );
        }
        let mut bound = None;
        for (i, object) in self.scene.objects.iter().enumerate() {
            let Some(state) = state_of(i) else { continue };
            apply(self.ctx, self.cmd, &state);
            if bound != Some(self.material_sets[i]) {
                bound = Some(self.material_sets[i]);
                unsafe {
                    d.cmd_bind_descriptor_sets(
                        self.cmd,
                        vk::PipelineBindPoint::GRAPHICS,
                        self.pipeline_layout,
                        1,
                        &[self.material_sets[i]],
                        &[],
                    );
                }
            }
            let push = DrawPush::new(object.transform, &object.material, self.material_indices[i]);
            unsafe {
                d.cmd_push_constants(
                    self.cmd,
                    self.pipeline_layout,
                    vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                    0,
                    bytemuck::bytes_of(&push),
                );
            }
            self.meshes.shape(object.shape).draw(self.ctx, self.cmd);
        }
    }

    /// Writes the G-buffer and each draw's BRDF slot into the stencil BRDF bits.
    pub fn record_gbuffer(
        &self,
        targets: &mut LightingTargets,
        layout: &StencilLayout,
        slots: &[u32],
        preserved_pattern: u8,
    ) {
        let (ctx, cmd) = (self.ctx, self.cmd);
        ctx.begin_label(cmd, "gbuffer");
        for image in targets.gbuffer.iter_mut() {
            transition(
                ctx,
                cmd,
                image,
                ImageAccess::ColorAttachment,
                Contents::Discard,
            );
        }
        transition(
            ctx,
            cmd,
            &mut targets.depth_stencil,
            ImageAccess::DepthStencilAttachment,
            Contents::Discard,
        );
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
        let clear = Load::Clear(clear_depth_stencil(self.depth));
        let ds = depth_stencil_attachment(&targets.depth_stencil, clear);
        begin_rendering(ctx, cmd, self.extent, &colors, Some(&ds));
        self.draw_objects(|i| {
            Some(match gbuffer_stencil(layout, slots[i], preserved_pattern) {
                Some(s) => with_stencil(oriented(OPAQUE, self.depth), s),
                None => oriented(OPAQUE, self.depth),
            })
        });
        unsafe { ctx.device.cmd_end_rendering(cmd) };
        ctx.end_label(cmd);
    }

    /// The forward reference: lit HDR colour straight from the meshes.
    pub fn record_forward(&self, targets: &mut LightingTargets) {
        let depth = Load::Clear(clear_depth_stencil(self.depth));
        self.record_into_hdr(targets, "forward", depth, |_| {
            Some(oriented(OPAQUE, self.depth))
        });
    }

    /// After the G-buffer pass (whose depth it reads): clears the HDR target and writes the
    /// radiance of every emitting object where that object is the visible surface (depth at or
    /// in front of the stored one: the same vertex stage computes it again, and no driver
    /// decorates `gl_Position` invariant without complaint; nothing written but colour), so
    /// the light passes add onto it and emission counts once.
    pub fn record_emissive(&self, targets: &mut LightingTargets) {
        let visible = oriented(VISIBLE_AGAIN, self.depth);
        self.record_into_hdr(targets, "emissive", Load::Keep, |i| {
            self.scene.objects[i].material.emits().then_some(visible)
        });
    }

    /// A pass labelled `label` into the cleared HDR target and the depth-stencil (`depth`:
    /// cleared or kept), drawing the objects `state_of` gives a state.
    fn record_into_hdr(
        &self,
        targets: &mut LightingTargets,
        label: &str,
        depth: Load,
        state_of: impl Fn(usize) -> Option<PassState>,
    ) {
        let (ctx, cmd) = (self.ctx, self.cmd);
        ctx.begin_label(cmd, label);
        begin_hdr_rendering(
            ctx,
            cmd,
            (&mut targets.hdr, &mut targets.depth_stencil),
            self.extent,
            Load::Clear(CLEAR_BLACK),
            depth,
        );
        self.draw_objects(state_of);
        unsafe { ctx.device.cmd_end_rendering(cmd) };
        ctx.end_label(cmd);
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
