//! The engine's alpha pass: its glass sphere and smoke drawn by its own shaders over the lit HDR
//! image, far to near, each lit from its region of the lightmap atlas that histencil's
//! `AlphaLightmaps` lit earlier in the same command buffer. The engine binds the records
//! (`AlphaLightmaps::entity_buffer`) and the atlas in a set of its own.

use crate::device::{barrier, graphics_pipeline, Buffer, Gpu, GpuMesh, PipelineSpec};
use crate::world::AlphaWorld;
use ash::vk;
use gpu_allocator::MemoryLocation;
use histencil::alpha::SpriteVertex;
use histencil::vk::{ImageRef, ImageState};

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct DrawPush {
    model: [[f32; 4]; 4],
    entity: u32,
    pad: [u32; 3],
}

/// The most sprite vertices a frame draws (6 per particle).
const MAX_SPRITE_VERTICES: u64 = 6 * 256;

pub const SAMPLED: ImageState = ImageState {
    layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
    stage: vk::PipelineStageFlags2::FRAGMENT_SHADER,
    access: vk::AccessFlags2::SHADER_READ,
};

pub struct AlphaPass {
    pub set_layout: vk::DescriptorSetLayout,
    /// How the alpha shaders read the atlas: bilinear, clamp to edge (lightmap_sample.glsl).
    sampler: vk::Sampler,
    layout: vk::PipelineLayout,
    object_pipeline: vk::Pipeline,
    particle_pipeline: vk::Pipeline,
    sphere: GpuMesh,
    /// Per frame in flight: the sprites it draws.
    sprites: Vec<Buffer>,
}

impl AlphaPass {
    pub fn new(gpu: &Gpu, camera_layout: vk::DescriptorSetLayout, in_flight: usize) -> Self {
        let d = &gpu.device;
        let fragment = vk::ShaderStageFlags::FRAGMENT;
        let both = vk::ShaderStageFlags::VERTEX | fragment;
        let bindings = [
            vk::DescriptorSetLayoutBinding::default()
                .binding(0)
                .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                .descriptor_count(1)
                .stage_flags(both),
            vk::DescriptorSetLayoutBinding::default()
                .binding(1)
                .descriptor_type(vk::DescriptorType::SAMPLED_IMAGE)
                .descriptor_count(1)
                .stage_flags(fragment),
            vk::DescriptorSetLayoutBinding::default()
                .binding(2)
                .descriptor_type(vk::DescriptorType::SAMPLER)
                .descriptor_count(1)
                .stage_flags(fragment),
        ];
        let set_layout = unsafe {
            d.create_descriptor_set_layout(
                &vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings),
                None,
            )
        }
        .unwrap();
        let push = [vk::PushConstantRange::default()
            .stage_flags(vk::ShaderStageFlags::VERTEX | fragment)
            .size(std::mem::size_of::<DrawPush>() as u32)];
        let set_layouts = [camera_layout, set_layout];
        let layout = unsafe {
            d.create_pipeline_layout(
                &vk::PipelineLayoutCreateInfo::default()
                    .set_layouts(&set_layouts)
                    .push_constant_ranges(&push),
                None,
            )
        }
        .unwrap();
        let f32x3 = vk::Format::R32G32B32_SFLOAT;
        let f32x2 = vk::Format::R32G32_SFLOAT;
        // histencil_scene's vertex: position, normal, uv (32 bytes); lit from the lightmap, the
        // object needs no normal.
        let object_pipeline = blended_pipeline(
            d,
            layout,
            (
                include_bytes!(concat!(env!("OUT_DIR"), "/alpha_object.vert.spv")),
                include_bytes!(concat!(env!("OUT_DIR"), "/alpha_object.frag.spv")),
            ),
            (32, &[(f32x3, 0), (f32x2, 24)]),
            vk::CullModeFlags::BACK,
        );
        let particle_pipeline = blended_pipeline(
            d,
            layout,
            (
                include_bytes!(concat!(env!("OUT_DIR"), "/particle.vert.spv")),
                include_bytes!(concat!(env!("OUT_DIR"), "/particle.frag.spv")),
            ),
            (
                std::mem::size_of::<SpriteVertex>() as u32,
                &[
                    (f32x3, 0),
                    (f32x2, 12),
                    (vk::Format::R32_UINT, 20),
                    (vk::Format::R32_SFLOAT, 24),
                ],
            ),
            vk::CullModeFlags::NONE,
        );
        let sprites = (0..in_flight)
            .map(|i| {
                gpu.buffer(
                    &format!("sprites-{i}"),
                    MAX_SPRITE_VERTICES * std::mem::size_of::<SpriteVertex>() as u64,
                    vk::BufferUsageFlags::VERTEX_BUFFER,
                    MemoryLocation::CpuToGpu,
                )
            })
            .collect();
        let info = vk::SamplerCreateInfo::default()
            .mag_filter(vk::Filter::LINEAR)
            .min_filter(vk::Filter::LINEAR)
            .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE);
        let sampler = unsafe { d.create_sampler(&info, None) }.unwrap();
        Self {
            set_layout,
            sampler,
            layout,
            object_pipeline,
            particle_pipeline,
            sphere: gpu.mesh("sphere", &crate::world::sphere_mesh()),
            sprites,
        }
    }

    /// Points the frame's set at histencil's entity records for the slot and at the atlas.
    pub fn write_set(
        &self,
        d: &ash::Device,
        set: vk::DescriptorSet,
        records: vk::Buffer,
        atlas: vk::ImageView,
    ) {
        let buffer = [vk::DescriptorBufferInfo::default()
            .buffer(records)
            .range(vk::WHOLE_SIZE)];
        let image = [vk::DescriptorImageInfo::default()
            .image_view(atlas)
            .image_layout(SAMPLED.layout)];
        let sampler = [vk::DescriptorImageInfo::default().sampler(self.sampler)];
        let writes = [
            vk::WriteDescriptorSet::default()
                .dst_set(set)
                .dst_binding(0)
                .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                .buffer_info(&buffer),
            vk::WriteDescriptorSet::default()
                .dst_set(set)
                .dst_binding(1)
                .descriptor_type(vk::DescriptorType::SAMPLED_IMAGE)
                .image_info(&image),
            vk::WriteDescriptorSet::default()
                .dst_set(set)
                .dst_binding(2)
                .descriptor_type(vk::DescriptorType::SAMPLER)
                .image_info(&sampler),
        ];
        unsafe { d.update_descriptor_sets(&writes, &[]) };
    }

    /// Blends the sphere (entity 0) and the smoke (entity 1) far to near over `hdr`, tested
    /// against the engine's reversed-Z depth, after taking the atlas to a shader read.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &mut self,
        d: &ash::Device,
        cmd: vk::CommandBuffer,
        slot: usize,
        sets: [vk::DescriptorSet; 2],
        alpha: &AlphaWorld,
        atlas: &mut ImageRef,
        (hdr, depth): (&mut ImageRef, &mut ImageRef),
    ) {
        let sprites: Vec<SpriteVertex> =
            histencil::alpha::sprite_vertices(&alpha.camera, &alpha.smoke, 1);
        assert!(sprites.len() as u64 <= MAX_SPRITE_VERTICES);
        self.sprites[slot].write(bytemuck::cast_slice(&sprites));
        barrier(d, cmd, atlas, SAMPLED, false);
        let color = ImageState {
            layout: vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
            stage: vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT,
            access: vk::AccessFlags2::COLOR_ATTACHMENT_READ
                | vk::AccessFlags2::COLOR_ATTACHMENT_WRITE,
        };
        let tested = ImageState {
            layout: vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL,
            stage: vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS
                | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS,
            access: vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ,
        };
        barrier(d, cmd, hdr, color, false);
        barrier(d, cmd, depth, tested, false);
        let colors = [vk::RenderingAttachmentInfo::default()
            .image_view(hdr.view)
            .image_layout(color.layout)
            .load_op(vk::AttachmentLoadOp::LOAD)
            .store_op(vk::AttachmentStoreOp::STORE)];
        let ds = vk::RenderingAttachmentInfo::default()
            .image_view(depth.view)
            .image_layout(tested.layout)
            .load_op(vk::AttachmentLoadOp::LOAD)
            .store_op(vk::AttachmentStoreOp::NONE);
        let area = vk::Rect2D::default().extent(hdr.extent);
        let info = vk::RenderingInfo::default()
            .render_area(area)
            .layer_count(1)
            .color_attachments(&colors)
            .depth_attachment(&ds)
            .stencil_attachment(&ds);
        let viewport = vk::Viewport {
            width: area.extent.width as f32,
            height: area.extent.height as f32,
            max_depth: 1.0,
            ..Default::default()
        };
        let stages = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT;
        unsafe {
            d.cmd_begin_rendering(cmd, &info);
            d.cmd_set_viewport(cmd, 0, &[viewport]);
            d.cmd_set_scissor(cmd, 0, &[area]);
            d.cmd_bind_descriptor_sets(
                cmd,
                vk::PipelineBindPoint::GRAPHICS,
                self.layout,
                0,
                &sets,
                &[],
            );
            for entity in alpha.back_to_front() {
                if entity == 0 {
                    d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.object_pipeline);
                    let push = DrawPush {
                        model: alpha.glass_transform.to_cols_array_2d(),
                        entity: 0,
                        pad: [0; 3],
                    };
                    d.cmd_push_constants(cmd, self.layout, stages, 0, bytemuck::bytes_of(&push));
                    self.sphere.draw(d, cmd);
                } else {
                    d.cmd_bind_pipeline(
                        cmd,
                        vk::PipelineBindPoint::GRAPHICS,
                        self.particle_pipeline,
                    );
                    let push = DrawPush {
                        model: glam::Mat4::IDENTITY.to_cols_array_2d(),
                        entity: 1,
                        pad: [0; 3],
                    };
                    d.cmd_push_constants(cmd, self.layout, stages, 0, bytemuck::bytes_of(&push));
                    d.cmd_bind_vertex_buffers(cmd, 0, &[self.sprites[slot].buffer], &[0]);
                    d.cmd_draw(cmd, sprites.len() as u32, 1, 0, 0);
                }
            }
            d.cmd_end_rendering(cmd);
        }
    }

    pub fn destroy(self, gpu: &Gpu) {
        unsafe {
            gpu.device.destroy_pipeline(self.object_pipeline, None);
            gpu.device.destroy_pipeline(self.particle_pipeline, None);
            gpu.device.destroy_pipeline_layout(self.layout, None);
            gpu.device.destroy_sampler(self.sampler, None);
            gpu.device
                .destroy_descriptor_set_layout(self.set_layout, None);
        }
        gpu.free_mesh(self.sphere);
        for b in self.sprites {
            gpu.free_buffer(b);
        }
    }
}

/// A blended pipeline over the HDR target: premultiplied "over", depth tested (reversed Z:
/// nearer or equal passes), not written.
fn blended_pipeline(
    d: &ash::Device,
    layout: vk::PipelineLayout,
    shaders: (&[u8], &[u8]),
    vertex: (u32, &[(vk::Format, u32)]),
    cull: vk::CullModeFlags,
) -> vk::Pipeline {
    let over = vk::BlendFactor::ONE_MINUS_SRC_ALPHA;
    let blend = [vk::PipelineColorBlendAttachmentState::default()
        .blend_enable(true)
        .src_color_blend_factor(vk::BlendFactor::ONE)
        .dst_color_blend_factor(over)
        .color_blend_op(vk::BlendOp::ADD)
        .src_alpha_blend_factor(vk::BlendFactor::ONE)
        .dst_alpha_blend_factor(over)
        .alpha_blend_op(vk::BlendOp::ADD)
        .color_write_mask(vk::ColorComponentFlags::RGBA)];
    graphics_pipeline(
        d,
        layout,
        &PipelineSpec {
            shaders,
            vertex,
            cull,
            depth_stencil: vk::PipelineDepthStencilStateCreateInfo::default()
                .depth_test_enable(true)
                .depth_write_enable(false)
                .depth_compare_op(vk::CompareOp::GREATER_OR_EQUAL),
            blend: &blend,
            color_formats: &[vk::Format::R16G16B16A16_SFLOAT],
            depth_format: crate::gbuffer::DEPTH_FORMAT,
            depth_bias: None,
            dynamic: &[],
        },
    )
}
