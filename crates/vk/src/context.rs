//! The Vulkan context: instance, device, queue, memory allocator, validation log and the naming /
//! labelling helpers every other module uses. Owned ([`Context::new`], for histencil's tools) or
//! lent by an engine ([`Context::from_raw`]), which keeps its device, allocator and messenger.

use crate::debug::ValidationLog;
use crate::error::{Error, Result, VkCall};
use crate::requirements::REQUIREMENTS;
use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};
use std::ffi::{CStr, CString};
use std::mem::ManuallyDrop;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";
/// The longest histencil waits for the device to finish a submission before it gives up with
/// `VK_TIMEOUT` as the error: a hung or lost device is an error, never an endless wait. Far
/// above any frame's time on a CPU rasteriser (the longest, 1280x720 `town` on lavapipe, takes
/// seconds).
pub(crate) const FENCE_TIMEOUT_NS: u64 = 300_000_000_000;

/// The depth-stencil formats the renderer can use: both have the 8 stencil bits the talk's
/// layouts need. The depth precision differs (float against 24-bit fixed point), and engines
/// ship on both, so `histencil check` runs its matrix on each the device has.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum DepthStencilFormat {
    /// `VK_FORMAT_D32_SFLOAT_S8_UINT`.
    D32S8,
    /// `VK_FORMAT_D24_UNORM_S8_UINT`.
    D24S8,
}

impl DepthStencilFormat {
    /// Both, in the order a device's format is probed when none is asked for.
    pub const ALL: [DepthStencilFormat; 2] = [DepthStencilFormat::D32S8, DepthStencilFormat::D24S8];

    pub fn vk(self) -> vk::Format {
        match self {
            DepthStencilFormat::D32S8 => vk::Format::D32_SFLOAT_S8_UINT,
            DepthStencilFormat::D24S8 => vk::Format::D24_UNORM_S8_UINT,
        }
    }

    /// The Vulkan name, e.g. `D32_SFLOAT_S8_UINT`.
    pub fn vk_name(self) -> &'static str {
        match self {
            DepthStencilFormat::D32S8 => "D32_SFLOAT_S8_UINT",
            DepthStencilFormat::D24S8 => "D24_UNORM_S8_UINT",
        }
    }
}

/// How to build a [`Context`].
#[derive(Clone, Debug, Default)]
pub struct ContextDesc {
    /// Enable the Khronos validation layer with synchronisation validation.
    pub validation: bool,
    /// With `validation`: the layer's best-practices checks too (they warn about legal but slow
    /// usage, so a clean run is a stronger claim and a noisier one).
    pub best_practices: bool,
    /// Pick the first device whose name contains this (case-insensitive). `None` reads the
    /// `HISTENCIL_DEVICE` environment variable; without it, a discrete GPU is preferred.
    pub device_filter: Option<String>,
    /// The depth-stencil format to render with; `None` takes the first of
    /// [`DepthStencilFormat::ALL`] the device can attach. A requested format the device lacks
    /// is [`Error::MissingFormat`].
    pub depth_stencil: Option<DepthStencilFormat>,
    /// The most device memory, in bytes, histencil's objects may hold at once; `None`: no
    /// limit but the device's. An allocation past it fails with [`Error::Allocation`], as one
    /// past the device's memory would.
    pub memory_budget: Option<u64>,
}

impl ContextDesc {
    /// Validation on, device from `HISTENCIL_DEVICE` or the default choice: what tests use.
    pub fn validated() -> Self {
        Self {
            validation: true,
            ..Self::default()
        }
    }
}

/// An engine's device, lent to histencil: the handles the engine created, which it keeps and
/// destroys itself after every histencil object made with them.
pub struct BorrowedDevice {
    pub instance: ash::Instance,
    pub device: ash::Device,
    pub physical_device: vk::PhysicalDevice,
    /// The family of `queue`; it must fit [`REQUIREMENTS`].
    pub queue_family: u32,
    pub queue: vk::Queue,
    /// The engine's allocator for `device`; histencil's allocations are named `histencil`-side
    /// and freed before its objects are dropped.
    pub allocator: Arc<Mutex<Allocator>>,
    /// `VK_EXT_debug_utils` is enabled on `instance`: histencil then names its objects and
    /// labels its passes (the engine's messenger receives any validation message).
    pub debug_utils: bool,
    /// As [`ContextDesc::depth_stencil`]. When named, [`crate::DeferredLighting::new`] refuses
    /// a [`crate::LightingDesc::depth_stencil_format`] that differs, so the format cannot mean
    /// two things; `None` leaves the lighting's format the only one that counts.
    pub depth_stencil: Option<DepthStencilFormat>,
    /// As [`ContextDesc::memory_budget`]: the share of the engine's memory histencil may take.
    pub memory_budget: Option<u64>,
    /// The engine's pipeline cache, for every pipeline histencil makes on this device (light
    /// volumes, the tiled kernels, the hi-stencil emulation, lightmaps): warm from an earlier
    /// run or lighting, it spares their compilation. `None`: no cache. The engine keeps it, and
    /// its external synchronisation: histencil creates pipelines only inside its own calls.
    pub pipeline_cache: Option<vk::PipelineCache>,
}

/// One Vulkan device and what hangs off it. Dropping an owned context waits for the device, frees
/// the allocator, destroys the device (the validation layer reports leaked objects then) and the
/// instance; dropping a borrowed one destroys nothing of the engine's.
pub struct Context {
    /// Keeps the loader loaded; `None` when the engine's instance is borrowed.
    _entry: Option<ash::Entry>,
    /// Whether the instance, device, messenger and allocator are histencil's to destroy.
    owned: bool,
    pub(crate) instance: ash::Instance,
    pub(crate) device: ash::Device,
    pub(crate) queue: vk::Queue,
    pub(crate) queue_family: u32,
    pub(crate) allocator: ManuallyDrop<Arc<Mutex<Allocator>>>,
    debug_instance: Option<ash::ext::debug_utils::Instance>,
    debug_device: Option<ash::ext::debug_utils::Device>,
    messenger: vk::DebugUtilsMessengerEXT,
    validation: Arc<ValidationLog>,
    device_name: String,
    device_type: vk::PhysicalDeviceType,
    driver: crate::driver::DriverInfo,
    /// Every pipeline's cache: the engine's (borrowed), or histencil's own on an owned device,
    /// so that a second renderer or lighting on one context reuses the first's compilations.
    pub(crate) pipeline_cache: vk::PipelineCache,
    pub(crate) depth_stencil_format: vk::Format,
    depth_stencil: DepthStencilFormat,
    /// The depth-stencil format was named when the context was made (not picked for it): the
    /// lighting's targets must then be in it.
    pub(crate) depth_stencil_named: bool,
    pub(crate) timestamp_period_ns: f64,
    pub(crate) max_image_dimension: u32,
    pub(crate) max_storage_buffer_range: u32,
    /// How many descriptor sets a pipeline layout may hold (an engine's visibility hook needs 5).
    pub(crate) max_bound_descriptor_sets: u32,
    pub(crate) memory: MemoryAccount,
}

/// The device memory histencil's allocations hold, against the budget the context was given.
#[derive(Debug, Default)]
pub(crate) struct MemoryAccount {
    budget: Option<u64>,
    in_use: AtomicU64,
    peak: AtomicU64,
}

impl MemoryAccount {
    fn new(budget: Option<u64>) -> Self {
        Self {
            budget,
            in_use: AtomicU64::new(0),
            peak: AtomicU64::new(0),
        }
    }

    /// Counts `bytes` more as held, or says why not: they would pass the budget.
    pub fn reserve(&self, bytes: u64) -> std::result::Result<(), String> {
        let mut held = self.in_use.load(Ordering::Relaxed);
        loop {
            let after = held.saturating_add(bytes);
            if let Some(budget) = self.budget.filter(|&b| after > b) {
                return Err(format!(
                    "{bytes} bytes would pass the context's memory budget of {budget} bytes \
                     ({held} held)"
                ));
            }
            match self.in_use.compare_exchange_weak(
                held,
                after,
                Ordering::Relaxed,
                Ordering::Relaxed,
            ) {
                Ok(_) => {
                    self.peak.fetch_max(after, Ordering::Relaxed);
                    return Ok(());
                }
                Err(now) => held = now,
            }
        }
    }

    /// Counts `bytes` as no longer held.
    pub fn release(&self, bytes: u64) {
        self.in_use.fetch_sub(bytes, Ordering::Relaxed);
    }
}

/// The format `wanted` names, or the first the device has; [`Error::MissingFormat`] when the
/// device cannot attach it (or either).
fn pick_depth_stencil_format(
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
            // SAFETY: `pd` was enumerated from `instance`, which is alive.
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
        // successful `new` takes them out (leaving `None` / null) before this runs.
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
    pub fn new(desc: ContextDesc) -> Result<Self> {
        // SAFETY: loading the system Vulkan loader; nothing else runs inside it yet.
        let entry = unsafe { ash::Entry::load() }.map_err(|e| Error::Loading(e.to_string()))?;
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
            layer_text = Some(crate::driver::layer_version(layer));
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
        let validation = Arc::new(ValidationLog::default());
        // SAFETY: the context keeps `validation` until after it destroys the messenger.
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
        if pin_settings {
            instance_info = instance_info.push_next(&mut layer_settings);
        }
        let instance =
            unsafe { entry.create_instance(&instance_info, None) }.call("vkCreateInstance")?;
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
        let features = REQUIREMENTS.features();
        let mut features13 = REQUIREMENTS.features13();
        let device_info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queue_infos)
            .enabled_features(&features)
            .push_next(&mut features13);
        let device = unsafe { instance.create_device(physical_device, &device_info, None) }
            .call("vkCreateDevice")?;
        partial.device = Some(device.clone());
        let queue = unsafe { device.get_device_queue(queue_family, 0) };
        let debug_device =
            debug_utils.then(|| ash::ext::debug_utils::Device::new(&instance, &device));

        let allocator = Allocator::new(&AllocatorCreateDesc {
            instance: instance.clone(),
            device: device.clone(),
            physical_device,
            debug_settings: Default::default(),
            buffer_device_address: false,
            allocation_sizes: Default::default(),
        })
        .map_err(|e| Error::Allocation {
            name: "allocator".into(),
            message: e.to_string(),
        })?;

        // From here the context owns every handle and its Drop destroys them.
        partial.device = None;
        partial.instance = None;
        let debug_instance = partial.debug_instance.take();
        let messenger =
            std::mem::replace(&mut partial.messenger, vk::DebugUtilsMessengerEXT::null());
        // SAFETY: `physical_device` was enumerated from `instance`.
        let props = unsafe { instance.get_physical_device_properties(physical_device) };
        let limits = props.limits;
        // SAFETY: as above; the instance asks for Vulkan 1.3.
        let driver = unsafe { crate::driver::driver_info(&instance, physical_device, layer_text) };
        // A cache of histencil's own, destroyed with the device; without one (a driver that
        // refuses) pipelines are made uncached.
        let pipeline_cache =
            unsafe { device.create_pipeline_cache(&vk::PipelineCacheCreateInfo::default(), None) }
                .unwrap_or_default();
        let ctx = Self {
            _entry: Some(entry),
            owned: true,
            instance,
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
            max_bound_descriptor_sets: limits.max_bound_descriptor_sets,
            memory: MemoryAccount::new(desc.memory_budget),
        };
        ctx.name(ctx.device.handle(), "histencil-device");
        if ctx.pipeline_cache != vk::PipelineCache::null() {
            ctx.name(ctx.pipeline_cache, "histencil-pipeline-cache");
        }
        ctx.name(ctx.queue, "graphics-queue");
        Ok(ctx)
    }

    /// A context on an engine's device. Nothing is created but the debug-utils function table;
    /// dropping the context destroys nothing of the engine's. Validation messages go to the
    /// engine's messenger ([`ValidationLog::messenger_create_info`] routes them into a log), so
    /// [`Context::validation_log`] stays empty.
    ///
    /// # Errors
    /// [`Error::NoDevice`] when the physical device or the queue family lacks what
    /// [`REQUIREMENTS`] asks; [`Error::MissingFormat`] as [`Context::new`].
    ///
    /// # Safety
    /// The caller guarantees that:
    /// - every handle in `lent` is valid and outlives this context and everything made with it;
    /// - `device` was created from `physical_device` of `instance` with at least the features of
    ///   [`REQUIREMENTS`] enabled, and `queue` is a queue of `queue_family` on it;
    /// - `allocator` was created for `device`;
    /// - `debug_utils` is true only if `VK_EXT_debug_utils` is enabled on `instance`;
    /// - while histencil's owned-device tools ([`crate::Renderer`]) submit to `queue` and wait,
    ///   nothing else uses that queue (Vulkan requires queues to be externally synchronised);
    /// - while a [`crate::DeferredLighting`] or [`crate::AlphaLightmaps`] that has recorded, or a
    ///   [`crate::LutTables`], is dropped, nothing else uses any queue of the device: dropping
    ///   waits for the device to go idle. Their `unsafe fn destroy` frees without that wait.
    ///
    /// The engine-facing parts submit nothing themselves: making, recording and reading them
    /// never touches a queue.
    pub unsafe fn from_raw(lent: BorrowedDevice) -> Result<Self> {
        let BorrowedDevice {
            instance,
            device,
            physical_device,
            queue_family,
            queue,
            allocator,
            debug_utils,
            depth_stencil,
            memory_budget,
            pipeline_cache,
        } = lent;
        // SAFETY: the caller's promise that `physical_device` belongs to `instance`.
        let missing = unsafe { REQUIREMENTS.missing(&instance, physical_device) };
        if !missing.is_empty() {
            return Err(Error::NoDevice(format!(
                "the lent device lacks {}",
                missing.join(", ")
            )));
        }
        // SAFETY: as above.
        if !unsafe { REQUIREMENTS.queue_family_fits(&instance, physical_device, queue_family) } {
            return Err(Error::NoDevice(format!(
                "queue family {queue_family} of the lent device cannot draw, compute and write \
                 timestamps"
            )));
        }
        let depth_stencil_named = depth_stencil.is_some();
        let depth_stencil = pick_depth_stencil_format(&instance, physical_device, depth_stencil)?;
        // SAFETY: as above.
        let props = unsafe { instance.get_physical_device_properties(physical_device) };
        let device_name = props
            .device_name_as_c_str()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let debug_device =
            debug_utils.then(|| ash::ext::debug_utils::Device::new(&instance, &device));
        // SAFETY: the caller's promise; histencil requires Vulkan 1.3.
        let driver = unsafe { crate::driver::driver_info(&instance, physical_device, None) };
        Ok(Self {
            _entry: None,
            owned: false,
            instance,
            device,
            queue,
            queue_family,
            allocator: ManuallyDrop::new(allocator),
            debug_instance: None,
            debug_device,
            messenger: vk::DebugUtilsMessengerEXT::null(),
            validation: Arc::new(ValidationLog::default()),
            device_name,
            device_type: props.device_type,
            driver,
            pipeline_cache: pipeline_cache.unwrap_or_default(),
            depth_stencil_format: depth_stencil.vk(),
            depth_stencil,
            depth_stencil_named,
            timestamp_period_ns: f64::from(props.limits.timestamp_period),
            max_image_dimension: props.limits.max_image_dimension2_d,
            max_storage_buffer_range: props.limits.max_storage_buffer_range,
            max_bound_descriptor_sets: props.limits.max_bound_descriptor_sets,
            memory: MemoryAccount::new(memory_budget),
        })
    }

    /// Whether histencil created (and will destroy) the device.
    pub fn owns_device(&self) -> bool {
        self.owned
    }

    fn pick_physical_device(
        instance: &ash::Instance,
        filter: Option<&str>,
    ) -> Result<(vk::PhysicalDevice, u32, String)> {
        let devices =
            unsafe { instance.enumerate_physical_devices() }.call("vkEnumeratePhysicalDevices")?;
        let mut candidates = Vec::new();
        let mut seen = Vec::new();
        for pd in devices {
            let props = unsafe { instance.get_physical_device_properties(pd) };
            let name = props
                .device_name_as_c_str()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            seen.push(name.clone());
            // SAFETY: `pd` was just enumerated from the live `instance`.
            if !unsafe { REQUIREMENTS.missing(instance, pd) }.is_empty() {
                continue;
            }
            let families = unsafe { instance.get_physical_device_queue_family_properties(pd) };
            let Some(family) = (0..families.len() as u32)
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

    /// The name of the device in use, e.g. `llvmpipe (LLVM 15.0.6, 256 bits)`.
    pub fn device_name(&self) -> &str {
        &self.device_name
    }

    /// The pipeline cache every pipeline on this context is made with: the engine's
    /// ([`BorrowedDevice::pipeline_cache`]), histencil's own on an owned device, or null.
    pub fn pipeline_cache(&self) -> vk::PipelineCache {
        self.pipeline_cache
    }

    /// The driver as Vulkan names it (name, build, conformance) and the validation layer's
    /// version: what tells two builds of one driver apart where [`Context::device_name`] cannot.
    pub fn driver(&self) -> &crate::driver::DriverInfo {
        &self.driver
    }

    /// The kind of device in use (llvmpipe is `CPU`): what some passes shape their work by
    /// ([`crate::TileClassify::for_device`]).
    pub fn device_type(&self) -> vk::PhysicalDeviceType {
        self.device_type
    }

    /// The bytes of device memory histencil's objects on this context hold now (what every
    /// renderer, lighting and lightmap made with it has allocated and not yet freed).
    pub fn memory_in_use(&self) -> u64 {
        self.memory.in_use.load(Ordering::Relaxed)
    }

    /// The most device memory histencil's objects on this context have held at once, staging
    /// buffers included: the budget a workload needs.
    pub fn memory_peak(&self) -> u64 {
        self.memory.peak.load(Ordering::Relaxed)
    }

    /// The budget [`ContextDesc::memory_budget`] or [`BorrowedDevice::memory_budget`] set.
    pub fn memory_budget(&self) -> Option<u64> {
        self.memory.budget
    }

    /// The depth-stencil format every renderer on this context uses.
    pub fn depth_stencil_format(&self) -> DepthStencilFormat {
        self.depth_stencil
    }

    /// The validation message log; keep a clone to check it after the context is dropped
    /// (leak reports arrive while the device is destroyed).
    pub fn validation_log(&self) -> Arc<ValidationLog> {
        self.validation.clone()
    }

    /// Names a Vulkan object for validation messages and captures.
    pub(crate) fn name<H: vk::Handle>(&self, handle: H, name: &str) {
        if let Some(dd) = &self.debug_device {
            let name = CString::new(name).expect("object names contain no NUL");
            let info = vk::DebugUtilsObjectNameInfoEXT::default()
                .object_handle(handle)
                .object_name(&name);
            // Naming is best effort: a failure here changes nothing the renderer does.
            let _ = unsafe { dd.set_debug_utils_object_name(&info) };
        }
    }

    /// Opens a debug label region on a command buffer; pair with [`Context::end_label`].
    pub(crate) fn begin_label(&self, cmd: vk::CommandBuffer, label: &str) {
        if let Some(dd) = &self.debug_device {
            let name = CString::new(label).expect("labels contain no NUL");
            let info = vk::DebugUtilsLabelEXT::default().label_name(&name);
            unsafe { dd.cmd_begin_debug_utils_label(cmd, &info) };
        }
    }

    pub(crate) fn end_label(&self, cmd: vk::CommandBuffer) {
        if let Some(dd) = &self.debug_device {
            unsafe { dd.cmd_end_debug_utils_label(cmd) };
        }
    }
}

impl Drop for Context {
    fn drop(&mut self) {
        if !self.owned {
            // The engine's allocator, device and instance stay; only our reference goes.
            // SAFETY: dropped once, here, and never used again.
            unsafe { ManuallyDrop::drop(&mut self.allocator) };
            return;
        }
        unsafe {
            let _ = self.device.device_wait_idle();
            // The allocator frees its memory blocks; it must go before the device. An owned
            // context never hands its allocator out, so this is the last reference.
            ManuallyDrop::drop(&mut self.allocator);
            self.device
                .destroy_pipeline_cache(self.pipeline_cache, None);
            self.device.destroy_device(None);
            if let Some(di) = &self.debug_instance {
                if self.messenger != vk::DebugUtilsMessengerEXT::null() {
                    di.destroy_debug_utils_messenger(self.messenger, None);
                }
            }
            self.instance.destroy_instance(None);
        }
    }
}
