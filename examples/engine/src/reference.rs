//! The engine's forward reference for its lighting with shadows: the world drawn once with every
//! light at every pixel through histencil's own shading (`light.glsl`), the same round trip
//! through the compact G-buffer's formats and the same shadow lookup as the deferred path
//! (`shaders/forward.frag`). histencil's own forward renderer knows neither the engine's
//! G-buffer nor its shadows, so the engine holds its deferred lighting to this.

use crate::device::{
    allocate_sets, barrier, begin_rendering, depth_attachment, graphics_pipeline, layout_bindings,
    set_layout, Buffer, Gpu, GpuMesh, Image, PipelineSpec,
};
use crate::gbuffer::{DrawPush, DEPTH_FORMAT};
use crate::world::World;
use ash::vk;
use gpu_allocator::MemoryLocation;
use histencil::scene::Light;
use histencil::vk::gpu_types::{FrameUniforms, GpuLight};
use histencil::vk::{ImageRef, ImageState};

pub struct ForwardReference {
    frame_layout: vk::DescriptorSetLayout,
    layout: vk::PipelineLayout,
    pipeline: vk::Pipeline,
    pool: vk::DescriptorPool,
    set: vk::DescriptorSet,
    uniforms: Buffer,
    lights: Buffer,
    depth: Image,
    pub hdr: Image,
    unit_box: GpuMesh,
}

impl ForwardReference {
    /// `shadow_layout`: the visibility hook's bindings alone, as set 1; `max_lights` lights a
    /// frame.
    pub fn new(
        gpu: &Gpu,
        extent: vk::Extent2D,
        hdr_format: vk::Format,
        shadow_layout: vk::DescriptorSetLayout,
        max_lights: usize,
    ) -> Self {
        let d = &gpu.device;
        let both = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT;
        let frame_layout = set_layout(
            d,
            &layout_bindings(&[
                (vk::DescriptorType::UNIFORM_BUFFER, both),
                (
                    vk::DescriptorType::STORAGE_BUFFER,
                    vk::ShaderStageFlags::FRAGMENT,
                ),
            ]),
        );
        let push = [vk::PushConstantRange::default()
            .stage_flags(both)
            .size(std::mem::size_of::<DrawPush>() as u32)];
        let sets = [frame_layout, shadow_layout];
        let layout = unsafe {
            d.create_pipeline_layout(
                &vk::PipelineLayoutCreateInfo::default()
                    .set_layouts(&sets)
                    .push_constant_ranges(&push),
                None,
            )
        }
        .unwrap();
        let f32x3 = vk::Format::R32G32B32_SFLOAT;
        let blend = [vk::PipelineColorBlendAttachmentState::default()
            .color_write_mask(vk::ColorComponentFlags::RGBA)];
        let pipeline = graphics_pipeline(
            d,
            layout,
            &PipelineSpec {
                shaders: (
                    include_bytes!(concat!(env!("OUT_DIR"), "/forward.vert.spv")),
                    include_bytes!(concat!(env!("OUT_DIR"), "/forward.frag.spv")),
                ),
                vertex: (32, &[(f32x3, 0), (f32x3, 12)]),
                cull: vk::CullModeFlags::BACK,
                depth_stencil: vk::PipelineDepthStencilStateCreateInfo::default()
                    .depth_test_enable(true)
                    .depth_write_enable(true)
                    .depth_compare_op(vk::CompareOp::GREATER),
                blend: &blend,
                color_formats: &[hdr_format],
                depth_format: DEPTH_FORMAT,
                depth_bias: None,
                dynamic: &[],
            },
        );
        let types = [
            vk::DescriptorType::UNIFORM_BUFFER,
            vk::DescriptorType::STORAGE_BUFFER,
        ];
        let (pool, sets) = allocate_sets(d, frame_layout, 1, &types);
        let set = sets[0];
        let uniforms = gpu.buffer(
            "reference-frame",
            std::mem::size_of::<FrameUniforms>() as u64,
            vk::BufferUsageFlags::UNIFORM_BUFFER,
            MemoryLocation::CpuToGpu,
        );
        let lights = gpu.buffer(
            "reference-lights",
            (max_lights * std::mem::size_of::<GpuLight>()) as u64,
            vk::BufferUsageFlags::STORAGE_BUFFER,
            MemoryLocation::CpuToGpu,
        );
        let ubo = [vk::DescriptorBufferInfo::default()
            .buffer(uniforms.buffer)
            .range(vk::WHOLE_SIZE)];
        let ssbo = [vk::DescriptorBufferInfo::default()
            .buffer(lights.buffer)
            .range(vk::WHOLE_SIZE)];
        let writes = [
            vk::WriteDescriptorSet::default()
                .dst_set(set)
                .dst_binding(0)
                .descriptor_type(vk::DescriptorType::UNIFORM_BUFFER)
                .buffer_info(&ubo),
            vk::WriteDescriptorSet::default()
                .dst_set(set)
                .dst_binding(1)
                .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                .buffer_info(&ssbo),
        ];
        unsafe { d.update_descriptor_sets(&writes, &[]) };
        use vk::ImageUsageFlags as U;
        let depth = gpu.image(
            "reference-depth",
            DEPTH_FORMAT,
            extent,
            U::DEPTH_STENCIL_ATTACHMENT,
        );
        let hdr = gpu.image(
            "reference-hdr",
            hdr_format,
            extent,
            U::COLOR_ATTACHMENT | U::TRANSFER_SRC,
        );
        Self {
            frame_layout,
            layout,
            pipeline,
            pool,
            set,
            uniforms,
            lights,
            depth,
            hdr,
            unit_box: gpu.mesh("reference-box", &histencil::scene::unit_box()),
        }
    }

    /// Draws `world` lit by `lights` seen through `frame` into [`ForwardReference::hdr`], with
    /// `shadow_set` (a set of the shadow map's own layout whose map is ready to sample) at set 1.
    /// Used once per
    /// captured frame: its buffers are written now, so the GPU must have finished its last use.
    pub fn record(
        &mut self,
        d: &ash::Device,
        cmd: vk::CommandBuffer,
        world: &World,
        frame: &FrameUniforms,
        lights: &[Light],
        shadow_set: vk::DescriptorSet,
    ) {
        self.uniforms.write(bytemuck::bytes_of(frame));
        let gpu_lights: Vec<GpuLight> = lights.iter().map(GpuLight::new).collect();
        self.lights.write(bytemuck::cast_slice(&gpu_lights));
        let color = ImageState {
            layout: vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
            stage: vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT,
            access: vk::AccessFlags2::COLOR_ATTACHMENT_WRITE,
        };
        let depth = ImageState {
            layout: vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
            stage: vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS
                | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS,
            access: vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ
                | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE,
        };
        barrier(d, cmd, &mut self.hdr.target, color, true);
        barrier(d, cmd, &mut self.depth.target, depth, true);
        let hdr: &ImageRef = &self.hdr.target;
        let colors = [vk::RenderingAttachmentInfo::default()
            .image_view(hdr.view)
            .image_layout(color.layout)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(vk::ClearValue {
                color: vk::ClearColorValue { float32: [0.0; 4] },
            })];
        // Reversed Z: the far plane is 0.
        let ds = depth_attachment(self.depth.target.view, depth.layout, 0.0, false);
        let both = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT;
        unsafe {
            begin_rendering(d, cmd, hdr.extent, &colors, &ds, false);
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.pipeline);
            let bind = |first: u32, set: vk::DescriptorSet| {
                d.cmd_bind_descriptor_sets(
                    cmd,
                    vk::PipelineBindPoint::GRAPHICS,
                    self.layout,
                    first,
                    &[set],
                    &[],
                )
            };
            bind(0, self.set);
            bind(1, shadow_set);
            for (i, object) in world.objects.iter().enumerate() {
                let push = DrawPush::new(object, i);
                d.cmd_push_constants(cmd, self.layout, both, 0, bytemuck::bytes_of(&push));
                self.unit_box.draw(d, cmd);
            }
            d.cmd_end_rendering(cmd);
        }
    }

    pub fn destroy(self, gpu: &Gpu) {
        let d = &gpu.device;
        unsafe {
            d.destroy_pipeline(self.pipeline, None);
            d.destroy_pipeline_layout(self.layout, None);
            d.destroy_descriptor_pool(self.pool, None);
            d.destroy_descriptor_set_layout(self.frame_layout, None);
        }
        gpu.free_buffer(self.uniforms);
        gpu.free_buffer(self.lights);
        gpu.free_image(self.depth);
        gpu.free_image(self.hdr);
        gpu.free_mesh(self.unit_box);
    }
}
