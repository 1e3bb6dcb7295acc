//! The engine's G-buffer pass: its own shaders, writing either its own compact layout
//! (`shaders/histencil_hooks/compact_gbuffer.glsl`, which histencil's light shaders read through
//! the engine's decode hook) or histencil's contract (`gbuffer_write.glsl`); reversed-Z depth,
//! and each draw's stencil: the BRDF slot where histencil's layout puts it, the engine's own bits
//! where the engine keeps them.

use crate::device::{
    allocate_sets, barrier, begin_rendering, depth_attachment, graphics_pipeline, layout_bindings,
    set_layout, Gpu, GpuMesh, PipelineSpec,
};
use crate::world::World;
use ash::vk;
use histencil::vk::{ImageRef, ImageState, LightingDesc, GBUFFER_FORMATS};

pub const DEPTH_FORMAT: vk::Format = vk::Format::D32_SFLOAT_S8_UINT;

/// The engine's bits: its own two, outside histencil's.
pub const ENGINE_MASK: u8 = crate::world::WALKABLE | crate::world::DYNAMIC;

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct CameraBlock {
    pub view: [[f32; 4]; 4],
    pub proj: [[f32; 4]; 4],
}

/// A draw's push constants (`Draw` in gbuffer.vert, gbuffer*.frag and forward.frag).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct DrawPush {
    model: [[f32; 4]; 4],
    tint_material: [f32; 4],
    brdf: [f32; 4],
}

impl DrawPush {
    /// Object `index` of the world: its transform, tint and material index, packed BRDF
    /// parameters and model id.
    pub fn new(object: &crate::world::Object, index: usize) -> Self {
        let p = object.brdf.packed_params();
        Self {
            model: object.transform.to_cols_array_2d(),
            tint_material: object.tint.extend(index as f32).to_array(),
            brdf: [
                p[0] as f32,
                p[1] as f32,
                p[2] as f32,
                object.brdf.model_index() as f32,
            ],
        }
    }
}

/// Which G-buffer layout a pass writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GBufferKind {
    /// The engine's own: two targets, 12 bytes per pixel, depth from the depth attachment.
    Compact,
    /// histencil's contract: three targets, 40 bytes per pixel.
    Histencil,
}

/// The compact layout's targets (compact_gbuffer.glsl).
pub const COMPACT_FORMATS: [vk::Format; 2] =
    [vk::Format::R8G8B8A8_UNORM, vk::Format::R16G16B16A16_UNORM];

impl GBufferKind {
    pub fn formats(self) -> &'static [vk::Format] {
        match self {
            GBufferKind::Compact => &COMPACT_FORMATS,
            GBufferKind::Histencil => &GBUFFER_FORMATS,
        }
    }

    /// Bytes per pixel of the colour targets (the depth-stencil is the same for both).
    pub fn bytes_per_pixel(self) -> u32 {
        self.formats()
            .iter()
            .map(|f| match *f {
                vk::Format::R8G8B8A8_UNORM => 4,
                vk::Format::R16G16B16A16_UNORM | vk::Format::R16G16B16A16_SFLOAT => 8,
                vk::Format::R32G32B32A32_SFLOAT => 16,
                other => panic!("no size for {other:?}"),
            })
            .sum()
    }
}

pub struct GBufferPass {
    pub kind: GBufferKind,
    pub set_layout: vk::DescriptorSetLayout,
    layout: vk::PipelineLayout,
    pipeline: vk::Pipeline,
    unit_box: GpuMesh,
}

impl GBufferPass {
    pub fn new(gpu: &Gpu, kind: GBufferKind) -> Self {
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
        let blend = vec![
            vk::PipelineColorBlendAttachmentState::default()
                .color_write_mask(vk::ColorComponentFlags::RGBA);
            kind.formats().len()
        ];
        let (vertex, fragment): (&[u8], &[u8]) = match kind {
            GBufferKind::Compact => (
                include_bytes!(concat!(env!("OUT_DIR"), "/gbuffer_compact.vert.spv")),
                include_bytes!(concat!(env!("OUT_DIR"), "/gbuffer_compact.frag.spv")),
            ),
            GBufferKind::Histencil => (
                include_bytes!(concat!(env!("OUT_DIR"), "/gbuffer.vert.spv")),
                include_bytes!(concat!(env!("OUT_DIR"), "/gbuffer.frag.spv")),
            ),
        };
        let pipeline = graphics_pipeline(
            d,
            layout,
            &PipelineSpec {
                shaders: (vertex, fragment),
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
                color_formats: kind.formats(),
                depth_format: DEPTH_FORMAT,
                depth_bias: None,
                dynamic: &[
                    vk::DynamicState::STENCIL_REFERENCE,
                    vk::DynamicState::STENCIL_WRITE_MASK,
                ],
            },
        );
        Self {
            kind,
            set_layout,
            layout,
            pipeline,
            unit_box: gpu.mesh("box", &histencil::scene::unit_box()),
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
        lighting: &LightingDesc,
        gbuffer: &mut [ImageRef],
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
        // histencil's contract: material w = -1 is "no geometry"; the compact layout marks it
        // by the far plane's depth.
        let clears = match self.kind {
            GBufferKind::Histencil => vec![
                clear([0.0; 4]),
                clear([0.0; 4]),
                clear([0.0, 0.0, 0.0, -1.0]),
            ],
            GBufferKind::Compact => vec![clear([0.0; 4]); 2],
        };
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
        // Reversed Z: the far plane is 0.
        let ds = depth_attachment(depth_stencil.view, depth.layout, 0.0, true);
        let faces = vk::StencilFaceFlags::FRONT_AND_BACK;
        unsafe {
            begin_rendering(d, cmd, extent, &colors, &ds, true);
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
                // By BRDF id, as the decode hook names it: histencil gives the slot.
                let (reference, mask) = lighting
                    .stencil_reference(object.brdf.id())
                    .expect("every object's BRDF is the lighting's");
                d.cmd_set_stencil_reference(cmd, faces, u32::from(reference | object.stencil));
                d.cmd_set_stencil_write_mask(cmd, faces, u32::from(mask | ENGINE_MASK));
                let push = DrawPush::new(object, i);
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

/// The engine's decode hook's descriptor sets: its two compact targets and the depth aspect of
/// its depth-stencil image, one set per frame in flight (the images are the same every frame).
pub struct CompactDecode {
    pub set_layout: vk::DescriptorSetLayout,
    /// What `set_layout` was made from, for histencil's check of the decode hook.
    pub bindings: Vec<vk::DescriptorSetLayoutBinding<'static>>,
    pool: vk::DescriptorPool,
    pub sets: Vec<vk::DescriptorSet>,
}

impl CompactDecode {
    /// `depth_view` is a depth-aspect view of the depth-stencil image. The visibility hook's
    /// shadow bindings join the decode's in one layout (set 1), and `shadow` writes them into
    /// each slot's set: the light pipelines then need four sets.
    pub fn new(
        gpu: &Gpu,
        in_flight: usize,
        targets: &[ImageRef],
        depth_view: vk::ImageView,
        shadow: &crate::shadow::ShadowMap,
    ) -> Self {
        let d = &gpu.device;
        // Fragment shaders, and the tiled technique's compute kernels.
        let sampled = (
            vk::DescriptorType::SAMPLED_IMAGE,
            vk::ShaderStageFlags::FRAGMENT | vk::ShaderStageFlags::COMPUTE,
        );
        let mut bindings = layout_bindings(&[sampled; 3]);
        bindings.extend(shadow.bindings.iter().copied());
        let set_layout = set_layout(d, &bindings);
        let types: Vec<_> = bindings.iter().map(|b| b.descriptor_type).collect();
        let (pool, sets) = allocate_sets(d, set_layout, in_flight, &types);
        // The layouts the images are in while histencil's light passes read them.
        let color = vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL;
        let depth = vk::ImageLayout::DEPTH_READ_ONLY_STENCIL_ATTACHMENT_OPTIMAL;
        let infos: Vec<[vk::DescriptorImageInfo; 1]> = targets
            .iter()
            .map(|t| (t.view, color))
            .chain([(depth_view, depth)])
            .map(|(view, layout)| {
                [vk::DescriptorImageInfo::default()
                    .image_view(view)
                    .image_layout(layout)]
            })
            .collect();
        for set in &sets {
            let writes: Vec<_> = infos
                .iter()
                .enumerate()
                .map(|(i, info)| {
                    vk::WriteDescriptorSet::default()
                        .dst_set(*set)
                        .dst_binding(i as u32)
                        .descriptor_type(vk::DescriptorType::SAMPLED_IMAGE)
                        .image_info(info)
                })
                .collect();
            unsafe { d.update_descriptor_sets(&writes, &[]) };
        }
        for (slot, set) in sets.iter().enumerate() {
            shadow.write_descriptors(d, *set, slot);
        }
        Self {
            set_layout,
            bindings,
            pool,
            sets,
        }
    }

    pub fn destroy(self, gpu: &Gpu) {
        unsafe {
            gpu.device.destroy_descriptor_pool(self.pool, None);
            gpu.device
                .destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}
