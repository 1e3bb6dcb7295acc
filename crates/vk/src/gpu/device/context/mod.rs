//! The Vulkan context: instance, device, queue, memory allocator, validation log and the naming /
//! labelling helpers every other module uses. Owned ([`Context::new`], for histencil's tools) or
//! lent by an engine ([`Context::from_raw`]), which keeps its device, allocator and messenger.

mod owned;

use crate::gpu::device::quirks::{Quirks, QUIRKS};
use owned::pick_depth_stencil_format;

use crate::gpu::device::debug::ValidationLog;
use crate::gpu::device::error::{Error, Result};
use crate::gpu::device::requirements::REQUIREMENTS;
use ash::vk;
use gpu_allocator::vulkan::Allocator;
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

    /// The Vulkan format.
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
    /// Leave the device's depth bounds test unused even where it has one (`depthBounds`): the
    /// lighting then takes the path of a device without it, as a comparison of the two needs.
    pub without_depth_bounds: bool,
    /// Apply no driver quirk ([`crate::QUIRKS`]): the general path every other device takes,
    /// on this one too.
    pub general_path: bool,
    /// Act as a device that offers only the spec's minimum of every limit histencil checks
    /// ([`crate::Limit`]): work that needs more is refused with [`Error::DeviceLimit`] or takes
    /// its smaller shape (8x8 tiles), as on such a device; the driver line reports the capped
    /// values. What a device at the minimums can run, tried on any device.
    pub spec_minimum_limits: bool,
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
    /// The engine's instance, which `device` was created from.
    pub instance: ash::Instance,
    /// The engine's device, with the features of [`REQUIREMENTS`] enabled.
    pub device: ash::Device,
    /// The physical device behind `device`, whose limits and formats histencil reads.
    pub physical_device: vk::PhysicalDevice,
    /// The family of `queue`; it must fit [`REQUIREMENTS`].
    pub queue_family: u32,
    /// The queue of `queue_family` that histencil's own tools (the renderer, the evaluators)
    /// submit to; the engine-facing parts submit nothing.
    pub queue: vk::Queue,
    /// The engine's allocator for `device`, if it has one (gpu-allocator's): histencil's
    /// allocations are named `histencil`-side and freed before its objects are dropped.
    /// `None`: histencil allocates through a private allocator of its own on `device`, freed
    /// with the context. That is sound beside whatever the engine allocates with (VMA, its
    /// own): each allocator holds `VkDeviceMemory` objects of its own and sub-allocates only
    /// within them, so nothing aliases. What it costs: memory blocks of its own (32 MiB
    /// device-local, 8 MiB host-visible, each allocated when first needed, with
    /// [`BorrowedDevice::memory_budget`] bounding what histencil takes in all) and a few of the
    /// device's `maxMemoryAllocationCount` (at least 4096).
    pub allocator: Option<Arc<Mutex<Allocator>>>,
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
    /// The device's physical device, whose format features a description is checked against.
    physical_device: vk::PhysicalDevice,
    pub(crate) device: ash::Device,
    pub(crate) queue: vk::Queue,
    pub(crate) queue_family: u32,
    /// Held by every submit and device-wide wait histencil makes: Vulkan requires a queue's
    /// host access to be externally synchronised, and renderers and lightings sharing one
    /// context may submit from several threads ([`Context::submit`]).
    queue_lock: Mutex<()>,
    pub(crate) allocator: ManuallyDrop<Arc<Mutex<Allocator>>>,
    debug_instance: Option<ash::ext::debug_utils::Instance>,
    debug_device: Option<ash::ext::debug_utils::Device>,
    messenger: vk::DebugUtilsMessengerEXT,
    validation: Arc<ValidationLog>,
    device_name: String,
    device_type: vk::PhysicalDeviceType,
    driver: crate::gpu::device::driver::DriverInfo,
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
    /// The device's values of the limits histencil checks ([`crate::Limit`]).
    pub(crate) limits: crate::gpu::device::limits::DeviceLimits,
    /// The largest need of each limit met on this context, for the reports and the test that
    /// holds [`crate::NEEDS`] to the code.
    pub(crate) limits_used: crate::gpu::device::limits::LimitsUsed,
    /// What each set layout made on this context holds, by stage and kind: what a pipeline
    /// layout built from them is checked against.
    pub(crate) set_counts: Mutex<
        std::collections::HashMap<
            vk::DescriptorSetLayout,
            Vec<crate::gpu::device::limits::SetCounts>,
        >,
    >,
    /// `depthBounds` is enabled on the device and histencil's pipelines take the depth bounds
    /// test as dynamic state: the renderer confines lights to their depth ranges
    /// ([`histencil_model::FramePlan::with_depth_bounds`]). Off on an engine's device, whose
    /// enabled features histencil is not told.
    pub(crate) depth_bounds: bool,
    /// How histencil shapes its work on this driver ([`crate::QUIRKS`]).
    pub(crate) quirks: crate::gpu::device::quirks::Quirks,
    pub(crate) memory: MemoryAccount,
    /// The step observer and the labelled regions open ([`Context::observe_steps`]).
    steps: Mutex<Steps>,
    /// What engine-facing objects left behind when dropped while the GPU might still use it
    /// ([`Context::retire`]): freed at [`Context::free_retired`] or when the context drops.
    retired: Mutex<Vec<Retired>>,
    /// The hazard check ([`crate::gpu::device::hazards`]): on for a context histencil creates with
    /// validation, in debug builds, and where an engine turns it on
    /// ([`Context::check_hazards`]).
    pub(crate) hazards: std::sync::OnceLock<crate::gpu::device::hazards::Hazards>,
    /// Each buffer's last declared uses, in recording order: what the barrier a step's declaration
    /// needs is derived from
    /// ([`Recording::declare_buffers`](crate::gpu::encoder::recording::Recording)).
    pub(crate) buffer_uses:
        Mutex<std::collections::HashMap<vk::Buffer, crate::gpu::access::BufferUse>>,
}

/// How to free what a dropped object left to its context ([`Context::retire`]).
pub(crate) type Retired = Box<dyn FnOnce(&Context) + Send>;

/// What [`Context::observe_steps`] calls with each step.
pub type StepObserver = Box<dyn Fn(&str) + Send + Sync>;

/// A step observer as the context keeps it: cloned out of the lock before it is called.
type SharedObserver = Arc<dyn Fn(&str) + Send + Sync>;

/// The labelled regions open on the context's command buffers, for the step observer.
#[derive(Default)]
struct Steps {
    observer: Option<SharedObserver>,
    open: Vec<String>,
    /// The outermost regions recorded since the last wait: what a fence wait waits for.
    since_wait: Vec<String>,
}

impl std::fmt::Debug for Steps {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Steps")
            .field("observed", &self.observer.is_some())
            .field("open", &self.open)
            .finish()
    }
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

/// A gpu-allocator allocator on `device` with blocks of `sizes`: an owned context's, or the
/// private one of a lent device whose engine lends none ([`BorrowedDevice::allocator`]).
pub(super) fn make_allocator(
    instance: &ash::Instance,
    device: &ash::Device,
    physical_device: vk::PhysicalDevice,
    sizes: gpu_allocator::AllocationSizes,
) -> Result<Allocator> {
    Allocator::new(&gpu_allocator::vulkan::AllocatorCreateDesc {
        instance: instance.clone(),
        device: device.clone(),
        physical_device,
        debug_settings: Default::default(),
        buffer_device_address: false,
        allocation_sizes: sizes,
    })
    .map_err(|e| Error::Allocation {
        name: "allocator".into(),
        message: e.to_string(),
    })
}

impl Context {
    /// Submits `submits` to the context's queue under the queue's lock (`queue_lock`), so no
    /// two of histencil's submits, nor a submit and a device-wide wait, meet on the queue.
    ///
    /// # Safety
    /// As `vkQueueSubmit2`: the command buffers are executable, the fence unsignalled and not
    /// in use, and what the submits name lives until they complete. On a lent device the
    /// engine's own access to the queue is synchronised with histencil's
    /// (`Context::from_raw`'s # Safety).
    pub(crate) unsafe fn submit(
        &self,
        submits: &[vk::SubmitInfo2],
        fence: vk::Fence,
    ) -> ash::prelude::VkResult<()> {
        let _queue = self.queue_lock.lock().unwrap_or_else(|p| p.into_inner());
        if let Some(hazards) = self.hazards.get() {
            let cmds: Vec<vk::CommandBuffer> = submits
                .iter()
                .flat_map(|s| {
                    // SAFETY: as `vkQueueSubmit2`'s, each pointer is null or points at its
                    // count of command buffer infos.
                    let infos = unsafe {
                        if s.p_command_buffer_infos.is_null() {
                            &[][..]
                        } else {
                            std::slice::from_raw_parts(
                                s.p_command_buffer_infos,
                                s.command_buffer_info_count as usize,
                            )
                        }
                    };
                    infos.iter().map(|i| i.command_buffer)
                })
                .collect();
            hazards.submitted(&cmds, fence);
        }
        // SAFETY: the caller's, above; the lock makes this thread's access the only one of
        // histencil's.
        unsafe { self.device.queue_submit2(self.queue, submits, fence) }
    }

    /// `vkDeviceWaitIdle` under the queue's lock: it counts as an access to every queue of the
    /// device.
    pub(crate) fn wait_idle(&self) -> ash::prelude::VkResult<()> {
        let _queue = self.queue_lock.lock().unwrap_or_else(|p| p.into_inner());
        // SAFETY: the device is live; histencil's own queue access is held off by the lock,
        // an engine's by `Context::from_raw`'s # Safety.
        let idle = unsafe { self.device.device_wait_idle() };
        if let (Ok(()), Some(hazards)) = (&idle, self.hazards.get()) {
            hazards.idle();
        }
        idle
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
    /// - `instance` was created with an `apiVersion` of 1.3 or later, as [`REQUIREMENTS`] asks:
    ///   histencil queries and records through it with Vulkan 1.1 to 1.3 commands;
    /// - `allocator`, if given, was created for `device`;
    /// - `debug_utils` is true only if `VK_EXT_debug_utils` is enabled on `instance`;
    /// - while histencil's owned-device tools ([`crate::Renderer`]) submit to `queue` and wait,
    ///   nothing else uses that queue (Vulkan requires queues to be externally synchronised);
    /// - while this context is dropped holding retired objects ([`Context::retired_count`]:
    ///   a [`crate::DeferredLighting`] or [`crate::AlphaLightmaps`] dropped with a slot not
    ///   declared finished, or [`crate::LutTables`] dropped without their `destroy`), nothing
    ///   else uses any queue of the device: the drop waits for the device to go idle before it
    ///   frees them, and every command buffer recorded through them has been submitted or never
    ///   will be. [`Context::free_retired`] frees them earlier, without that wait.
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
        // SAFETY: `missing`'s # Safety, by this fn's: `physical_device` belongs to the live
        // `instance`, which was created for Vulkan 1.3.
        let missing = unsafe { REQUIREMENTS.missing(&instance, physical_device) };
        if !missing.is_empty() {
            return Err(Error::NoDevice(format!(
                "the lent device lacks {}",
                missing.join(", ")
            )));
        }
        // SAFETY: `queue_family_fits`'s # Safety: `physical_device` belongs to the live
        // `instance` (this fn's # Safety).
        if !unsafe { REQUIREMENTS.queue_family_fits(&instance, physical_device, queue_family) } {
            return Err(Error::NoDevice(format!(
                "queue family {queue_family} of the lent device cannot draw, compute and write \
                 timestamps"
            )));
        }
        let depth_stencil_named = depth_stencil.is_some();
        let depth_stencil = pick_depth_stencil_format(&instance, physical_device, depth_stencil)?;
        // Once the device is known to fit: a private allocator of histencil's own when the
        // engine lends none, with blocks smaller than gpu-allocator's defaults (256 and 64 MiB),
        // since it sits beside the engine's own memory.
        let allocator = match allocator {
            Some(engines) => engines,
            None => {
                const MIB: u64 = 1 << 20;
                let sizes = gpu_allocator::AllocationSizes::new(32 * MIB, 8 * MIB);
                let private = make_allocator(&instance, &device, physical_device, sizes)?;
                Arc::new(Mutex::new(private))
            }
        };
        // SAFETY: `physical_device` belongs to the live `instance` (this fn's # Safety).
        let props = unsafe { instance.get_physical_device_properties(physical_device) };
        let device_name = props
            .device_name_as_c_str()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let debug_device =
            debug_utils.then(|| ash::ext::debug_utils::Device::new(&instance, &device));
        // SAFETY: `driver_info`'s # Safety: `physical_device` belongs to `instance`, created for
        // Vulkan 1.3 (this fn's # Safety), and supports 1.3 (`missing` above found nothing).
        let mut driver =
            unsafe { crate::gpu::device::driver::driver_info(&instance, physical_device, None) };
        let quirks = Quirks::of(QUIRKS, driver.id, driver.version);
        driver.quirks = quirks.describe();
        Ok(Self {
            _entry: None,
            owned: false,
            instance,
            physical_device,
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
            limits: crate::gpu::device::limits::DeviceLimits::new(&props.limits),
            limits_used: Default::default(),
            set_counts: Default::default(),
            queue_lock: Mutex::new(()),
            steps: Default::default(),
            depth_bounds: false,
            quirks,
            memory: MemoryAccount::new(memory_budget),
            retired: Mutex::default(),
            hazards: Default::default(),
            buffer_uses: Mutex::default(),
        })
    }

    /// What the device can do with `format` in optimally tiled images.
    pub(crate) fn format_features(&self, format: vk::Format) -> vk::FormatFeatureFlags {
        // SAFETY: `physical_device` is the live instance's: enumerated by `Context::new`, or
        // promised by `from_raw`'s caller.
        unsafe {
            (self.instance).get_physical_device_format_properties(self.physical_device, format)
        }
        .optimal_tiling_features
    }

    /// Whether histencil created (and will destroy) the device.
    pub fn owns_device(&self) -> bool {
        self.owned
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
    pub fn driver(&self) -> &crate::gpu::device::driver::DriverInfo {
        &self.driver
    }

    /// Whether the depth bounds test is enabled and in use: light shade passes are confined to
    /// their light's depth range ([`histencil_model::FramePlan::with_depth_bounds`]). False on a
    /// device without `depthBounds`, with [`ContextDesc::without_depth_bounds`], and on an
    /// engine's device.
    pub fn depth_bounds(&self) -> bool {
        self.depth_bounds
    }

    /// The quirks in force on this device: the table's rows for its driver, or none with
    /// [`ContextDesc::general_path`].
    pub fn quirks(&self) -> &crate::gpu::device::quirks::Quirks {
        &self.quirks
    }

    /// The device's values of the limits histencil checks.
    pub fn device_limits(&self) -> &crate::gpu::device::limits::DeviceLimits {
        &self.limits
    }

    /// The largest need of `limit` that work made on this context has had (0 before any).
    pub fn limit_used(&self, limit: crate::gpu::device::limits::Limit) -> u32 {
        self.limits_used.get(limit)
    }

    /// Checks `need` of `limit` against the device and notes it: an error naming the limit
    /// and `what` needs it where the device offers less.
    pub(crate) fn need(
        &self,
        limit: crate::gpu::device::limits::Limit,
        need: u32,
        what: &str,
    ) -> Result<()> {
        self.limits
            .check(limit, need, what)
            .map_err(Error::DeviceLimit)?;
        self.limits_used.note(limit, need);
        Ok(())
    }

    /// The kind of device in use (llvmpipe is `CPU`), as Vulkan reports it.
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

    /// Turns the hazard check on (the book's "The hazard check"), its findings going to `log` as
    /// ERROR messages (`HISTENCIL-HAZARD-...`): for an engine's debug builds and tests. From
    /// here on histencil journals the buffers its commands use and the barriers they record;
    /// the engine tells it what it submits and waits for ([`Context::note_submit`],
    /// [`Context::note_wait`], [`Context::note_idle`]), and each submission is checked against
    /// the ones still in flight. Objects made before this call are not known to it: turn it
    /// on before creating lightings. Returns false (and changes nothing) where it was on.
    pub fn check_hazards(&self, log: Arc<ValidationLog>) -> bool {
        self.hazards
            .set(crate::gpu::device::hazards::Hazards::new(log))
            .is_ok()
    }

    /// Tells the hazard check that `cmds` were submitted, in this order, signalling `fence`
    /// (null for none): their accesses are checked against every submission not yet waited
    /// for. Nothing where the check is off.
    pub fn note_submit(&self, cmds: &[vk::CommandBuffer], fence: vk::Fence) {
        if let Some(hazards) = self.hazards.get() {
            hazards.submitted(cmds, fence);
        }
    }

    /// Tells the hazard check that the host saw `fence` signalled: the submissions that
    /// signalled it are complete.
    pub fn note_wait(&self, fence: vk::Fence) {
        if let Some(hazards) = self.hazards.get() {
            hazards.waited(fence);
        }
    }

    /// Tells the hazard check that the queue is idle (`vkQueueWaitIdle`, `vkDeviceWaitIdle`).
    pub fn note_idle(&self) {
        if let Some(hazards) = self.hazards.get() {
            hazards.idle();
        }
    }

    /// Tells the hazard check that `cmd` was begun (or reset): what it recorded before is gone.
    pub fn note_begin(&self, cmd: vk::CommandBuffer) {
        if let Some(hazards) = self.hazards.get() {
            hazards.begun(cmd);
        }
    }

    /// Names a Vulkan object for validation messages and captures.
    pub(crate) fn name<H: vk::Handle + Copy>(&self, handle: H, name: &str) {
        if let Some(hazards) = self.hazards.get() {
            hazards.name(H::TYPE, handle.as_raw(), name);
        }
        if let Some(dd) = &self.debug_device {
            let name = CString::new(name).expect("object names contain no NUL");
            let info = vk::DebugUtilsObjectNameInfoEXT::default()
                .object_handle(handle)
                .object_name(&name);
            // Naming is best effort: a failure here changes nothing the renderer does.
            // SAFETY: `dd` is loaded for `self.device`, whose instance has VK_EXT_debug_utils
            // enabled (`Context::new` enabled it wherever it makes `dd`; `from_raw`'s caller
            // promises it with `debug_utils`). Every caller names the device, or a live object
            // of it, right after making it and before any other thread can reach it (the
            // handle's external synchronisation); `info` and `name` outlive the call.
            let _ = unsafe { dd.set_debug_utils_object_name(&info) };
        }
    }

    /// Calls `observer` with each step of histencil's work as it begins: the labelled region
    /// being recorded, nested regions joined by ` / ` (`recording lighting / light-3 /
    /// shade-ggx`), and before each fence wait what the GPU is given (`waiting on the GPU for
    /// gbuffer, lighting, tonemap, readback`). A runner that prints them learns,
    /// when the process crashes or hangs, what was being recorded or waited on (`histencil
    /// check`'s workers do). `None` stops it. Without an observer a step costs one lock. The
    /// observer is called with no lock of the context's held, so it may call back into the
    /// context.
    pub fn observe_steps(&self, observer: Option<StepObserver>) {
        let mut steps = self.steps.lock().unwrap_or_else(|e| e.into_inner());
        steps.observer = observer.map(Arc::from);
        steps.open.clear();
        steps.since_wait.clear();
    }

    /// Tells the observer that `what` begins (a fence wait, a submission), after the regions
    /// recorded last; returns the line it was told (`None` without an observer), which
    /// [`Context::step_progress`] extends.
    pub(crate) fn step(&self, what: &str) -> Option<String> {
        let (observer, work) = {
            let mut steps = self.steps.lock().unwrap_or_else(|e| e.into_inner());
            let work = std::mem::take(&mut steps.since_wait);
            (steps.observer.clone(), work)
        };
        let observer = observer?;
        let work = if work.is_empty() {
            "work recorded without a label".to_owned()
        } else {
            work.join(", ")
        };
        let line = format!("{what} for {work}");
        observer(&line);
        Some(line)
    }

    /// Tells the observer how far the GPU has got with the work a [`Context::step`] line named
    /// (`waiting on the GPU for gbuffer, lighting: the GPU has finished gbuffer, not
    /// lighting`): the last line a runner keeps, when the GPU hangs, names the GPU's own step.
    pub(crate) fn step_progress(&self, step: &str, progress: &str) {
        let observer = {
            let steps = self.steps.lock().unwrap_or_else(|e| e.into_inner());
            steps.observer.clone()
        };
        if let Some(observer) = observer {
            observer(&format!("{step}: {progress}"));
        }
    }

    /// Opens a debug label region on a command buffer and tells the step observer; pair with
    /// [`Context::end_label`]. Only the encoder calls it (`Recording::step`, which tracks the
    /// labels it opened and checks they are closed).
    pub(crate) fn begin_label(&self, cmd: vk::CommandBuffer, label: &str) {
        let observed = {
            let mut steps = self.steps.lock().unwrap_or_else(|e| e.into_inner());
            match steps.observer.clone() {
                Some(observer) => {
                    if steps.open.is_empty() {
                        steps.since_wait.push(label.to_owned());
                    }
                    steps.open.push(label.to_owned());
                    Some((observer, steps.open.join(" / ")))
                }
                None => None,
            }
        };
        if let Some((observer, open)) = observed {
            observer(&format!("recording {open}"));
        }
        if let Some(dd) = &self.debug_device {
            let name = CString::new(label).expect("labels contain no NUL");
            let info = vk::DebugUtilsLabelEXT::default().label_name(&name);
            // SAFETY: every caller passes the command buffer of this device it is recording
            // (`submit_once`'s, the renderer's, or an engine's under the # Safety of the
            // `unsafe fn record*` it called), held by this thread; `info` outlives the call.
            unsafe { dd.cmd_begin_debug_utils_label(cmd, &info) };
        }
    }

    pub(crate) fn end_label(&self, cmd: vk::CommandBuffer) {
        {
            let mut steps = self.steps.lock().unwrap_or_else(|e| e.into_inner());
            if steps.observer.is_some() {
                steps.open.pop();
            }
        }
        if let Some(dd) = &self.debug_device {
            // SAFETY: `cmd` is recording, as for `begin_label`, and every caller pairs this
            // with a `begin_label` it recorded earlier into the same `cmd`.
            unsafe { dd.cmd_end_debug_utils_label(cmd) };
        }
    }
}

impl Context {
    /// Keeps what `free` frees until the GPU is known to be done with it: an engine-facing
    /// object ([`crate::DeferredLighting`], [`crate::AlphaLightmaps`], [`crate::LutTables`])
    /// dropped while a frame it recorded may not have run yet (recorded and not declared
    /// finished: the engine may still submit it, after the drop) hands its objects here instead
    /// of freeing them under that frame. Dropping never waits for the GPU, so an engine that
    /// replaces its lighting with a frame recorded and not yet submitted gets no crash when it
    /// submits: the old lighting's objects live on with the context.
    pub(crate) fn retire(&self, free: Retired) {
        let mut retired = self.retired.lock().unwrap_or_else(|p| p.into_inner());
        retired.push(free);
    }

    /// How many dropped objects' parts this context still keeps for frames that may not have
    /// run ([`Context::free_retired`]).
    pub fn retired_count(&self) -> usize {
        self.retired.lock().unwrap_or_else(|p| p.into_inner()).len()
    }

    /// Frees what lightings, lightmaps and tables dropped while in flight left to this context
    /// (they keep their Vulkan objects here, so that a command buffer recorded before the drop
    /// and submitted after it reads live objects). Dropping the context frees them too, after
    /// waiting for the device to go idle; an engine that replaces lightings often calls this
    /// once its fences say those frames are done.
    ///
    /// # Safety
    /// Every command buffer recorded through an object dropped before this call has finished
    /// executing on the GPU, or will never be submitted.
    pub unsafe fn free_retired(&self) {
        let retired = std::mem::take(&mut *self.retired.lock().unwrap_or_else(|p| p.into_inner()));
        for free in retired {
            free(self);
        }
    }

    /// The context's drop: waits for the device when anything is retired (a retired object's
    /// frame may have been submitted after its drop), then frees it.
    fn free_retired_at_drop(&mut self) {
        let retired = std::mem::take(self.retired.get_mut().unwrap_or_else(|p| p.into_inner()));
        if retired.is_empty() {
            return;
        }
        let _ = self.wait_idle();
        for free in retired {
            free(self);
        }
    }
}

impl Drop for Context {
    fn drop(&mut self) {
        // What dropped objects retired holds allocations of the allocator: freed before it.
        self.free_retired_at_drop();
        if !self.owned {
            // The engine's allocator, device and instance stay; only our reference goes. A
            // private allocator (the engine lent none) goes with it, freeing its blocks while
            // the engine's device still lives (`from_raw`'s # Safety).
            // SAFETY: dropped once, here, and never used again.
            unsafe { ManuallyDrop::drop(&mut self.allocator) };
            return;
        }
        // SAFETY: every handle here is this context's own, destroyed once, here. The wait
        // leaves no submitted work running (a lost device, whose error is ignored, runs none);
        // its external synchronisation of the queue holds because `&mut self` means no
        // renderer or lighting of this context is left to submit. histencil's objects borrow
        // or share the context and are destroyed before it (one leaked by `mem::forget` is a
        // child left alive, which the validation layer reports). Children go before parents:
        // the allocator's memory and the cache before the device, then the messenger (whose
        // user data `validation` is dropped only after this) and the instance.
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
