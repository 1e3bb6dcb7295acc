//! An owned context, as histencil's own tools make it ([`Context::new`]): the loader, the
//! instance with the validation layer when asked for, the device picked by `HISTENCIL_DEVICE`,
//! its depth-stencil format and the allocator; each step undone if a later one fails.

use super::{Context, ContextDesc, DepthStencilFormat, MemoryAccount, VALIDATION_LAYER};
use crate::gpu::device::debug::ValidationLog;
use crate::gpu::device::error::{Error, Result, VkCall};
use crate::gpu::device::requirements::REQUIREMENTS;
use ash::vk;
use std::ffi::CStr;
use std::mem::ManuallyDrop;
use std::sync::{Arc, Mutex};

/// The format `wanted` names, or the first the device has; [`Error::MissingFormat`] when the
/// device cannot attach it (or either).
pub(super) fn pick_depth_stencil_format(
    instance: &ash::Instance,
    pd: vk::PhysicalDevice,
    wanted: Option<DepthStencilFormat>,
) -> Result<DepthStencilFormat> {
    // Sampled: the hi-stencil emulation reads the stencil through a stencil-aspect view.
    let needed = vk::FormatFeatureFlags::DEPTH_STENCIL_ATTACHMENT
        | vk::FormatFeatureFlags::TRANSFER_SRC
        | vk::FormatFeatureFlags::SAMPLED_IMAGE;
    let candidates = match wanted {
        Some(f) => vec![f],
        None => DepthStencilFormat::ALL.to_vec(),
    };
    candidates
        .iter()
        .copied()
        .find(|f| {
            // SAFETY: both callers pass a `pd` of the live `instance`: `Context::new` enumerated
            // it, and `from_raw`'s caller promises it.
            let props = unsafe { instance.get_physical_device_format_properties(pd, f.vk()) };
            props.optimal_tiling_features.contains(needed)
        })
        .ok_or_else(|| {
            let names: Vec<_> = candidates.iter().map(|f| f.vk_name()).collect();
            Error::MissingFormat(format!(
                "the device cannot use {} as a depth-stencil attachment copied out and sampled",
                names.join(" or ")
            ))
        })
}

/// What `Context::new` has created so far, destroyed in reverse order if a later step fails:
/// a failed `Context::new` leaks nothing (the device, the messenger and the instance included).
struct Partial {
    instance: Option<ash::Instance>,
    debug_instance: Option<ash::ext::debug_utils::Instance>,
    messenger: vk::DebugUtilsMessengerEXT,
    device: Option<ash::Device>,
}

impl Drop for Partial {
    fn drop(&mut self) {
        // SAFETY: every handle here was created by `Context::new` and nothing else holds it: a
        // successful `new` takes them out (leaving `None` / null) before this runs. The device
        // has no child objects yet (nothing is created on it before the allocator, the last
        // step that can fail) and no queue work; the device and the messenger go before the
        // instance they belong to. `entry` (the loader) and `validation` (the messengers' user
        // data) are declared before the `Partial`, so they are dropped after it.
        unsafe {
            if let Some(device) = self.device.take() {
                device.destroy_device(None);
            }
            if let Some(di) = &self.debug_instance {
                if self.messenger != vk::DebugUtilsMessengerEXT::null() {
                    di.destroy_debug_utils_messenger(self.messenger, None);
                }
            }
            if let Some(instance) = self.instance.take() {
                instance.destroy_instance(None);
            }
        }
    }
}

impl Context {
    /// histencil's own instance and device, as `desc` asks: what its tools and tests light with.
    ///
    /// # Errors
    /// [`Error::Loading`] without a Vulkan loader (or, asked for, the validation layer);
    /// [`Error::NoDevice`] when no device meets [`REQUIREMENTS`] (or matches the filter);
    /// [`Error::MissingFormat`] when it cannot attach the depth-stencil format asked for.
    pub fn new(desc: ContextDesc) -> Result<Self> {
        // SAFETY: dlopen of the system's Vulkan loader, trusted as every Vulkan program trusts
        // it; the `Entry` keeps the library loaded for as long as the context holds it, past
        // the last call through the instance and device it hands out (see `Drop`).
        let entry = unsafe { ash::Entry::load() }.map_err(|e| Error::Loading(e.to_string()))?;
        // SAFETY: a global command of the loader just loaded; `None` asks for the extensions of
        // the implementation and the implicit layers.
        let available_exts = unsafe { entry.enumerate_instance_extension_properties(None) }
            .call("vkEnumerateInstanceExtensionProperties")?;
        let has_ext = |name: &CStr| {
            available_exts
                .iter()
                .any(|e| e.extension_name_as_c_str() == Ok(name))
        };
        let debug_utils = has_ext(ash::ext::debug_utils::NAME) || desc.validation;
        let mut layer_text = None;
        let mut layer_settings_ext = false;
        if desc.validation {
            // SAFETY: a global command of the loaded loader, taking no handle.
            let layers = unsafe { entry.enumerate_instance_layer_properties() }
                .call("vkEnumerateInstanceLayerProperties")?;
            let Some(layer) = layers
                .iter()
                .find(|l| l.layer_name_as_c_str() == Ok(VALIDATION_LAYER))
            else {
                return Err(Error::Loading(
                    "validation requested but VK_LAYER_KHRONOS_validation is not installed \
                     (tools/setup installs vulkan-validationlayers)"
                        .into(),
                ));
            };
            layer_text = Some(crate::gpu::device::driver::layer_version(layer));
            // SAFETY: a global command; `VALIDATION_LAYER` is a NUL-terminated `'static` name
            // of a layer found installed just above.
            let layer_exts =
                unsafe { entry.enumerate_instance_extension_properties(Some(VALIDATION_LAYER)) }
                    .call("vkEnumerateInstanceExtensionProperties")?;
            layer_settings_ext = layer_exts
                .iter()
                .any(|e| e.extension_name_as_c_str() == Ok(ash::ext::layer_settings::NAME));
        }

        let app_name = c"histencil";
        let app_info = vk::ApplicationInfo::default()
            .application_name(app_name)
            .engine_name(app_name)
            .api_version(vk::API_VERSION_1_3);
        let mut extensions = Vec::new();
        if debug_utils {
            extensions.push(ash::ext::debug_utils::NAME.as_ptr());
        }
        let mut layers = Vec::new();
        let mut enabled_features = vec![vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
        if desc.best_practices {
            enabled_features.push(vk::ValidationFeatureEnableEXT::BEST_PRACTICES);
        }
        let mut validation_features =
            vk::ValidationFeaturesEXT::default().enabled_validation_features(&enabled_features);
        if desc.validation {
            layers.push(VALIDATION_LAYER.as_ptr());
            extensions.push(ash::ext::validation_features::NAME.as_ptr());
        }
        // The settings a validation verdict rests on, pinned where the layer takes settings
        // through the API (VK_EXT_layer_settings, layers from 1.3.268 on): no duplicate-message
        // limit, synchronisation validation on. The layer lets its environment variables
        // override these; `histencil check` clears them for its workers, and its canary
        // ([`Context::validation_canary`]) proves what is in force.
        let (off, on): (vk::Bool32, vk::Bool32) = (vk::FALSE, vk::TRUE);
        // ash's `values` counts bytes; a BOOL32 setting holds one value.
        let bool_setting = |name: &'static CStr, value: &vk::Bool32| {
            let mut setting = vk::LayerSettingEXT::default()
                .layer_name(VALIDATION_LAYER)
                .setting_name(name)
                .ty(vk::LayerSettingTypeEXT::BOOL32);
            setting.value_count = 1;
            setting.p_values = (value as *const vk::Bool32).cast();
            setting
        };
        let pinned = [
            bool_setting(c"enable_message_limit", &off),
            bool_setting(c"validate_sync", &on),
        ];
        let mut layer_settings = vk::LayerSettingsCreateInfoEXT::default().settings(&pinned);
        let pin_settings = desc.validation && layer_settings_ext;
        if pin_settings {
            extensions.push(ash::ext::layer_settings::NAME.as_ptr());
        }
        // By name: two uses of a const need not share an address.
        let extensions_without: Vec<_> = extensions
            .iter()
            .copied()
            // SAFETY: every pointer in `extensions` is `as_ptr` of a `'static` NUL-terminated
            // extension name (`ash::ext::*::NAME`).
            .filter(|&e| unsafe { CStr::from_ptr(e) } != ash::ext::layer_settings::NAME)
            .collect();
        let validation = Arc::new(ValidationLog::default());
        // SAFETY: `validation` outlives every messenger made from this info: the one chained into
        // instance creation (called until vkDestroyInstance) and the one created below. On an
        // error `partial`, declared after `validation`, destroys both first; the context keeps
        // its `Arc` until after its Drop has destroyed the messenger and the instance.
        let messenger_info = unsafe { ValidationLog::messenger_create_info(&validation) };
        // Chained into instance creation too, so messages from vkCreateInstance are caught.
        let mut messenger_for_create = messenger_info;
        let mut instance_info = vk::InstanceCreateInfo::default()
            .application_info(&app_info)
            .enabled_extension_names(&extensions)
            .enabled_layer_names(&layers);
        if desc.validation {
            instance_info = instance_info
                .push_next(&mut validation_features)
                .push_next(&mut messenger_for_create);
        }
        let without_settings = instance_info;
        if pin_settings {
            instance_info = instance_info.push_next(&mut layer_settings);
        }
        // A layer newer than the loader (an SDK's layer over a distribution's loader, say) offers
        // VK_EXT_layer_settings, and a loader that predates the extension refuses it at
        // vkCreateInstance. Then the settings stay pinned as they are for layers without the
        // extension (the check's settings file, its cleared environment, its canary), and the
        // report says so.
        let mut settings_way = "through VK_EXT_layer_settings".to_owned();
        let mark = validation.len();
        // SAFETY: `instance_info` and all it points at live until the call returns: `app_info`,
        // the `'static` layer and extension names, and the chained `validation_features`,
        // `messenger_for_create` and `layer_settings` (whose `p_values` point at `off` / `on`,
        // alive to the end of `new`). A layer or extension missing fails the call with an error
        // (ERROR_EXTENSION_NOT_PRESENT, the retry below), not undefined behaviour.
        let created = unsafe { entry.create_instance(&instance_info, None) };
        let instance = match created {
            Err(vk::Result::ERROR_EXTENSION_NOT_PRESENT) if pin_settings => {
                // The loader says why on the messenger chained in (`loader_validate_instance_
                // extensions: Extension VK_EXT_layer_settings not found`): a refusal of a call
                // that is retried, stated here instead, not a message about histencil's use.
                let refusals =
                    validation.forget_since(mark, |m| m.text.contains("VK_EXT_layer_settings"));
                settings_way = format!(
                    "from the environment (the loader refused VK_EXT_layer_settings{})",
                    if refusals > 0 {
                        format!("; its {refusals} message(s) saying so are not counted")
                    } else {
                        String::new()
                    }
                );
                let retry = without_settings.enabled_extension_names(&extensions_without);
                // SAFETY: as the first try: the same live structs, less VK_EXT_layer_settings
                // (`without_settings` was copied before `layer_settings` joined the chain).
                unsafe { entry.create_instance(&retry, None) }
            }
            other => {
                if !pin_settings {
                    settings_way =
                        "from the environment (the layer lacks VK_EXT_layer_settings)".to_owned();
                }
                other
            }
        }
        .call("vkCreateInstance")?;
        let layer_text = layer_text.map(|t| format!("{t}, settings {settings_way}"));
        let mut partial = Partial {
            instance: Some(instance.clone()),
            debug_instance: None,
            messenger: vk::DebugUtilsMessengerEXT::null(),
            device: None,
        };
        if debug_utils {
            let di = ash::ext::debug_utils::Instance::new(&entry, &instance);
            // A fresh copy: messenger_for_create's pNext was rewritten by push_next.
            if desc.validation {
                // SAFETY: `di` is loaded from the live `instance`, which enables
                // VK_EXT_debug_utils (`debug_utils` is true); `messenger_info` is a fresh copy
                // with no pNext, and its user data `validation` outlives the messenger (above).
                partial.messenger =
                    unsafe { di.create_debug_utils_messenger(&messenger_info, None) }
                        .call("vkCreateDebugUtilsMessengerEXT")?;
            }
            partial.debug_instance = Some(di);
        }

        let filter = desc.device_filter.clone().or_else(|| {
            std::env::var("HISTENCIL_DEVICE")
                .ok()
                .filter(|s| !s.is_empty())
        });
        let (physical_device, queue_family, device_name) =
            Self::pick_physical_device(&instance, filter.as_deref())?;
        let depth_stencil =
            pick_depth_stencil_format(&instance, physical_device, desc.depth_stencil)?;

        let priorities = [1.0];
        let queue_infos = [vk::DeviceQueueCreateInfo::default()
            .queue_family_index(queue_family)
            .queue_priorities(&priorities)];
        // The depth bounds test, where the device has it and the caller does not decline it:
        // light passes confined to their light's depth range (histencil_model::depth_bounds).
        // SAFETY: `physical_device` was enumerated from `instance`.
        let depth_bounds = !desc.without_depth_bounds
            && unsafe { instance.get_physical_device_features(physical_device) }.depth_bounds
                == vk::TRUE;
        let features = REQUIREMENTS.features().depth_bounds(depth_bounds);
        let mut features13 = REQUIREMENTS.features13();
        let device_info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queue_infos)
            .enabled_features(&features)
            .push_next(&mut features13);
        // SAFETY: `physical_device` is `instance`'s and passed `REQUIREMENTS.missing`, so it has
        // every feature asked for (`depthBounds` only where it reported it); `queue_family`
        // fits, one queue at priority 1.0. `device_info` and the arrays and `features13` it
        // points at live until the call returns.
        let device = unsafe { instance.create_device(physical_device, &device_info, None) }
            .call("vkCreateDevice")?;
        partial.device = Some(device.clone());
        // SAFETY: queue 0 of `queue_family` is the one queue `queue_infos` asked for.
        let queue = unsafe { device.get_device_queue(queue_family, 0) };
        let debug_device =
            debug_utils.then(|| ash::ext::debug_utils::Device::new(&instance, &device));

        let allocator =
            super::make_allocator(&instance, &device, physical_device, Default::default())?;

        // From here the context owns every handle and its Drop destroys them.
        partial.device = None;
        partial.instance = None;
        let debug_instance = partial.debug_instance.take();
        let messenger =
            std::mem::replace(&mut partial.messenger, vk::DebugUtilsMessengerEXT::null());
        // SAFETY: `physical_device` was enumerated from `instance`.
        let props = unsafe { instance.get_physical_device_properties(physical_device) };
        let limits = props.limits;
        // SAFETY: `driver_info`'s # Safety: `physical_device` is `instance`'s, the instance was
        // created for Vulkan 1.3, and the device supports 1.3 (it passed `REQUIREMENTS.missing`).
        let mut driver = unsafe {
            crate::gpu::device::driver::driver_info(&instance, physical_device, layer_text)
        };
        let quirks = if desc.general_path {
            crate::gpu::device::quirks::Quirks::none()
        } else {
            crate::gpu::device::quirks::Quirks::of(
                crate::gpu::device::quirks::QUIRKS,
                driver.id,
                driver.version,
            )
        };
        let device_limits = crate::gpu::device::limits::DeviceLimits::new(&limits);
        let device_limits = if desc.spec_minimum_limits {
            device_limits.at_spec_minimum()
        } else {
            device_limits
        };
        driver.limits =
            crate::gpu::device::limits::describe(crate::gpu::device::limits::NEEDS, &device_limits);
        if desc.spec_minimum_limits {
            driver
                .limits
                .push_str(" (capped at the spec's minimums, asked for)");
        }
        driver.quirks = if desc.general_path {
            "none (the general path, asked for)".into()
        } else {
            quirks.describe()
        };
        // A cache of histencil's own, destroyed with the device; without one (a driver that
        // refuses) pipelines are made uncached.
        // SAFETY: `device` is live; the default create info has no initial data to validate.
        let pipeline_cache =
            unsafe { device.create_pipeline_cache(&vk::PipelineCacheCreateInfo::default(), None) }
                .unwrap_or_default();
        let hazards = std::sync::OnceLock::new();
        if cfg!(debug_assertions) && desc.validation {
            let _ = hazards.set(crate::gpu::device::hazards::Hazards::new(
                validation.clone(),
            ));
        }
        let ctx = Self {
            _entry: Some(entry),
            owned: true,
            instance,
            physical_device,
            device,
            queue,
            queue_family,
            allocator: ManuallyDrop::new(Arc::new(Mutex::new(allocator))),
            debug_instance,
            debug_device,
            messenger,
            validation,
            device_name,
            device_type: props.device_type,
            driver,
            pipeline_cache,
            depth_stencil_format: depth_stencil.vk(),
            depth_stencil,
            depth_stencil_named: desc.depth_stencil.is_some(),
            timestamp_period_ns: f64::from(limits.timestamp_period),
            max_image_dimension: limits.max_image_dimension2_d,
            max_storage_buffer_range: limits.max_storage_buffer_range,
            limits: device_limits,
            limits_used: Default::default(),
            set_counts: Default::default(),
            queue_lock: Mutex::new(()),
            steps: Default::default(),
            depth_bounds,
            quirks,
            memory: MemoryAccount::new(desc.memory_budget),
            retired: Mutex::default(),
            hazards,
            buffer_uses: Mutex::default(),
        };
        ctx.name(ctx.device.handle(), "histencil-device");
        if ctx.pipeline_cache != vk::PipelineCache::null() {
            ctx.name(ctx.pipeline_cache, "histencil-pipeline-cache");
        }
        ctx.name(ctx.queue, "graphics-queue");
        Ok(ctx)
    }

    fn pick_physical_device(
        instance: &ash::Instance,
        filter: Option<&str>,
    ) -> Result<(vk::PhysicalDevice, u32, String)> {
        // SAFETY: `instance` is live (the caller's, created just before).
        let devices =
            unsafe { instance.enumerate_physical_devices() }.call("vkEnumeratePhysicalDevices")?;
        let mut candidates = Vec::new();
        let mut seen = Vec::new();
        for pd in devices {
            // SAFETY: `pd` was just enumerated from the live `instance`.
            let props = unsafe { instance.get_physical_device_properties(pd) };
            let name = props
                .device_name_as_c_str()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            seen.push(name.clone());
            // SAFETY: `missing`'s # Safety: `pd` was just enumerated from the live `instance`,
            // which `Context::new` created for Vulkan 1.3.
            if !unsafe { REQUIREMENTS.missing(instance, pd) }.is_empty() {
                continue;
            }
            // SAFETY: as above.
            let families = unsafe { instance.get_physical_device_queue_family_properties(pd) };
            let Some(family) = (0..families.len() as u32)
                // SAFETY: `queue_family_fits`'s # Safety: `pd` was enumerated from `instance`.
                .find(|&f| unsafe { REQUIREMENTS.queue_family_fits(instance, pd, f) })
            else {
                continue;
            };
            if let Some(f) = filter {
                if !name.to_lowercase().contains(&f.to_lowercase()) {
                    continue;
                }
            }
            let rank = match props.device_type {
                vk::PhysicalDeviceType::DISCRETE_GPU => 0,
                vk::PhysicalDeviceType::INTEGRATED_GPU => 1,
                vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
                _ => 3,
            };
            candidates.push((rank, pd, family, name));
        }
        candidates.sort_by_key(|c| c.0);
        candidates
            .into_iter()
            .next()
            .map(|(_, pd, family, name)| (pd, family, name))
            .ok_or_else(|| {
                Error::NoDevice(format!(
                    "{}devices seen: [{}]",
                    filter
                        .map(|f| format!("none matches HISTENCIL_DEVICE=`{f}`; "))
                        .unwrap_or_default(),
                    seen.join(", ")
                ))
            })
    }
}
