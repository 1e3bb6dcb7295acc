//! The engine's shadow map for its spot light, and what histencil's visibility hook
//! (`shaders/histencil_hooks/light_visibility.glsl`) reads it through: a depth-compare sampler
//! over the map and a block with the light's matrix, index and bias, at bindings 3 and 4 of
//! set 1. The light pipelines find them in the decode hook's sets ([`ShadowMap::descriptors`]),
//! the forward reference in sets of this layout's own.

use crate::device::{
    allocate_sets, barrier, begin_rendering, depth_attachment, graphics_pipeline, layout_bindings,
    set_layout, Buffer, Gpu, GpuMesh, Image, PipelineSpec,
};
use crate::world::World;
use ash::vk;
use glam::Mat4;
use gpu_allocator::MemoryLocation;
use histencil::vk::ImageState;

/// The hook's first binding in set 1: the decode hook's three images come first.
pub const FIRST_BINDING: u32 = 3;

/// The shadow map's side in texels and format.
pub const SIDE: u32 = 1024;
const FORMAT: vk::Format = vk::Format::D32_SFLOAT;
/// Depth bias in the map's depth units, and the offset along the surface normal in world units,
/// against self-shadowing on lit surfaces.
const DEPTH_BIAS: f32 = 0.0005;
const NORMAL_OFFSET: f32 = 0.02;

/// The hook's block (std140), mirrored by `Shadow` in light_visibility.glsl.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ShadowBlock {
    light_view_proj: [[f32; 4]; 4],
    light: [u32; 4],
    bias: [f32; 4],
}

impl ShadowBlock {
    /// `light`: the index of the shadowed light in the frame's lights; `None` switches the
    /// lookup off (every light unshadowed, the map not read).
    pub fn new(view_proj: Mat4, light: Option<usize>) -> Self {
        Self {
            light_view_proj: view_proj.to_cols_array_2d(),
            light: [light.map_or(u32::MAX, |l| l as u32), 0, 0, 0],
            bias: [DEPTH_BIAS, NORMAL_OFFSET, 0.0, 0.0],
        }
    }
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ShadowPush {
    model: [[f32; 4]; 4],
    light_view_proj: [[f32; 4]; 4],
}

pub struct ShadowMap {
    pub map: Image,
    sampler: vk::Sampler,
    layout: vk::PipelineLayout,
    pipeline: vk::Pipeline,
    unit_box: GpuMesh,
    /// Set 1 of the forward reference: bindings 3 and 4 alone.
    pub set_layout: vk::DescriptorSetLayout,
    /// Bindings 3 and 4 as the hook declares them, for the decode hook's layout too.
    pub bindings: Vec<vk::DescriptorSetLayoutBinding<'static>>,
    pool: vk::DescriptorPool,
    /// Per frame in flight: the block and the set.
    pub blocks: Vec<Buffer>,
    pub sets: Vec<vk::DescriptorSet>,
}

/// The state the map is in while histencil's light shaders sample it: fragment shaders, and
/// the tiled technique's compute kernels.
const SAMPLED: ImageState = ImageState {
    layout: vk::ImageLayout::DEPTH_READ_ONLY_OPTIMAL,
    stage: vk::PipelineStageFlags2::from_raw(
        vk::PipelineStageFlags2::FRAGMENT_SHADER.as_raw()
            | vk::PipelineStageFlags2::COMPUTE_SHADER.as_raw(),
    ),
    access: vk::AccessFlags2::SHADER_SAMPLED_READ,
};

impl ShadowMap {
    pub fn new(gpu: &Gpu, in_flight: usize) -> Self {
        let d = &gpu.device;
        let extent = vk::Extent2D {
            width: SIDE,
            height: SIDE,
        };
        use vk::ImageUsageFlags as U;
        let map = gpu.image(
            "shadow-map",
            FORMAT,
            extent,
            U::DEPTH_STENCIL_ATTACHMENT | U::SAMPLED,
        );
        // Comparison with linear filtering: the four nearest texels compared and blended.
        let sampler = unsafe {
            d.create_sampler(
                &vk::SamplerCreateInfo::default()
                    .mag_filter(vk::Filter::LINEAR)
                    .min_filter(vk::Filter::LINEAR)
                    .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
                    .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
                    .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE)
                    .compare_enable(true)
                    .compare_op(vk::CompareOp::LESS_OR_EQUAL),
                None,
            )
        }
        .unwrap();
        let push = [vk::PushConstantRange::default()
            .stage_flags(vk::ShaderStageFlags::VERTEX)
            .size(std::mem::size_of::<ShadowPush>() as u32)];
        let layout = unsafe {
            d.create_pipeline_layout(
                &vk::PipelineLayoutCreateInfo::default().push_constant_ranges(&push),
                None,
            )
        }
        .unwrap();
        let f32x3 = vk::Format::R32G32B32_SFLOAT;
        let pipeline = graphics_pipeline(
            d,
            layout,
            &PipelineSpec {
                shaders: (
                    include_bytes!(concat!(env!("OUT_DIR"), "/shadow.vert.spv")),
                    include_bytes!(concat!(env!("OUT_DIR"), "/shadow.frag.spv")),
                ),
                vertex: (32, &[(f32x3, 0)]),
                // Both faces: the boxes are closed, and the floor slab is thin.
                cull: vk::CullModeFlags::NONE,
                depth_stencil: vk::PipelineDepthStencilStateCreateInfo::default()
                    .depth_test_enable(true)
                    .depth_write_enable(true)
                    .depth_compare_op(vk::CompareOp::LESS),
                blend: &[],
                color_formats: &[],
                depth_format: FORMAT,
                depth_bias: Some((1.0, 1.5)),
                dynamic: &[],
            },
        );
        // The tiled technique's kernels read it too.
        let stage = vk::ShaderStageFlags::FRAGMENT | vk::ShaderStageFlags::COMPUTE;
        let types = [
            vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
            vk::DescriptorType::UNIFORM_BUFFER,
        ];
        let bindings: Vec<_> = layout_bindings(&[(types[0], stage), (types[1], stage)])
            .into_iter()
            .zip(FIRST_BINDING..)
            .map(|(b, n)| b.binding(n))
            .collect();
        let set_layout = set_layout(d, &bindings);
        let (pool, sets) = allocate_sets(d, set_layout, in_flight, &types);
        let blocks: Vec<Buffer> = (0..in_flight)
            .map(|i| {
                gpu.buffer(
                    &format!("shadow-block-{i}"),
                    std::mem::size_of::<ShadowBlock>() as u64,
                    vk::BufferUsageFlags::UNIFORM_BUFFER,
                    MemoryLocation::CpuToGpu,
                )
            })
            .collect();
        let shadow = Self {
            map,
            sampler,
            layout,
            pipeline,
            unit_box: gpu.mesh("shadow-box", &histencil::scene::unit_box()),
            set_layout,
            bindings,
            pool,
            blocks,
            sets,
        };
        for (slot, set) in shadow.sets.clone().into_iter().enumerate() {
            shadow.write_descriptors(d, set, slot);
        }
        shadow
    }

    /// Writes the map and slot `slot`'s block into bindings 3 and 4 of `set`: one of this
    /// layout's sets, or a decode hook set that holds the same bindings.
    pub fn write_descriptors(&self, d: &ash::Device, set: vk::DescriptorSet, slot: usize) {
        let image = [vk::DescriptorImageInfo::default()
            .sampler(self.sampler)
            .image_view(self.map.target.view)
            .image_layout(SAMPLED.layout)];
        let buffer = [vk::DescriptorBufferInfo::default()
            .buffer(self.blocks[slot].buffer)
            .range(vk::WHOLE_SIZE)];
        let writes = [
            vk::WriteDescriptorSet::default()
                .dst_set(set)
                .dst_binding(FIRST_BINDING)
                .descriptor_type(vk::DescriptorType::COMBINED_IMAGE_SAMPLER)
                .image_info(&image),
            vk::WriteDescriptorSet::default()
                .dst_set(set)
                .dst_binding(FIRST_BINDING + 1)
                .descriptor_type(vk::DescriptorType::UNIFORM_BUFFER)
                .buffer_info(&buffer),
        ];
        unsafe { d.update_descriptor_sets(&writes, &[]) };
    }

    /// Renders the world's depth from `view_proj` and leaves the map ready for fragment
    /// shaders to sample; writes slot `slot`'s block with `block`.
    pub fn record(
        &mut self,
        d: &ash::Device,
        cmd: vk::CommandBuffer,
        slot: usize,
        world: &World,
        view_proj: Mat4,
        block: ShadowBlock,
    ) {
        self.blocks[slot].write(bytemuck::bytes_of(&block));
        let target = &mut self.map.target;
        let attachment = ImageState {
            layout: vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL,
            stage: vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS
                | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS,
            access: vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ
                | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE,
        };
        barrier(d, cmd, target, attachment, true);
        let ds = depth_attachment(target.view, attachment.layout, 1.0, true);
        unsafe {
            begin_rendering(d, cmd, target.extent, &[], &ds, false);
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.pipeline);
            for object in &world.objects {
                let push = ShadowPush {
                    model: object.transform.to_cols_array_2d(),
                    light_view_proj: view_proj.to_cols_array_2d(),
                };
                d.cmd_push_constants(
                    cmd,
                    self.layout,
                    vk::ShaderStageFlags::VERTEX,
                    0,
                    bytemuck::bytes_of(&push),
                );
                self.unit_box.draw(d, cmd);
            }
            d.cmd_end_rendering(cmd);
        }
        barrier(d, cmd, target, SAMPLED, false);
    }

    pub fn destroy(self, gpu: &Gpu) {
        let d = &gpu.device;
        unsafe {
            d.destroy_pipeline(self.pipeline, None);
            d.destroy_pipeline_layout(self.layout, None);
            d.destroy_descriptor_pool(self.pool, None);
            d.destroy_descriptor_set_layout(self.set_layout, None);
            d.destroy_sampler(self.sampler, None);
        }
        for b in self.blocks {
            gpu.free_buffer(b);
        }
        gpu.free_mesh(self.unit_box);
        gpu.free_image(self.map);
    }
}
