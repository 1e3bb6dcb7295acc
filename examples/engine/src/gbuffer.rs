//! The engine's G-buffer pass: its own shaders (writing histencil's contract through
//! `gbuffer_write.glsl`), reversed-Z depth, and each draw's stencil: the BRDF slot where
//! histencil's layout puts it, the engine's own bits where the engine keeps them.

use crate::device::{barrier, Buffer, Gpu};
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

fn spirv(bytes: &[u8]) -> Vec<u32> {
    ash::util::read_spv(&mut std::io::Cursor::new(bytes)).expect("SPIR-V")
}

pub struct GBufferPass {
    pub set_layout: vk::DescriptorSetLayout,
    layout: vk::PipelineLayout,
    pipeline: vk::Pipeline,
    box_vertices: Buffer,
    box_indices: Buffer,
    index_count: u32,
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
        let module = |bytes: &[u8]| {
            let code = spirv(bytes);
            unsafe {
                d.create_shader_module(&vk::ShaderModuleCreateInfo::default().code(&code), None)
            }
            .unwrap()
        };
        let vert = module(include_bytes!(concat!(
            env!("OUT_DIR"),
            "/gbuffer.vert.spv"
        )));
        let frag = module(include_bytes!(concat!(
            env!("OUT_DIR"),
            "/gbuffer.frag.spv"
        )));
        let stages = [
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::VERTEX)
                .module(vert)
                .name(c"main"),
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::FRAGMENT)
                .module(frag)
                .name(c"main"),
        ];
        // histencil_scene's vertex: position, normal, uv (32 bytes).
        let bindings = [vk::VertexInputBindingDescription::default().stride(32)];
        let attributes = [
            vk::VertexInputAttributeDescription::default()
                .location(0)
                .format(vk::Format::R32G32B32_SFLOAT),
            vk::VertexInputAttributeDescription::default()
                .location(1)
                .format(vk::Format::R32G32B32_SFLOAT)
                .offset(12),
        ];
        let vertex_input = vk::PipelineVertexInputStateCreateInfo::default()
            .vertex_binding_descriptions(&bindings)
            .vertex_attribute_descriptions(&attributes);
        let assembly = vk::PipelineInputAssemblyStateCreateInfo::default()
            .topology(vk::PrimitiveTopology::TRIANGLE_LIST);
        let viewport = vk::PipelineViewportStateCreateInfo::default()
            .viewport_count(1)
            .scissor_count(1);
        let raster = vk::PipelineRasterizationStateCreateInfo::default()
            .cull_mode(vk::CullModeFlags::BACK)
            .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
            .line_width(1.0);
        let multisample = vk::PipelineMultisampleStateCreateInfo::default()
            .rasterization_samples(vk::SampleCountFlags::TYPE_1);
        let stencil = vk::StencilOpState::default()
            .compare_op(vk::CompareOp::ALWAYS)
            .pass_op(vk::StencilOp::REPLACE)
            .compare_mask(0xFF);
        // Reversed Z: nearer is greater.
        let depth = vk::PipelineDepthStencilStateCreateInfo::default()
            .depth_test_enable(true)
            .depth_write_enable(true)
            .depth_compare_op(vk::CompareOp::GREATER)
            .stencil_test_enable(true)
            .front(stencil)
            .back(stencil);
        let blend = [vk::PipelineColorBlendAttachmentState::default()
            .color_write_mask(vk::ColorComponentFlags::RGBA); 3];
        let blend = vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend);
        let dynamic = [
            vk::DynamicState::VIEWPORT,
            vk::DynamicState::SCISSOR,
            vk::DynamicState::STENCIL_REFERENCE,
            vk::DynamicState::STENCIL_WRITE_MASK,
        ];
        let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic);
        let mut rendering = vk::PipelineRenderingCreateInfo::default()
            .color_attachment_formats(&GBUFFER_FORMATS)
            .depth_attachment_format(DEPTH_FORMAT)
            .stencil_attachment_format(DEPTH_FORMAT);
        let info = vk::GraphicsPipelineCreateInfo::default()
            .stages(&stages)
            .vertex_input_state(&vertex_input)
            .input_assembly_state(&assembly)
            .viewport_state(&viewport)
            .rasterization_state(&raster)
            .multisample_state(&multisample)
            .depth_stencil_state(&depth)
            .color_blend_state(&blend)
            .dynamic_state(&dynamic)
            .layout(layout)
            .push_next(&mut rendering);
        let pipeline =
            unsafe { d.create_graphics_pipelines(vk::PipelineCache::null(), &[info], None) }
                .map_err(|(_, e)| e)
                .unwrap()[0];
        unsafe {
            d.destroy_shader_module(vert, None);
            d.destroy_shader_module(frag, None);
        }
        let mesh = histencil_scene::unit_box();
        let vertex_bytes: Vec<u8> = mesh
            .vertices
            .iter()
            .flat_map(|v| {
                bytemuck::cast_slice::<f32, u8>(&[v.position, v.normal].concat())
                    .to_vec()
                    .into_iter()
                    .chain(bytemuck::cast_slice::<f32, u8>(&v.uv).to_vec())
            })
            .collect();
        let index_bytes: &[u8] = bytemuck::cast_slice(&mesh.indices);
        let upload = |name, bytes: &[u8], usage| {
            let mut b = gpu.buffer(
                name,
                bytes.len() as u64,
                usage,
                gpu_allocator::MemoryLocation::CpuToGpu,
            );
            b.write(bytes);
            b
        };
        Self {
            set_layout,
            layout,
            pipeline,
            box_vertices: upload(
                "box-vertices",
                &vertex_bytes,
                vk::BufferUsageFlags::VERTEX_BUFFER,
            ),
            box_indices: upload(
                "box-indices",
                index_bytes,
                vk::BufferUsageFlags::INDEX_BUFFER,
            ),
            index_count: mesh.indices.len() as u32,
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
            d.cmd_bind_vertex_buffers(cmd, 0, &[self.box_vertices.buffer], &[0]);
            d.cmd_bind_index_buffer(cmd, self.box_indices.buffer, 0, vk::IndexType::UINT32);
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
                d.cmd_draw_indexed(cmd, self.index_count, 1, 0, 0, 0);
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
        gpu.free_buffer(self.box_vertices);
        gpu.free_buffer(self.box_indices);
    }
}
