//! An engine played by a test: its own instance with the validation layer and synchronisation
//! validation, its own messenger, device and gpu-allocator allocator, created from
//! `histencil_vk::REQUIREMENTS` and lent to histencil through `Context::from_raw`.

use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};
use gpu_allocator::MemoryLocation;
use histencil_vk::{BorrowedDevice, ImageState, ValidationLog, REQUIREMENTS};
use std::sync::{Arc, Mutex};

/// The engine's side: what it created, in creation order.
pub struct Engine {
    /// The loader, whose `vkGetInstanceProcAddr` a C engine lends histencil.
    pub entry: ash::Entry,
    pub instance: ash::Instance,
    pub debug: ash::ext::debug_utils::Instance,
    pub messenger: vk::DebugUtilsMessengerEXT,
    pub physical_device: vk::PhysicalDevice,
    pub queue_family: u32,
    pub device: ash::Device,
    pub allocator: Arc<Mutex<Allocator>>,
    pub log: Arc<ValidationLog>,
    /// Held until the instance is destroyed ([`crate::instance_turn`]); the last field, so it
    /// is released after everything else.
    _turn: std::sync::MutexGuard<'static, ()>,
}

impl Engine {
    /// Creates the instance (with the validation layer, synchronisation validation on),
    /// messenger, device and allocator.
    pub fn start() -> Self {
        Self::start_with(true)
    }

    /// [`Engine::start`] without the validation layer: for benchmarks of the CPU's work, which
    /// the layer's own would swamp.
    pub fn start_unvalidated() -> Self {
        Self::start_with(false)
    }

    fn start_with(validated: bool) -> Self {
        let turn = crate::instance_turn();
        let entry = unsafe { ash::Entry::load() }.expect("Vulkan loader");
        let log = Arc::new(ValidationLog::default());
        let app = vk::ApplicationInfo::default().api_version(REQUIREMENTS.api_version);
        let all_layers = [c"VK_LAYER_KHRONOS_validation".as_ptr()];
        let layers = if validated { &all_layers[..] } else { &[] };
        let all_extensions = [
            ash::ext::debug_utils::NAME.as_ptr(),
            ash::ext::validation_features::NAME.as_ptr(),
        ];
        let extensions = if validated {
            &all_extensions[..]
        } else {
            &all_extensions[..1]
        };
        let enables = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
        let mut features =
            vk::ValidationFeaturesEXT::default().enabled_validation_features(&enables);
        // SAFETY: `log` lives in the engine until after the messenger is destroyed.
        let messenger_info = unsafe { ValidationLog::messenger_create_info(&log) };
        let mut on_create = messenger_info;
        let mut info = vk::InstanceCreateInfo::default()
            .application_info(&app)
            .enabled_layer_names(layers)
            .enabled_extension_names(extensions)
            .push_next(&mut on_create);
        if validated {
            info = info.push_next(&mut features);
        }
        let instance = unsafe { entry.create_instance(&info, None) }.expect("instance");
        let debug = ash::ext::debug_utils::Instance::new(&entry, &instance);
        let messenger = unsafe { debug.create_debug_utils_messenger(&messenger_info, None) }
            .expect("messenger");
        let filter = std::env::var("HISTENCIL_DEVICE")
            .unwrap_or_default()
            .to_lowercase();
        let (physical_device, queue_family) = unsafe { instance.enumerate_physical_devices() }
            .unwrap()
            .into_iter()
            .filter(|&pd| {
                let props = unsafe { instance.get_physical_device_properties(pd) };
                let name = props.device_name_as_c_str().unwrap().to_string_lossy();
                name.to_lowercase().contains(&filter)
                    && unsafe { REQUIREMENTS.missing(&instance, pd) }.is_empty()
            })
            .find_map(|pd| {
                (0..8)
                    .find(|&f| unsafe { REQUIREMENTS.queue_family_fits(&instance, pd, f) })
                    .map(|f| (pd, f))
            })
            .expect("a device that meets histencil's requirements");
        let priorities = [1.0];
        let queues = [vk::DeviceQueueCreateInfo::default()
            .queue_family_index(queue_family)
            .queue_priorities(&priorities)];
        let core = REQUIREMENTS.features();
        let mut features13 = REQUIREMENTS.features13();
        let info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queues)
            .enabled_features(&core)
            .push_next(&mut features13);
        let device =
            unsafe { instance.create_device(physical_device, &info, None) }.expect("device");
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
            entry,
            instance,
            debug,
            messenger,
            physical_device,
            queue_family,
            device,
            allocator: Arc::new(Mutex::new(allocator)),
            log,
            _turn: turn,
        }
    }

    pub fn lend(&self, queue_family: u32) -> BorrowedDevice {
        BorrowedDevice {
            instance: self.instance.clone(),
            device: self.device.clone(),
            physical_device: self.physical_device,
            queue_family,
            queue: unsafe { self.device.get_device_queue(self.queue_family, 0) },
            allocator: Some(self.allocator.clone()),
            debug_utils: true,
            depth_stencil: None,
            memory_budget: None,
            pipeline_cache: None,
        }
    }

    /// Destroys everything in reverse order; returns the messenger's log.
    pub fn destroy(self) -> Arc<ValidationLog> {
        let allocator = Arc::try_unwrap(self.allocator)
            .unwrap_or_else(|_| panic!("histencil kept a reference to the engine's allocator"));
        drop(allocator);
        unsafe {
            self.device.destroy_device(None);
            self.debug
                .destroy_debug_utils_messenger(self.messenger, None);
            self.instance.destroy_instance(None);
        }
        self.log
    }
}

/// An image the engine made with its own allocator, and one view over all its aspects.
pub struct EngineImage {
    pub image: vk::Image,
    pub view: vk::ImageView,
    pub format: vk::Format,
    pub extent: vk::Extent2D,
    pub usage: vk::ImageUsageFlags,
    allocation: gpu_allocator::vulkan::Allocation,
}

impl EngineImage {
    /// As histencil sees it, in state `state`.
    pub fn as_ref(&self, state: histencil_vk::ImageState) -> histencil_vk::ImageRef {
        histencil_vk::ImageRef {
            image: self.image,
            view: self.view,
            format: self.format,
            extent: self.extent,
            usage: self.usage,
            state,
        }
    }
}

/// A host-readable buffer the engine copies into.
pub struct EngineBuffer {
    pub buffer: vk::Buffer,
    allocation: gpu_allocator::vulkan::Allocation,
}

impl EngineBuffer {
    pub fn bytes(&self) -> &[u8] {
        self.allocation.mapped_slice().expect("host visible")
    }
}

impl Engine {
    pub fn image(
        &self,
        name: &str,
        format: vk::Format,
        extent: vk::Extent2D,
        usage: vk::ImageUsageFlags,
    ) -> EngineImage {
        use gpu_allocator::vulkan::{AllocationCreateDesc, AllocationScheme};
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
        let requirements = unsafe { d.get_image_memory_requirements(image) };
        let allocation = self
            .allocator
            .lock()
            .unwrap()
            .allocate(&AllocationCreateDesc {
                name,
                requirements,
                location: gpu_allocator::MemoryLocation::GpuOnly,
                linear: false,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
            .expect("image memory");
        unsafe { d.bind_image_memory(image, allocation.memory(), allocation.offset()) }
            .expect("bind");
        let aspect = histencil_vk::aspect_of(format);
        let range = vk::ImageSubresourceRange::default()
            .aspect_mask(aspect)
            .level_count(1)
            .layer_count(1);
        let view_info = vk::ImageViewCreateInfo::default()
            .image(image)
            .view_type(vk::ImageViewType::TYPE_2D)
            .format(format)
            .subresource_range(range);
        let view = unsafe { d.create_image_view(&view_info, None) }.expect("view");
        EngineImage {
            usage,
            image,
            view,
            format,
            extent,
            allocation,
        }
    }

    /// A command pool with one primary command buffer.
    pub fn command_buffer(&self) -> (vk::CommandPool, vk::CommandBuffer) {
        let d = &self.device;
        let info = vk::CommandPoolCreateInfo::default().queue_family_index(self.queue_family);
        let pool = unsafe { d.create_command_pool(&info, None) }.expect("command pool");
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(pool)
            .command_buffer_count(1);
        let cmd = unsafe { d.allocate_command_buffers(&alloc) }.expect("command buffer")[0];
        (pool, cmd)
    }

    /// Ends `cmd` (from [`Engine::command_buffer`]), submits it, waits for the queue and frees
    /// its pool.
    ///
    /// # Safety
    /// `cmd` is recording on this device, and `pool` is its pool.
    pub unsafe fn submit_and_wait(&self, pool: vk::CommandPool, cmd: vk::CommandBuffer) {
        let d = &self.device;
        unsafe {
            d.end_command_buffer(cmd).unwrap();
            let queue = d.get_device_queue(self.queue_family, 0);
            let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
            let submit = vk::SubmitInfo2::default().command_buffer_infos(&cmds);
            d.queue_submit2(queue, &[submit], vk::Fence::null())
                .unwrap();
            d.queue_wait_idle(queue).unwrap();
            d.destroy_command_pool(pool, None);
        }
    }

    /// `count` frame slots: a command pool and buffer each, and a fence made signalled (the
    /// first wait on a slot passes).
    pub fn frame_slots(
        &self,
        count: usize,
    ) -> Vec<(vk::CommandPool, vk::CommandBuffer, vk::Fence)> {
        (0..count)
            .map(|_| {
                let (pool, cmd) = self.command_buffer();
                let signalled =
                    vk::FenceCreateInfo::default().flags(vk::FenceCreateFlags::SIGNALED);
                let fence = unsafe { self.device.create_fence(&signalled, None) }.expect("fence");
                (pool, cmd, fence)
            })
            .collect()
    }

    /// Frees what [`Engine::frame_slots`] made, once the GPU is done with it.
    pub fn free_frame_slots(&self, slots: &[(vk::CommandPool, vk::CommandBuffer, vk::Fence)]) {
        for (pool, _, fence) in slots {
            unsafe {
                self.device.destroy_fence(*fence, None);
                self.device.destroy_command_pool(*pool, None);
            }
        }
    }

    pub fn free_image(&self, image: EngineImage) {
        unsafe {
            self.device.destroy_image_view(image.view, None);
            self.device.destroy_image(image.image, None);
        }
        self.allocator
            .lock()
            .unwrap()
            .free(image.allocation)
            .expect("free");
    }

    pub fn readback_buffer(&self, size: u64) -> EngineBuffer {
        let (usage, location) = (vk::BufferUsageFlags::TRANSFER_DST, MemoryLocation::GpuToCpu);
        self.host_buffer(size, usage, location, "engine-readback")
    }

    /// A buffer the GPU reads holding `bytes` (an upload's source, a uniform block), with
    /// `usage`.
    pub fn upload_buffer(&self, bytes: &[u8], usage: vk::BufferUsageFlags) -> EngineBuffer {
        let size = bytes.len() as u64;
        let mut b = self.host_buffer(size, usage, MemoryLocation::CpuToGpu, "engine-upload");
        let mapped = b.allocation.mapped_slice_mut().expect("host visible");
        mapped[..bytes.len()].copy_from_slice(bytes);
        b
    }

    fn host_buffer(
        &self,
        size: u64,
        usage: vk::BufferUsageFlags,
        location: MemoryLocation,
        name: &str,
    ) -> EngineBuffer {
        use gpu_allocator::vulkan::{AllocationCreateDesc, AllocationScheme};
        let info = vk::BufferCreateInfo::default().size(size).usage(usage);
        let buffer = unsafe { self.device.create_buffer(&info, None) }.expect("buffer");
        let requirements = unsafe { self.device.get_buffer_memory_requirements(buffer) };
        let allocation = self
            .allocator
            .lock()
            .unwrap()
            .allocate(&AllocationCreateDesc {
                name,
                requirements,
                location,
                linear: true,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
            .expect("buffer memory");
        unsafe {
            self.device
                .bind_buffer_memory(buffer, allocation.memory(), allocation.offset())
        }
        .expect("bind");
        EngineBuffer { buffer, allocation }
    }

    pub fn free_buffer(&self, buffer: EngineBuffer) {
        unsafe { self.device.destroy_buffer(buffer.buffer, None) };
        self.allocator
            .lock()
            .unwrap()
            .free(buffer.allocation)
            .expect("free");
    }
}

/// The engine's barrier from the image's tracked state to `next`, over every aspect.
///
/// # Safety
/// `cmd` is recording on the engine's device and `image.state` is true.
pub unsafe fn barrier(
    d: &ash::Device,
    cmd: vk::CommandBuffer,
    image: &mut histencil_vk::ImageRef,
    next: ImageState,
    discard: bool,
) {
    let old = if discard {
        vk::ImageLayout::UNDEFINED
    } else {
        image.state.layout
    };
    let b = [vk::ImageMemoryBarrier2::default()
        .src_stage_mask(image.state.stage)
        .src_access_mask(image.state.access)
        .dst_stage_mask(next.stage)
        .dst_access_mask(next.access)
        .old_layout(old)
        .new_layout(next.layout)
        .image(image.image)
        .subresource_range(color_range(image))];
    d.cmd_pipeline_barrier2(
        cmd,
        &vk::DependencyInfo::default().image_memory_barriers(&b),
    );
    image.state = next;
}

/// Copies `image` (colour) into `buffer` and makes the copy visible to the host, tracking the
/// image's state.
///
/// # Safety
/// `cmd` is recording on the engine's device, `image.state` is true, `buffer` is large enough.
pub unsafe fn copy_to_buffer(
    d: &ash::Device,
    cmd: vk::CommandBuffer,
    image: &mut histencil_vk::ImageRef,
    buffer: vk::Buffer,
) {
    let state = ImageState {
        layout: vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
        stage: vk::PipelineStageFlags2::COPY,
        access: vk::AccessFlags2::TRANSFER_READ,
    };
    barrier(d, cmd, image, state, false);
    let region = vk::BufferImageCopy::default()
        .image_subresource(
            vk::ImageSubresourceLayers::default()
                .aspect_mask(vk::ImageAspectFlags::COLOR)
                .layer_count(1),
        )
        .image_extent(vk::Extent3D {
            width: image.extent.width,
            height: image.extent.height,
            depth: 1,
        });
    d.cmd_copy_image_to_buffer(cmd, image.image, state.layout, buffer, &[region]);
    let host = [vk::MemoryBarrier2::default()
        .src_stage_mask(vk::PipelineStageFlags2::COPY)
        .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
        .dst_stage_mask(vk::PipelineStageFlags2::HOST)
        .dst_access_mask(vk::AccessFlags2::HOST_READ)];
    d.cmd_pipeline_barrier2(cmd, &vk::DependencyInfo::default().memory_barriers(&host));
}

fn color_range(image: &histencil_vk::ImageRef) -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange::default()
        .aspect_mask(image.aspect())
        .level_count(1)
        .layer_count(1)
}

/// The images an engine lights into: the G-buffer in `GBUFFER_FORMATS`, depth-stencil and an
/// RGBA16F HDR image, with the contract's usages plus copies out (and the HDR image's clear).
pub struct EngineTargets {
    pub gbuffer: Vec<EngineImage>,
    pub depth: EngineImage,
    pub hdr: EngineImage,
}

impl Engine {
    /// Lighting targets of `extent`, depth-stencil in `depth_format`.
    pub fn lighting_targets(
        &self,
        extent: vk::Extent2D,
        depth_format: vk::Format,
    ) -> EngineTargets {
        use vk::ImageUsageFlags as U;
        let names = ["albedo", "normal-depth", "material"];
        let gbuffer = names
            .iter()
            .zip(histencil_vk::GBUFFER_FORMATS)
            .map(|(n, f)| {
                self.image(
                    n,
                    f,
                    extent,
                    U::COLOR_ATTACHMENT | U::SAMPLED | U::TRANSFER_SRC,
                )
            })
            .collect();
        let depth_usage = U::DEPTH_STENCIL_ATTACHMENT | U::TRANSFER_SRC | U::SAMPLED;
        let hdr_usage = U::COLOR_ATTACHMENT | U::TRANSFER_DST | U::TRANSFER_SRC | U::STORAGE;
        EngineTargets {
            gbuffer,
            depth: self.image("depth", depth_format, extent, depth_usage),
            hdr: self.image("hdr", vk::Format::R16G16B16A16_SFLOAT, extent, hdr_usage),
        }
    }
}

/// An engine's decode set for histencil's own decode read through a layout of the engine's: its
/// three G-buffer images as sampled images, visible to `stages`.
pub struct DecodeSet {
    pub bindings: Vec<vk::DescriptorSetLayoutBinding<'static>>,
    pub layout: vk::DescriptorSetLayout,
    pub pool: vk::DescriptorPool,
    pub set: vk::DescriptorSet,
}

impl Engine {
    /// The decode set of `images`' G-buffer (see [`DecodeSet`]); freed by [`DecodeSet::free`]
    /// after every lighting made with its layout.
    pub fn decode_set(&self, images: &EngineTargets, stages: vk::ShaderStageFlags) -> DecodeSet {
        let d = &self.device;
        let bindings = gbuffer_bindings(stages);
        let info = vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings);
        // SAFETY: the engine's device; the caller frees them after their users.
        let layout = unsafe { d.create_descriptor_set_layout(&info, None) }.unwrap();
        let sizes = [vk::DescriptorPoolSize::default()
            .ty(vk::DescriptorType::SAMPLED_IMAGE)
            .descriptor_count(3)];
        let pool_info = vk::DescriptorPoolCreateInfo::default()
            .max_sets(1)
            .pool_sizes(&sizes);
        // SAFETY: as above.
        let pool = unsafe { d.create_descriptor_pool(&pool_info, None) }.unwrap();
        let layouts = [layout];
        let alloc = vk::DescriptorSetAllocateInfo::default()
            .descriptor_pool(pool)
            .set_layouts(&layouts);
        // SAFETY: as above.
        let set = unsafe { d.allocate_descriptor_sets(&alloc) }.unwrap()[0];
        let infos: Vec<[vk::DescriptorImageInfo; 1]> = (images.gbuffer.iter())
            .map(|g| {
                [vk::DescriptorImageInfo::default()
                    .image_view(g.view)
                    .image_layout(vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL)]
            })
            .collect();
        let writes: Vec<_> = (infos.iter().enumerate())
            .map(|(i, info)| {
                vk::WriteDescriptorSet::default()
                    .dst_set(set)
                    .dst_binding(i as u32)
                    .descriptor_type(vk::DescriptorType::SAMPLED_IMAGE)
                    .image_info(info)
            })
            .collect();
        // SAFETY: a set of the engine's pool; the views are live.
        unsafe { d.update_descriptor_sets(&writes, &[]) };
        DecodeSet {
            bindings,
            layout,
            pool,
            set,
        }
    }
}

/// The bindings of histencil's own decode (`include/gbuffer.glsl`: three sampled images), as an
/// engine that binds that decode's resources itself declares them, visible to `stages`.
pub fn gbuffer_bindings(
    stages: vk::ShaderStageFlags,
) -> Vec<vk::DescriptorSetLayoutBinding<'static>> {
    (0..3)
        .map(|binding| {
            vk::DescriptorSetLayoutBinding::default()
                .binding(binding)
                .descriptor_type(vk::DescriptorType::SAMPLED_IMAGE)
                .descriptor_count(1)
                .stage_flags(stages)
        })
        .collect()
}

impl DecodeSet {
    /// Frees the pool and layout: after every lighting made with the layout is gone.
    pub fn free(self, engine: &Engine) {
        // SAFETY: the caller's word: nothing uses them any more.
        unsafe {
            engine.device.destroy_descriptor_pool(self.pool, None);
            engine
                .device
                .destroy_descriptor_set_layout(self.layout, None);
        }
    }
}

impl EngineTargets {
    /// As histencil sees them, before anything touched them.
    pub fn refs(&self) -> histencil_vk::LightingTargets {
        histencil_vk::LightingTargets {
            gbuffer: (0..3)
                .map(|i| self.gbuffer[i].as_ref(ImageState::UNDEFINED))
                .collect(),
            depth_stencil: self.depth.as_ref(ImageState::UNDEFINED),
            hdr: self.hdr.as_ref(ImageState::UNDEFINED),
        }
    }

    pub fn free(self, engine: &Engine) {
        for image in self.gbuffer.into_iter().chain([self.depth, self.hdr]) {
            engine.free_image(image);
        }
    }
}

/// The scene's lights at frame `f`: each circles its own position. Directions are unit vectors
/// and ranges capped as the renderer's scene validation leaves them (`normalise_lights`).
pub fn lights_at(scene: &histencil_scene::Scene, f: usize) -> Vec<histencil_scene::Light> {
    let mut moved = scene.clone();
    moved.lights = scene
        .lights
        .iter()
        .enumerate()
        .map(|(i, l)| {
            let angle = 0.7 * f as f32 + i as f32;
            let offset = glam::Vec3::new(angle.cos(), 0.0, angle.sin()) * 0.6;
            histencil_scene::Light {
                position: l.position + offset,
                ..*l
            }
        })
        .collect();
    moved.normalise_lights();
    moved.lights
}

/// An RGBA16F image's bytes as floats.
pub fn hdr_floats(bytes: &[u8]) -> Vec<f32> {
    bytes
        .chunks_exact(2)
        .map(|h| f16_to_f32(u16::from_le_bytes([h[0], h[1]])))
        .collect()
}

/// IEEE half to single, exactly.
fn f16_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exponent = i32::from((h >> 10) & 0x1F);
    let mantissa = f32::from(h & 0x3FF);
    match exponent {
        0 => sign * mantissa * 2f32.powi(-24),
        31 => sign * f32::INFINITY,
        e => sign * (1.0 + mantissa / 1024.0) * 2f32.powi(e - 15),
    }
}

/// Asserts that the engine's HDR channels equal the renderer's bit for bit, and that the
/// renderer's frame is lit (more than an eighth of its channels above zero).
pub fn assert_same_hdr(expected: &[f32], engine: &[f32]) {
    assert_eq!(expected.len(), engine.len());
    let lit = expected.iter().filter(|v| **v > 0.0).count();
    assert!(lit > expected.len() / 8, "the reference is mostly dark");
    let differing = expected
        .iter()
        .zip(engine)
        .filter(|(e, a)| e.to_bits() != a.to_bits())
        .count();
    assert_eq!(differing, 0, "channels differ from the renderer's frame");
}

/// The stencil technique's plan of `scene`'s lights and BRDF bounds for `view` on `backend`,
/// as an engine makes it each frame (`plan_frame`), in `layout` with the BRDF slots `brdfs`.
pub fn stencil_plan(
    scene: &histencil_scene::Scene,
    layout: &histencil_model::StencilLayout,
    brdfs: &[histencil_brdf::BrdfId],
    view: &histencil_model::ViewDesc,
    backend: histencil_vk::Backend,
) -> histencil_model::FramePlan {
    plan(
        scene,
        layout,
        brdfs,
        view,
        backend,
        histencil_model::TechniqueChoice::Stencil,
    )
}

/// As [`stencil_plan`], for `technique` (branching's plan, which the LUT technique shades).
pub fn plan(
    scene: &histencil_scene::Scene,
    layout: &histencil_model::StencilLayout,
    brdfs: &[histencil_brdf::BrdfId],
    view: &histencil_model::ViewDesc,
    backend: histencil_vk::Backend,
    technique: histencil_model::TechniqueChoice,
) -> histencil_model::FramePlan {
    use histencil_model::{FlushPolicy, PlanInputs, PlanSettings, View};
    let shapes: Vec<_> = scene.lights.iter().map(|l| l.shape()).collect();
    let bounds = scene.brdf_bounds(brdfs);
    let inputs = PlanInputs {
        lights: &shapes,
        brdf_bounds: &bounds,
        view: &View::new(view).expect("a valid view"),
    };
    let settings = PlanSettings {
        technique,
        caps: backend.platform().caps(),
        flush: FlushPolicy::Auto,
    };
    histencil_model::plan_frame(layout, &inputs, &settings).expect("a plan")
}

/// A frame of `plan` in slot 0 with the HDR target cleared, formula BRDFs, no timestamps or
/// statistics, and `hook_sets`.
pub fn plain_frame<'a>(
    view: &'a histencil_model::ViewDesc,
    lights: &'a [histencil_scene::Light],
    plan: &'a histencil_model::FramePlan,
    hook_sets: histencil_vk::HookSets,
) -> histencil_vk::LightingFrame<'a> {
    histencil_vk::LightingFrame {
        slot: 0,
        view,
        lights,
        plan,
        clear_hdr: true,
        timestamps: false,
        brdf_source: histencil_vk::BrdfSource::Formula,
        tile_stats: false,
        hook_sets,
    }
}

/// The lighting the engine tests make unless they say otherwise: histencil's own hooks, an
/// RGBA16F HDR target, one frame in flight, the hi-stencil emulation on.
pub fn lighting_desc(
    layout: histencil_model::StencilLayout,
    brdfs: Vec<histencil_brdf::BrdfId>,
    extent: vk::Extent2D,
    depth_stencil_format: vk::Format,
    max_lights: usize,
) -> histencil_vk::LightingDesc {
    histencil_vk::LightingDesc {
        layout,
        brdfs,
        extent,
        depth_stencil_format,
        hdr_format: vk::Format::R16G16B16A16_SFLOAT,
        frames_in_flight: 1,
        max_lights: max_lights as u32,
        hi_stencil: true,
        hooks: histencil_vk::LightHooks::Builtin,
    }
}
