//! The engine's G-buffer pass: its own shaders (writing histencil's contract through
//! `gbuffer_write.glsl`), reversed-Z depth, and each draw's stencil: the BRDF slot where
//! histencil's layout puts it, the engine's own bits where the engine keeps them.

use crate::device::{barrier, graphics_pipeline, Gpu, GpuMesh, PipelineSpec};
use crate::world::World;
use ash::vk;
use histencil_model::StencilLayout;
use histencil_vk::{gbuffer_stencil_reference, ImageRef, ImageState, GBUFFER_FORMATS};

pub const DEPTH_FORMAT: vk::Format = vk::Format::D32_SFLOAT_S8_UINT;

/// The engine's bits: its own two, outside histencil's.
pub const ENGINE_MASK: u8 = crate::world::WALKABLE | crate::world::DYNAMIC;

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct CameraBlock {
    pub view: [[f32; 4]; 4],
    pub proj: [[f32; 4]; 4],
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct DrawPush {
    model: [[f32; 4]; 4],
    tint_material: [f32; 4],
    brdf: [f32; 4],
}

pub struct GBufferPass {
    pub set_layout: vk::DescriptorSetLayout,
    layout: vk::PipelineLayout,
    pipeline: vk::Pipeline,
    unit_box: GpuMesh,
}

impl GBufferPass {
    pub fn new(gpu: &Gpu) -> Self {
        let d = &gpu.device;
        let binding = [vk::DescriptorSetLayoutBinding::default()
            .binding(0)
            .descriptor_type(vk::DescriptorType::UNIFORM_BUFFER)
            .descriptor_count(1)
            .stage_flags(vk::ShaderStageFlags::VERTEX)];
        let set_layout = unsafe {
            d.create_descriptor_set_layout(
                &vk::DescriptorSetLayoutCreateInfo::default().bindings(&binding),
                None,
            )
        }
        .unwrap();
        let push = [vk::PushConstantRange::default()
            .stage_flags(vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT)
            .size(std::mem::size_of::<DrawPush>() as u32)];
        let set_layouts = [set_layout];
        let layout = unsafe {
            d.create_pipeline_layout(
                &vk::PipelineLayoutCreateInfo::default()
                    .set_layouts(&set_layouts)
                    .push_constant_ranges(&push),
                None,
            )
        }
        .unwrap();
        let stencil = vk::StencilOpState::default()
            .compare_op(vk::CompareOp::ALWAYS)
            .pass_op(vk::StencilOp::REPLACE)
            .compare_mask(0xFF);
        let f32x3 = vk::Format::R32G32B32_SFLOAT;
        let blend = [vk::PipelineColorBlendAttachmentState::default()
            .color_write_mask(vk::ColorComponentFlags::RGBA); 3];
        let pipeline = graphics_pipeline(
            d,
            layout,
            &PipelineSpec {
                shaders: (
                    include_bytes!(concat!(env!("OUT_DIR"), "/gbuffer.vert.spv")),
                    include_bytes!(concat!(env!("OUT_DIR"), "/gbuffer.frag.spv")),
                ),
                // histencil_scene's vertex: position, normal, uv (32 bytes).
                vertex: (32, &[(f32x3, 0), (f32x3, 12)]),
                cull: vk::CullModeFlags::BACK,
                // Reversed Z: nearer is greater.
                depth_stencil: vk::PipelineDepthStencilStateCreateInfo::default()
                    .depth_test_enable(true)
                    .depth_write_enable(true)
                    .depth_compare_op(vk::CompareOp::GREATER)
                    .stencil_test_enable(true)
                    .front(stencil)
                    .back(stencil),
                blend: &blend,
                color_formats: &GBUFFER_FORMATS,
                dynamic: &[
                    vk::DynamicState::STENCIL_REFERENCE,
                    vk::DynamicState::STENCIL_WRITE_MASK,
                ],
            },
        );
        Self {
            set_layout,
            layout,
            pipeline,
            unit_box: gpu.mesh("box", &histencil_scene::unit_box()),
        }
    }

    /// Clears and writes the G-buffer and depth-stencil, leaving their states in the refs.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        d: &ash::Device,
        cmd: vk::CommandBuffer,
        camera_set: vk::DescriptorSet,
        world: &World,
        layout: &StencilLayout,
        gbuffer: &mut [ImageRef; 3],
        depth_stencil: &mut ImageRef,
    ) {
        let color = ImageState {
            layout: vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
            stage: vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT,
            access: vk::AccessFlags2::COLOR_ATTACHMENT_WRITE
                | vk::AccessFlags2::COLOR_ATTACHMENT_READ,
        };
        let depth = ImageState {
            layout: vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
            stage: vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS
                | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS,
            access: vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ
                | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE,
        };
        for image in gbuffer.iter_mut() {
            barrier(d, cmd, image, color, true);
        }
        barrier(d, cmd, depth_stencil, depth, true);
        let extent = depth_stencil.extent;
        let clear = |c: [f32; 4]| vk::ClearValue {
            color: vk::ClearColorValue { float32: c },
        };
        // The contract's clears: material w = -1 is "no geometry".
        let clears = [
            clear([0.0; 4]),
            clear([0.0; 4]),
            clear([0.0, 0.0, 0.0, -1.0]),
        ];
        let colors: Vec<_> = gbuffer
            .iter()
            .zip(clears)
            .map(|(g, c)| {
                vk::RenderingAttachmentInfo::default()
                    .image_view(g.view)
                    .image_layout(color.layout)
                    .load_op(vk::AttachmentLoadOp::CLEAR)
                    .store_op(vk::AttachmentStoreOp::STORE)
                    .clear_value(c)
            })
            .collect();
        let ds = vk::RenderingAttachmentInfo::default()
            .image_view(depth_stencil.view)
            .image_layout(depth.layout)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(vk::ClearValue {
                // Reversed Z: the far plane is 0.
                depth_stencil: vk::ClearDepthStencilValue {
                    depth: 0.0,
                    stencil: 0,
                },
            });
        let area = vk::Rect2D::default().extent(extent);
        let info = vk::RenderingInfo::default()
            .render_area(area)
            .layer_count(1)
            .color_attachments(&colors)
            .depth_attachment(&ds)
            .stencil_attachment(&ds);
        let viewport = vk::Viewport {
            width: extent.width as f32,
            height: extent.height as f32,
            max_depth: 1.0,
            ..Default::default()
        };
        let faces = vk::StencilFaceFlags::FRONT_AND_BACK;
        unsafe {
            d.cmd_begin_rendering(cmd, &info);
            d.cmd_set_viewport(cmd, 0, &[viewport]);
            d.cmd_set_scissor(cmd, 0, &[area]);
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.pipeline);
            d.cmd_bind_descriptor_sets(
                cmd,
                vk::PipelineBindPoint::GRAPHICS,
                self.layout,
                0,
                &[camera_set],
                &[],
            );
            for (i, object) in world.objects.iter().enumerate() {
                let (reference, mask) = gbuffer_stencil_reference(layout, world.slot(object))
                    .expect("every object's slot is in the layout");
                d.cmd_set_stencil_reference(cmd, faces, u32::from(reference | object.stencil));
                d.cmd_set_stencil_write_mask(cmd, faces, u32::from(mask | ENGINE_MASK));
                let p = object.brdf.packed_params();
                let push = DrawPush {
                    model: object.transform.to_cols_array_2d(),
                    tint_material: object.tint.extend(i as f32).to_array(),
                    brdf: [
                        p[0] as f32,
                        p[1] as f32,
                        p[2] as f32,
                        object.brdf.model_index() as f32,
                    ],
                };
                d.cmd_push_constants(
                    cmd,
                    self.layout,
                    vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                    0,
                    bytemuck::bytes_of(&push),
                );
                self.unit_box.draw(d, cmd);
            }
            d.cmd_end_rendering(cmd);
        }
    }

    pub fn destroy(self, gpu: &Gpu) {
        unsafe {
            gpu.device.destroy_pipeline(self.pipeline, None);
            gpu.device.destroy_pipeline_layout(self.layout, None);
            gpu.device
                .destroy_descriptor_set_layout(self.set_layout, None);
        }
        gpu.free_mesh(self.unit_box);
    }
}
