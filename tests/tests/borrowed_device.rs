//! histencil on an engine's own device: the test plays the engine (its own instance with the
//! validation layer and synchronisation validation, its own messenger, device and gpu-allocator
//! allocator, created from `histencil_vk::REQUIREMENTS`), lends them through
//! `Context::from_raw`, renders, and destroys everything itself afterwards. The frames must equal
//! an owned context's bit for bit, nothing of the engine's may be destroyed by histencil, and the
//! engine's messenger must see no message, leak reports at its `vkDestroyDevice` included.

use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};
use histencil_tests::{render, with_validated_context};
use histencil_vk::{
    Backend, BorrowedDevice, Context, FlushPolicy, Readback, Technique, ValidationLog, REQUIREMENTS,
};
use std::sync::{Arc, Mutex};

const SIZE: u32 = 96;

/// The engine's side: what it created, in creation order.
struct Engine {
    _entry: ash::Entry,
    instance: ash::Instance,
    debug: ash::ext::debug_utils::Instance,
    messenger: vk::DebugUtilsMessengerEXT,
    physical_device: vk::PhysicalDevice,
    queue_family: u32,
    device: ash::Device,
    allocator: Arc<Mutex<Allocator>>,
    log: Arc<ValidationLog>,
}

impl Engine {
    fn new() -> Self {
        let entry = unsafe { ash::Entry::load() }.expect("Vulkan loader");
        let log = Arc::new(ValidationLog::default());
        let app = vk::ApplicationInfo::default().api_version(REQUIREMENTS.api_version);
        let layers = [c"VK_LAYER_KHRONOS_validation".as_ptr()];
        let extensions = [
            ash::ext::debug_utils::NAME.as_ptr(),
            ash::ext::validation_features::NAME.as_ptr(),
        ];
        let enables = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
        let mut features =
            vk::ValidationFeaturesEXT::default().enabled_validation_features(&enables);
        // SAFETY: `log` lives in the engine until after the messenger is destroyed.
        let messenger_info = unsafe { ValidationLog::messenger_create_info(&log) };
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
            _entry: entry,
            instance,
            debug,
            messenger,
            physical_device,
            queue_family,
            device,
            allocator: Arc::new(Mutex::new(allocator)),
            log,
        }
    }

    fn lend(&self, queue_family: u32) -> BorrowedDevice {
        BorrowedDevice {
            instance: self.instance.clone(),
            device: self.device.clone(),
            physical_device: self.physical_device,
            queue_family,
            queue: unsafe { self.device.get_device_queue(self.queue_family, 0) },
            allocator: self.allocator.clone(),
            debug_utils: true,
            depth_stencil: None,
        }
    }

    /// Destroys everything in reverse order; returns the messenger's log.
    fn destroy(self) -> Arc<ValidationLog> {
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

#[test]
fn an_engines_device_renders_what_histencils_own_renders() {
    let scene = histencil_scene::embedded("default").unwrap();
    let techniques = [
        Technique::Forward,
        Technique::Stencil {
            backend: Backend::Ps3,
            flush: FlushPolicy::Auto,
        },
    ];
    let owned: Vec<_> = with_validated_context(|ctx| {
        assert!(ctx.owns_device());
        techniques
            .iter()
            .map(|&t| {
                render(ctx, &scene, t, SIZE, Readback::ALL)
                    .images
                    .ldr
                    .unwrap()
            })
            .collect()
    });

    let engine = Engine::new();
    {
        // SAFETY: the engine's handles outlive the context, its device has REQUIREMENTS'
        // features and nothing else uses its queue meanwhile.
        let ctx = unsafe { Context::from_raw(engine.lend(engine.queue_family)) }.expect("context");
        assert!(!ctx.owns_device());
        for (technique, expected) in techniques.iter().zip(&owned) {
            let frame = render(&ctx, &scene, *technique, SIZE, Readback::ALL);
            assert!(
                frame.images.ldr.as_ref() == Some(expected),
                "{technique:?}: the lent device rendered another image"
            );
        }
        assert!(ctx.validation_log().is_empty(), "messages go to the engine");
    }
    // The engine's device still works after histencil is gone.
    unsafe { engine.device.device_wait_idle() }.expect("the engine's device is alive");
    engine.destroy().assert_clean();
}

#[test]
fn a_lent_queue_family_that_does_not_exist_is_refused() {
    let engine = Engine::new();
    let err = unsafe { Context::from_raw(engine.lend(1000)) }
        .err()
        .expect("an error");
    assert!(err.to_string().contains("queue family 1000"), "{err}");
    engine.destroy().assert_clean();
}
