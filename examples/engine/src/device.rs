//! The engine's own Vulkan: instance with the validation layer and synchronisation validation, a
//! messenger that counts what it reports, a device made with what histencil requires
//! (`histencil::vk::REQUIREMENTS`), a gpu-allocator allocator, and images and buffers from it.

use ash::vk;
use gpu_allocator::vulkan::{
    Allocation, AllocationCreateDesc, AllocationScheme, Allocator, AllocatorCreateDesc,
};
use gpu_allocator::MemoryLocation;
use histencil::vk::{
    aspect_of, BorrowedDevice, DepthStencilFormat, ImageRef, ImageState, REQUIREMENTS,
};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

/// Validation errors and warnings seen so far.
pub static MESSAGES: AtomicUsize = AtomicUsize::new(0);

unsafe extern "system" fn on_message(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    _user: *mut std::ffi::c_void,
) -> vk::Bool32 {
    use vk::DebugUtilsMessageSeverityFlagsEXT as S;
    if severity.intersects(S::ERROR | S::WARNING) {
        MESSAGES.fetch_add(1, Ordering::SeqCst);
        let text = unsafe { (*data).message_as_c_str() }
            .map(|m| m.to_string_lossy().into_owned())
            .unwrap_or_default();
        eprintln!("validation: {text}");
    }
    vk::FALSE
}

pub struct Gpu {
    _entry: ash::Entry,
    pub instance: ash::Instance,
    debug: ash::ext::debug_utils::Instance,
    messenger: vk::DebugUtilsMessengerEXT,
    pub physical_device: vk::PhysicalDevice,
    pub queue_family: u32,
    pub device: ash::Device,
    pub queue: vk::Queue,
    pub allocator: Arc<Mutex<Allocator>>,
}

impl Gpu {
    pub fn new() -> Self {
        let entry = unsafe { ash::Entry::load() }.expect("the Vulkan loader");
        let app = vk::ApplicationInfo::default().api_version(REQUIREMENTS.api_version);
        let layers = [c"VK_LAYER_KHRONOS_validation".as_ptr()];
        let extensions = [
            ash::ext::debug_utils::NAME.as_ptr(),
            ash::ext::validation_features::NAME.as_ptr(),
        ];
        let enables = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
        let mut features =
            vk::ValidationFeaturesEXT::default().enabled_validation_features(&enables);
        let messenger_info = vk::DebugUtilsMessengerCreateInfoEXT::default()
            .message_severity(
                vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
                    | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING,
            )
            .message_type(
                vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                    | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                    | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
            )
            .pfn_user_callback(Some(on_message));
        let mut on_create = messenger_info;
        let info = vk::InstanceCreateInfo::default()
            .application_info(&app)
            .enabled_layer_names(&layers)
            .enabled_extension_names(&extensions)
            .push_next(&mut features)
            .push_next(&mut on_create);
        let instance = unsafe { entry.create_instance(&info, None) }.expect("instance");
        let debug = ash::ext::debug_utils::Instance::new(&entry, &instance);
        let messenger = unsafe { debug.create_debug_utils_messenger(&messenger_info, None) }
            .expect("messenger");
        let filter = std::env::var("HISTENCIL_DEVICE")
            .unwrap_or_default()
            .to_lowercase();
        let (physical_device, queue_family) = unsafe { instance.enumerate_physical_devices() }
            .expect("devices")
            .into_iter()
            .filter(|&pd| {
                let props = unsafe { instance.get_physical_device_properties(pd) };
                let name = props.device_name_as_c_str().unwrap().to_string_lossy();
                name.to_lowercase().contains(&filter)
                    && unsafe { REQUIREMENTS.missing(&instance, pd) }.is_empty()
            })
            .find_map(|pd| {
                let families =
                    unsafe { instance.get_physical_device_queue_family_properties(pd) }.len();
                (0..families as u32)
                    .find(|&f| unsafe { REQUIREMENTS.queue_family_fits(&instance, pd, f) })
                    .map(|f| (pd, f))
            })
            .expect("a Vulkan 1.3 device with what histencil requires");
        let priorities = [1.0];
        let queues = [vk::DeviceQueueCreateInfo::default()
            .queue_family_index(queue_family)
            .queue_priorities(&priorities)];
        let core = REQUIREMENTS.features();
        let mut features13 = REQUIREMENTS.features13();
        let device_extensions: Vec<_> = REQUIREMENTS
            .device_extensions
            .iter()
            .map(|e| e.as_ptr())
            .collect();
        let info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queues)
            .enabled_extension_names(&device_extensions)
            .enabled_features(&core)
            .push_next(&mut features13);
        let device =
            unsafe { instance.create_device(physical_device, &info, None) }.expect("device");
        let queue = unsafe { device.get_device_queue(queue_family, 0) };
        let allocator = Allocator::new(&AllocatorCreateDesc {
            instance: instance.clone(),
            device: device.clone(),
            physical_device,
            debug_settings: Default::default(),
            buffer_device_address: false,
            allocation_sizes: Default::default(),
        })
        .expect("allocator");
        Self {
            _entry: entry,
            instance,
            debug,
            messenger,
            physical_device,
            queue_family,
            device,
            queue,
            allocator: Arc::new(Mutex::new(allocator)),
        }
    }

    /// The device as histencil borrows it.
    pub fn lend(&self) -> BorrowedDevice {
        BorrowedDevice {
            instance: self.instance.clone(),
            device: self.device.clone(),
            physical_device: self.physical_device,
            queue_family: self.queue_family,
            queue: self.queue,
            allocator: Some(self.allocator.clone()),
            debug_utils: true,
            depth_stencil: Some(DepthStencilFormat::D32S8),
            // The most of this engine's memory histencil's lighting and lightmaps may hold.
            memory_budget: Some(256 << 20),
            pipeline_cache: None,
        }
    }

    fn allocate(
        &self,
        name: &str,
        requirements: vk::MemoryRequirements,
        location: MemoryLocation,
        linear: bool,
    ) -> Allocation {
        self.allocator
            .lock()
            .unwrap()
            .allocate(&AllocationCreateDesc {
                name,
                requirements,
                location,
                linear,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
            .expect("memory")
    }

    pub fn image(
        &self,
        name: &str,
        format: vk::Format,
        extent: vk::Extent2D,
        usage: vk::ImageUsageFlags,
    ) -> Image {
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(format)
            .extent(vk::Extent3D {
                width: extent.width,
                height: extent.height,
                depth: 1,
            })
            .mip_levels(1)
            .array_layers(1)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(usage);
        let d = &self.device;
        let image = unsafe { d.create_image(&info, None) }.expect("image");
        let allocation = self.allocate(
            name,
            unsafe { d.get_image_memory_requirements(image) },
            MemoryLocation::GpuOnly,
            false,
        );
        unsafe { d.bind_image_memory(image, allocation.memory(), allocation.offset()) }
            .expect("bind");
        let range = vk::ImageSubresourceRange::default()
            .aspect_mask(aspect_of(format))
            .level_count(1)
            .layer_count(1);
        let view_info = vk::ImageViewCreateInfo::default()
            .image(image)
            .view_type(vk::ImageViewType::TYPE_2D)
            .format(format)
            .subresource_range(range);
        let view = unsafe { d.create_image_view(&view_info, None) }.expect("view");
        Image {
            target: ImageRef {
                image,
                view,
                format,
                extent,
                usage,
                state: ImageState::UNDEFINED,
            },
            allocation,
        }
    }

    pub fn buffer(
        &self,
        name: &str,
        size: u64,
        usage: vk::BufferUsageFlags,
        location: MemoryLocation,
    ) -> Buffer {
        let info = vk::BufferCreateInfo::default().size(size).usage(usage);
        let buffer = unsafe { self.device.create_buffer(&info, None) }.expect("buffer");
        let requirements = unsafe { self.device.get_buffer_memory_requirements(buffer) };
        let allocation = self.allocate(name, requirements, location, true);
        unsafe {
            self.device
                .bind_buffer_memory(buffer, allocation.memory(), allocation.offset())
        }
        .expect("bind");
        Buffer { buffer, allocation }
    }

    /// A view of the depth aspect alone of a depth-stencil `image`, for sampling depth.
    pub fn depth_view(&self, image: &Image) -> vk::ImageView {
        let range = vk::ImageSubresourceRange::default()
            .aspect_mask(vk::ImageAspectFlags::DEPTH)
            .level_count(1)
            .layer_count(1);
        let info = vk::ImageViewCreateInfo::default()
            .image(image.target.image)
            .view_type(vk::ImageViewType::TYPE_2D)
            .format(image.target.format)
            .subresource_range(range);
        unsafe { self.device.create_image_view(&info, None) }.expect("depth view")
    }

    pub fn free_image(&self, image: Image) {
        unsafe {
            self.device.destroy_image_view(image.target.view, None);
            self.device.destroy_image(image.target.image, None);
        }
        self.allocator
            .lock()
            .unwrap()
            .free(image.allocation)
            .expect("free");
    }

    pub fn free_buffer(&self, buffer: Buffer) {
        unsafe { self.device.destroy_buffer(buffer.buffer, None) };
        self.allocator
            .lock()
            .unwrap()
            .free(buffer.allocation)
            .expect("free");
    }

    /// Destroys the allocator, device, messenger and instance, in that order.
    pub fn destroy(self) {
        let allocator = Arc::try_unwrap(self.allocator)
            .unwrap_or_else(|_| panic!("someone still holds the allocator"));
        drop(allocator);
        unsafe {
            self.device.destroy_device(None);
            self.debug
                .destroy_debug_utils_messenger(self.messenger, None);
            self.instance.destroy_instance(None);
        }
    }
}

/// An engine image: its memory, and histencil's view of it with the state the engine tracks.
pub struct Image {
    pub target: ImageRef,
    allocation: Allocation,
}

pub struct Buffer {
    pub buffer: vk::Buffer,
    allocation: Allocation,
}

impl Buffer {
    pub fn bytes(&self) -> &[u8] {
        self.allocation.mapped_slice().expect("host visible")
    }

    pub fn write(&mut self, bytes: &[u8]) {
        self.allocation.mapped_slice_mut().expect("host visible")[..bytes.len()]
            .copy_from_slice(bytes);
    }
}

/// The engine's barrier: from the image's tracked state to `next`, contents kept unless
/// `discard`.
pub fn barrier(
    device: &ash::Device,
    cmd: vk::CommandBuffer,
    image: &mut ImageRef,
    next: ImageState,
    discard: bool,
) {
    let old = if discard {
        vk::ImageLayout::UNDEFINED
    } else {
        image.state.layout
    };
    let range = vk::ImageSubresourceRange::default()
        .aspect_mask(image.aspect())
        .level_count(1)
        .layer_count(1);
    let b = [vk::ImageMemoryBarrier2::default()
        .src_stage_mask(image.state.stage)
        .src_access_mask(image.state.access)
        .dst_stage_mask(next.stage)
        .dst_access_mask(next.access)
        .old_layout(old)
        .new_layout(next.layout)
        .image(image.image)
        .subresource_range(range)];
    unsafe {
        device.cmd_pipeline_barrier2(
            cmd,
            &vk::DependencyInfo::default().image_memory_barriers(&b),
        )
    };
    image.state = next;
}

/// A mesh in the engine's vertex and index buffers (histencil_scene's vertex: position, normal,
/// uv; 32 bytes), drawn with one indexed call.
pub struct GpuMesh {
    pub vertices: Buffer,
    pub indices: Buffer,
    pub index_count: u32,
}

impl GpuMesh {
    pub fn draw(&self, d: &ash::Device, cmd: vk::CommandBuffer) {
        unsafe {
            d.cmd_bind_vertex_buffers(cmd, 0, &[self.vertices.buffer], &[0]);
            d.cmd_bind_index_buffer(cmd, self.indices.buffer, 0, vk::IndexType::UINT32);
            d.cmd_draw_indexed(cmd, self.index_count, 1, 0, 0, 0);
        }
    }
}

impl Gpu {
    /// Uploads `mesh` into host-visible vertex and index buffers named after `name`.
    pub fn mesh(&self, name: &str, mesh: &histencil::scene::Mesh) -> GpuMesh {
        let floats: Vec<f32> = mesh
            .vertices
            .iter()
            .flat_map(|v| [v.position.as_slice(), &v.normal, &v.uv].concat())
            .collect();
        let upload = |what: &str, bytes: &[u8], usage| {
            let mut b = self.buffer(
                &format!("{name}-{what}"),
                bytes.len() as u64,
                usage,
                MemoryLocation::CpuToGpu,
            );
            b.write(bytes);
            b
        };
        GpuMesh {
            vertices: upload(
                "vertices",
                bytemuck::cast_slice(&floats),
                vk::BufferUsageFlags::VERTEX_BUFFER,
            ),
            indices: upload(
                "indices",
                bytemuck::cast_slice(&mesh.indices),
                vk::BufferUsageFlags::INDEX_BUFFER,
            ),
            index_count: mesh.indices.len() as u32,
        }
    }

    pub fn free_mesh(&self, mesh: GpuMesh) {
        self.free_buffer(mesh.vertices);
        self.free_buffer(mesh.indices);
    }
}

/// What differs between the engine's graphics pipelines; the rest is shared: triangle lists,
/// counter-clockwise front faces, one sample, dynamic viewport and scissor, dynamic rendering
/// with the engine's depth-stencil format.
pub struct PipelineSpec<'a> {
    /// Vertex and fragment SPIR-V.
    pub shaders: (&'a [u8], &'a [u8]),
    /// The vertex stride and each attribute's format and offset, at locations 0, 1, ...
    pub vertex: (u32, &'a [(vk::Format, u32)]),
    pub cull: vk::CullModeFlags,
    pub depth_stencil: vk::PipelineDepthStencilStateCreateInfo<'a>,
    /// One per colour attachment.
    pub blend: &'a [vk::PipelineColorBlendAttachmentState],
    pub color_formats: &'a [vk::Format],
    /// The depth attachment's format; its stencil too when it has one.
    pub depth_format: vk::Format,
    /// Constant and slope-scaled depth bias (the shadow map pass).
    pub depth_bias: Option<(f32, f32)>,
    /// Dynamic state besides viewport and scissor.
    pub dynamic: &'a [vk::DynamicState],
}

/// Creates a graphics pipeline of `layout` as `spec` says.
pub fn graphics_pipeline(
    d: &ash::Device,
    layout: vk::PipelineLayout,
    spec: &PipelineSpec,
) -> vk::Pipeline {
    let module = |bytes: &[u8]| {
        let code = ash::util::read_spv(&mut std::io::Cursor::new(bytes)).expect("SPIR-V");
        unsafe { d.create_shader_module(&vk::ShaderModuleCreateInfo::default().code(&code), None) }
            .unwrap()
    };
    let (vert, frag) = (module(spec.shaders.0), module(spec.shaders.1));
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
    let (stride, attributes) = spec.vertex;
    let bindings = [vk::VertexInputBindingDescription::default().stride(stride)];
    let attributes: Vec<_> = attributes
        .iter()
        .enumerate()
        .map(|(location, (format, offset))| {
            vk::VertexInputAttributeDescription::default()
                .location(location as u32)
                .format(*format)
                .offset(*offset)
        })
        .collect();
    let vertex_input = vk::PipelineVertexInputStateCreateInfo::default()
        .vertex_binding_descriptions(&bindings)
        .vertex_attribute_descriptions(&attributes);
    let assembly = vk::PipelineInputAssemblyStateCreateInfo::default()
        .topology(vk::PrimitiveTopology::TRIANGLE_LIST);
    let viewport = vk::PipelineViewportStateCreateInfo::default()
        .viewport_count(1)
        .scissor_count(1);
    let (bias, constant, slope) = match spec.depth_bias {
        Some((c, s)) => (true, c, s),
        None => (false, 0.0, 0.0),
    };
    let raster = vk::PipelineRasterizationStateCreateInfo::default()
        .depth_bias_enable(bias)
        .depth_bias_constant_factor(constant)
        .depth_bias_slope_factor(slope)
        .cull_mode(spec.cull)
        .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
        .line_width(1.0);
    let multisample = vk::PipelineMultisampleStateCreateInfo::default()
        .rasterization_samples(vk::SampleCountFlags::TYPE_1);
    let blend = vk::PipelineColorBlendStateCreateInfo::default().attachments(spec.blend);
    let dynamic: Vec<_> = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR]
        .into_iter()
        .chain(spec.dynamic.iter().copied())
        .collect();
    let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic);
    let mut rendering = vk::PipelineRenderingCreateInfo::default()
        .color_attachment_formats(spec.color_formats)
        .depth_attachment_format(spec.depth_format)
        .stencil_attachment_format(match spec.depth_format {
            vk::Format::D32_SFLOAT_S8_UINT | vk::Format::D24_UNORM_S8_UINT => spec.depth_format,
            _ => vk::Format::UNDEFINED,
        });
    let info = vk::GraphicsPipelineCreateInfo::default()
        .stages(&stages)
        .vertex_input_state(&vertex_input)
        .input_assembly_state(&assembly)
        .viewport_state(&viewport)
        .rasterization_state(&raster)
        .multisample_state(&multisample)
        .depth_stencil_state(&spec.depth_stencil)
        .color_blend_state(&blend)
        .dynamic_state(&dynamic)
        .layout(layout)
        .push_next(&mut rendering);
    let pipeline = unsafe { d.create_graphics_pipelines(vk::PipelineCache::null(), &[info], None) }
        .map_err(|(_, e)| e)
        .unwrap()[0];
    unsafe {
        d.destroy_shader_module(vert, None);
        d.destroy_shader_module(frag, None);
    }
    pipeline
}

/// One descriptor per binding: binding `i` of type and stages `bindings[i]`.
pub fn layout_bindings(
    bindings: &[(vk::DescriptorType, vk::ShaderStageFlags)],
) -> Vec<vk::DescriptorSetLayoutBinding<'static>> {
    bindings
        .iter()
        .enumerate()
        .map(|(i, (ty, stages))| {
            vk::DescriptorSetLayoutBinding::default()
                .binding(i as u32)
                .descriptor_type(*ty)
                .descriptor_count(1)
                .stage_flags(*stages)
        })
        .collect()
}

/// A descriptor set layout of `bindings` ([`layout_bindings`]).
pub fn set_layout(
    d: &ash::Device,
    bindings: &[vk::DescriptorSetLayoutBinding],
) -> vk::DescriptorSetLayout {
    let info = vk::DescriptorSetLayoutCreateInfo::default().bindings(bindings);
    unsafe { d.create_descriptor_set_layout(&info, None) }.expect("set layout")
}

/// A pool and `count` sets of `layout`, whose bindings hold `types` (one descriptor each).
pub fn allocate_sets(
    d: &ash::Device,
    layout: vk::DescriptorSetLayout,
    count: usize,
    types: &[vk::DescriptorType],
) -> (vk::DescriptorPool, Vec<vk::DescriptorSet>) {
    let sizes: Vec<_> = types
        .iter()
        .map(|ty| {
            vk::DescriptorPoolSize::default()
                .ty(*ty)
                .descriptor_count(count as u32)
        })
        .collect();
    let info = vk::DescriptorPoolCreateInfo::default()
        .max_sets(count as u32)
        .pool_sizes(&sizes);
    let pool = unsafe { d.create_descriptor_pool(&info, None) }.expect("descriptor pool");
    let layouts = vec![layout; count];
    let alloc = vk::DescriptorSetAllocateInfo::default()
        .descriptor_pool(pool)
        .set_layouts(&layouts);
    let sets = unsafe { d.allocate_descriptor_sets(&alloc) }.expect("descriptor sets");
    (pool, sets)
}

/// A depth(-stencil) attachment in `layout`, cleared to `depth` and stencil 0, kept after the
/// pass or not.
pub fn depth_attachment(
    view: vk::ImageView,
    layout: vk::ImageLayout,
    depth: f32,
    store: bool,
) -> vk::RenderingAttachmentInfo<'static> {
    vk::RenderingAttachmentInfo::default()
        .image_view(view)
        .image_layout(layout)
        .load_op(vk::AttachmentLoadOp::CLEAR)
        .store_op(if store {
            vk::AttachmentStoreOp::STORE
        } else {
            vk::AttachmentStoreOp::DONT_CARE
        })
        .clear_value(vk::ClearValue {
            depth_stencil: vk::ClearDepthStencilValue { depth, stencil: 0 },
        })
}

/// Begins rendering over `extent` into `colors` and `depth` (its stencil too with `stencil`)
/// and sets the whole-extent viewport and scissor.
///
/// # Safety
/// `cmd` is recording outside rendering on `d`; the attachments' images are in the layouts
/// their infos name.
pub unsafe fn begin_rendering(
    d: &ash::Device,
    cmd: vk::CommandBuffer,
    extent: vk::Extent2D,
    colors: &[vk::RenderingAttachmentInfo],
    depth: &vk::RenderingAttachmentInfo,
    stencil: bool,
) {
    let area = vk::Rect2D::default().extent(extent);
    let mut info = vk::RenderingInfo::default()
        .render_area(area)
        .layer_count(1)
        .color_attachments(colors)
        .depth_attachment(depth);
    if stencil {
        info = info.stencil_attachment(depth);
    }
    let viewport = vk::Viewport {
        width: extent.width as f32,
        height: extent.height as f32,
        max_depth: 1.0,
        ..Default::default()
    };
    d.cmd_begin_rendering(cmd, &info);
    d.cmd_set_viewport(cmd, 0, &[viewport]);
    d.cmd_set_scissor(cmd, 0, &[area]);
}
