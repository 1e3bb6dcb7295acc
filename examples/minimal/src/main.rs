//! The smallest engine that lights its own G-buffer through `histencil`: its own instance (with
//! the validation layer), device and allocator, lent to histencil; its own 64x64 G-buffer in
//! histencil's built-in layout holding a wall, Lambert on the left half and GGX on the right,
//! each half's BRDF in the stencil; one point light planned with `plan_frame` and recorded with
//! `DeferredLighting::record`; the HDR image read back. Its last line is its verdict; it exits
//! non-zero when the frame or the validation layer says something is wrong. Its G-buffer pass
//! clears each half's render area to the wall's texels, so it needs no shader; an engine draws
//! its meshes there through `gbuffer_encode` (the book's "Engine integration: a lit frame").

use ash::vk;
use glam::Vec3;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme, Allocator};
use gpu_allocator::{vulkan::AllocatorCreateDesc, MemoryLocation};
use histencil::prelude::*;
use histencil::vk::access::ImageAccess;
use std::sync::{Arc, Mutex};

const EXTENT: vk::Extent2D = vk::Extent2D { width: 64, height: 64 };
const EXTENT_3D: vk::Extent3D = vk::Extent3D { width: 64, height: 64, depth: 1 };
const DEPTH_STENCIL: vk::Format = vk::Format::D32_SFLOAT_S8_UINT;
const HDR: vk::Format = vk::Format::R16G16B16A16_SFLOAT;
/// The wall's distance along the view direction.
const WALL: f32 = 4.0;

type Fallible<T> = Result<T, Box<dyn std::error::Error>>;

fn main() {
    // SAFETY: `run` destroys every Vulkan object it makes before it returns, children first.
    let (verdict, pass) =
        unsafe { run() }.unwrap_or_else(|e| (format!("minimal example failed: {e}"), false));
    println!("{verdict}");
    std::process::exit(i32::from(!pass));
}

/// Lights one frame; returns the verdict and whether the frame passed.
/// # Safety
/// The Vulkan objects it makes are its own, and it destroys them.
unsafe fn run() -> Fallible<(String, bool)> {
    // The engine's instance; histencil's ValidationLog keeps what the layer says.
    let entry = ash::Entry::load()?;
    let log = Arc::new(ValidationLog::default());
    let sync = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
    let mut features = vk::ValidationFeaturesEXT::default().enabled_validation_features(&sync);
    let app = vk::ApplicationInfo::default().api_version(REQUIREMENTS.api_version);
    let layers = [c"VK_LAYER_KHRONOS_validation".as_ptr()];
    let extensions =
        [ash::ext::debug_utils::NAME.as_ptr(), ash::ext::validation_features::NAME.as_ptr()];
    let instance_info = vk::InstanceCreateInfo::default()
        .application_info(&app)
        .enabled_layer_names(&layers)
        .enabled_extension_names(&extensions)
        .push_next(&mut features);
    let instance = entry.create_instance(&instance_info, None)?;
    let debug = ash::ext::debug_utils::Instance::new(&entry, &instance);
    let messenger =
        debug.create_debug_utils_messenger(&ValidationLog::messenger_create_info(&log), None)?;

    // Its device: the first (named like HISTENCIL_DEVICE) with what histencil requires.
    let filter = std::env::var("HISTENCIL_DEVICE").unwrap_or_default().to_lowercase();
    let (physical_device, queue_family) = (instance.enumerate_physical_devices()?.into_iter())
        .filter(|&pd| {
            let props = instance.get_physical_device_properties(pd);
            let name = props.device_name_as_c_str().unwrap_or_default().to_string_lossy();
            name.to_lowercase().contains(&filter) && REQUIREMENTS.missing(&instance, pd).is_empty()
        })
        .find_map(|pd| {
            (0..8).find(|&f| REQUIREMENTS.queue_family_fits(&instance, pd, f)).map(|f| (pd, f))
        })
        .ok_or("no Vulkan 1.3 device with what histencil requires")?;
    let queues = [vk::DeviceQueueCreateInfo::default()
        .queue_family_index(queue_family)
        .queue_priorities(&[1.0])];
    let (core, mut features13) = (REQUIREMENTS.features(), REQUIREMENTS.features13());
    let device_info = vk::DeviceCreateInfo::default()
        .queue_create_infos(&queues)
        .enabled_features(&core)
        .push_next(&mut features13);
    let device = instance.create_device(physical_device, &device_info, None)?;
    let queue = device.get_device_queue(queue_family, 0);
    let allocator = Arc::new(Mutex::new(Allocator::new(&AllocatorCreateDesc {
        instance: instance.clone(),
        device: device.clone(),
        physical_device,
        debug_settings: Default::default(),
        buffer_device_address: false,
        allocation_sizes: Default::default(),
    })?));

    // Lend it, and make the lighting once: two BRDFs in the talk's stencil layout.
    let ctx = Context::from_raw(BorrowedDevice {
        instance: instance.clone(),
        device: device.clone(),
        physical_device,
        queue_family,
        queue,
        allocator: Some(allocator.clone()),
        debug_utils: true,
        depth_stencil: Some(DepthStencilFormat::D32S8),
        memory_budget: None,
        pipeline_cache: None,
    })?;
    let brdfs = [Brdf::Lambert { rho: 1.0 }, Brdf::Ggx { alpha: 0.25, f0: 0.04, f90: 1.0 }];
    let layout = StencilLayout::new(brdfs.len() as u32, 0)?;
    let desc = LightingDesc {
        layout,
        brdfs: brdfs.iter().map(Brdf::id).collect(),
        extent: EXTENT,
        depth_stencil_format: DEPTH_STENCIL,
        hdr_format: HDR,
        frames_in_flight: 1,
        max_lights: 1,
        hi_stencil: false,
        hooks: LightHooks::Builtin,
    };
    let mut lighting = DeferredLighting::new(&ctx, &desc)?;

    // Its images, and the buffer the HDR image comes back in; `memory` is freed at the end.
    let mut memory: Vec<Allocation> = Vec::new();
    let mut bind = |name, requirements, location| -> Fallible<(vk::DeviceMemory, u64)> {
        let (linear, allocation_scheme) =
            (location != MemoryLocation::GpuOnly, AllocationScheme::GpuAllocatorManaged);
        let desc = AllocationCreateDesc { name, requirements, location, linear, allocation_scheme };
        memory.push(allocator.lock().map_err(|_| "allocator")?.allocate(&desc)?);
        Ok(memory.last().map(|m| (m.memory(), m.offset())).unwrap_or_default())
    };
    let mut image = |name, format, usage| -> Fallible<ImageRef> {
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(format)
            .extent(EXTENT_3D)
            .mip_levels(1)
            .array_layers(1)
            .samples(vk::SampleCountFlags::TYPE_1)
            .usage(usage);
        let image = device.create_image(&info, None)?;
        let (memory, offset) =
            bind(name, device.get_image_memory_requirements(image), MemoryLocation::GpuOnly)?;
        device.bind_image_memory(image, memory, offset)?;
        let view_info = vk::ImageViewCreateInfo::default()
            .image(image)
            .view_type(vk::ImageViewType::TYPE_2D)
            .format(format)
            .subresource_range(whole(aspect_of(format)));
        let view = device.create_image_view(&view_info, None)?;
        Ok(ImageRef { image, view, format, extent: EXTENT, usage, state: ImageState::UNDEFINED })
    };
    use vk::ImageUsageFlags as Usage;
    let mut targets = LightingTargets {
        gbuffer: (["gbuffer-albedo", "gbuffer-normal-depth", "gbuffer-material"].into_iter())
            .zip(GBUFFER_FORMATS)
            .map(|(name, format)| image(name, format, Usage::COLOR_ATTACHMENT | Usage::SAMPLED))
            .collect::<Fallible<_>>()?,
        depth_stencil: image("depth-stencil", DEPTH_STENCIL, Usage::DEPTH_STENCIL_ATTACHMENT)?,
        hdr: image("hdr", HDR, Usage::COLOR_ATTACHMENT | Usage::TRANSFER_SRC)?,
    };
    let size = u64::from(EXTENT.width * EXTENT.height) * 8;
    let buffer_info =
        vk::BufferCreateInfo::default().size(size).usage(vk::BufferUsageFlags::TRANSFER_DST);
    let buffer = device.create_buffer(&buffer_info, None)?;
    let requirements = device.get_buffer_memory_requirements(buffer);
    let (buffer_memory, offset) = bind("hdr-readback", requirements, MemoryLocation::GpuToCpu)?;
    device.bind_buffer_memory(buffer, buffer_memory, offset)?;

    // The camera looks down -Z at the wall; the plan says which light passes draw, in what state.
    let view = Perspective {
        eye: [0.0; 3],
        target: [0.0, 0.0, -1.0],
        up: [0.0, 1.0, 0.0],
        fov_y_radians: 1.0,
        aspect: 1.0,
        near: 0.1,
        far: FarPlane::Finite(100.0),
        depth: DepthConvention::Standard,
    }
    .desc();
    let lights = [Light::point(Vec3::new(0.0, 0.0, 1.0 - WALL), 2.0, Vec3::splat(4.0))];
    let shapes: Vec<LightShape> = lights.iter().map(Light::shape).collect();
    let half = |x0, x1| vec![Aabb { min: [x0, -9.0, -WALL - 0.1], max: [x1, 9.0, 0.1 - WALL] }];
    let bounds = [half(-9.0, 0.0), half(0.0, 9.0)];
    let inputs = PlanInputs { lights: &shapes, brdf_bounds: &bounds, view: &View::new(&view)? };
    let caps = Backend::Native.platform().caps();
    let settings =
        PlanSettings { technique: TechniqueChoice::Stencil, caps, flush: FlushPolicy::Auto };
    let plan = plan_frame(&layout, &inputs, &settings)?;

    // One command buffer: the G-buffer pass, the lighting, the copy back.
    let pool_info = vk::CommandPoolCreateInfo::default().queue_family_index(queue_family);
    let pool = device.create_command_pool(&pool_info, None)?;
    let cmd_info =
        vk::CommandBufferAllocateInfo::default().command_pool(pool).command_buffer_count(1);
    let cmd = device.allocate_command_buffers(&cmd_info)?[0];
    device.begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default())?;
    // The engine's barriers: from an image's tracked state to the next, whose layout it takes.
    let barrier = |image: &mut ImageRef, next: ImageState| {
        let barrier = [vk::ImageMemoryBarrier2::default()
            .src_stage_mask(image.state.stage)
            .src_access_mask(image.state.access)
            .dst_stage_mask(next.stage)
            .dst_access_mask(next.access)
            .old_layout(image.state.layout)
            .new_layout(next.layout)
            .image(image.image)
            .subresource_range(whole(image.aspect()))];
        let dependency = vk::DependencyInfo::default().image_memory_barriers(&barrier);
        device.cmd_pipeline_barrier2(cmd, &dependency);
        image.state = next;
    };
    let attached = ImageState::after(ImageAccess::ColorAttachment);
    let depth_attached = ImageState::after(ImageAccess::DepthStencilAttachment);
    targets.gbuffer.iter_mut().for_each(|image| barrier(image, attached));
    barrier(&mut targets.depth_stencil, depth_attached);
    // The wall's value in the depth buffer: clip z over clip w of a point WALL ahead.
    let m = view.view_to_clip;
    let depth = (m[2][2] * -WALL + m[3][2]) / (m[2][3] * -WALL + m[3][3]);
    for (half, brdf) in brdfs.iter().enumerate() {
        // What `gbuffer_encode` writes: tint and material index, world normal and linear
        // depth, the BRDF's packed parameters and model; the stencil, the BRDF's reference.
        let [a, b, c, _] = brdf.packed_params().map(|x| x as f32);
        let texels =
            [[0.8, 0.8, 0.8, 0.0], [0.0, 0.0, 1.0, WALL], [a, b, c, brdf.model_index() as f32]];
        let (stencil, _) = desc.stencil_reference(brdf.id()).ok_or("a BRDF of the lighting")?;
        let clear = |target: &ImageRef, layout, clear_value| {
            vk::RenderingAttachmentInfo::default()
                .image_view(target.view)
                .image_layout(layout)
                .load_op(vk::AttachmentLoadOp::CLEAR)
                .store_op(vk::AttachmentStoreOp::STORE)
                .clear_value(clear_value)
        };
        let colours: Vec<_> = (targets.gbuffer.iter().zip(texels))
            .map(|(g, float32)| {
                clear(g, attached.layout, vk::ClearValue { color: vk::ClearColorValue { float32 } })
            })
            .collect();
        let depth_stencil = vk::ClearDepthStencilValue { depth, stencil: stencil.into() };
        let ds =
            clear(&targets.depth_stencil, depth_attached.layout, vk::ClearValue { depth_stencil });
        let width = EXTENT.width / 2;
        let offset = vk::Offset2D { x: (half as u32 * width) as i32, y: 0 };
        let area = vk::Rect2D { offset, extent: vk::Extent2D { width, height: EXTENT.height } };
        let rendering = vk::RenderingInfo::default()
            .render_area(area)
            .layer_count(1)
            .color_attachments(&colours)
            .depth_attachment(&ds)
            .stencil_attachment(&ds);
        device.cmd_begin_rendering(cmd, &rendering);
        device.cmd_end_rendering(cmd);
    }
    let frame = LightingFrame {
        slot: 0,
        view: &view,
        lights: &lights,
        plan: &plan,
        clear_hdr: true,
        timestamps: false,
        brdf_source: BrdfSource::Formula,
        tile_stats: false,
        hook_sets: HookSets::default(),
    };
    lighting.record(cmd, &frame, &mut targets)?;
    let copied = ImageState::after(ImageAccess::TransferSource);
    barrier(&mut targets.hdr, copied);
    let layer = vk::ImageSubresourceLayers::default().aspect_mask(targets.hdr.aspect());
    let region = vk::BufferImageCopy::default().image_subresource(layer.layer_count(1));
    let region = region.image_extent(EXTENT_3D);
    device.cmd_copy_image_to_buffer(cmd, targets.hdr.image, copied.layout, buffer, &[region]);
    let to_host = [vk::MemoryBarrier2::default()
        .src_stage_mask(vk::PipelineStageFlags2::COPY)
        .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
        .dst_stage_mask(vk::PipelineStageFlags2::HOST)
        .dst_access_mask(vk::AccessFlags2::HOST_READ)];
    device.cmd_pipeline_barrier2(cmd, &vk::DependencyInfo::default().memory_barriers(&to_host));
    device.end_command_buffer(cmd)?;
    let fence = device.create_fence(&vk::FenceCreateInfo::default(), None)?;
    let submit = vk::SubmitInfo::default().command_buffers(std::slice::from_ref(&cmd));
    device.queue_submit(queue, &[submit], fence)?;
    device.wait_for_fences(&[fence], true, u64::MAX)?;
    lighting.slot_finished(0)?;

    // A pixel is lit when a colour channel is above zero: a positive half float has bits set.
    let hdr = memory.last().and_then(Allocation::mapped_slice).ok_or("a mapped readback")?;
    let lit =
        |x: u32, y: u32| hdr[(y * EXTENT.width + x) as usize * 8..][..6].iter().any(|&b| b != 0);
    let (w, h) = (EXTENT.width, EXTENT.height);
    let count =
        |xs: std::ops::Range<u32>| xs.flat_map(|x| (0..h).filter(move |&y| lit(x, y))).count();
    let (lambert, ggx) = (count(0..w / 2), count(w / 2..w));
    let corners_dark =
        ![(0, 0), (w - 1, 0), (0, h - 1), (w - 1, h - 1)].iter().any(|&(x, y)| lit(x, y));

    // Teardown, children first: histencil's objects, then the engine's.
    drop(lighting);
    drop(ctx);
    device.destroy_fence(fence, None);
    device.destroy_command_pool(pool, None);
    device.destroy_buffer(buffer, None);
    for target in targets.gbuffer.iter().chain([&targets.depth_stencil, &targets.hdr]) {
        device.destroy_image_view(target.view, None);
        device.destroy_image(target.image, None);
    }
    let mut allocator =
        Arc::into_inner(allocator).ok_or("the allocator is shared")?.into_inner()?;
    memory.into_iter().try_for_each(|m| allocator.free(m))?;
    drop(allocator);
    device.destroy_device(None);
    // The layer reports leaked objects when the device is destroyed: count after it.
    let messages = log.len();
    debug.destroy_debug_utils_messenger(messenger, None);
    instance.destroy_instance(None);
    log.problems().iter().for_each(|problem| eprintln!("validation: {problem}"));
    let corners = if corners_dark { "dark" } else { "LIT" };
    let verdict = format!(
        "minimal example: {w}x{h} G-buffer, 2 BRDFs, 1 light: {lambert} lambert and {ggx} ggx \
         pixels lit, corners {corners}, {messages} validation messages"
    );
    Ok((verdict, lambert > 0 && ggx > 0 && corners_dark && messages == 0))
}

/// The one mip level and layer of an image, over `aspect`.
fn whole(aspect: vk::ImageAspectFlags) -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange::default().aspect_mask(aspect).level_count(1).layer_count(1)
}
