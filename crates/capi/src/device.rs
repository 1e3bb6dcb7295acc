//! Lending histencil the engine's device: a [`HistencilContext`] from its raw Vulkan handles and
//! its loader's `vkGetInstanceProcAddr`, through which histencil loads every function it calls.

use crate::handles::{self, Kind};
use crate::{call, check_size, required, Failure, HistencilResult, Outcome};
use ash::vk;
use histencil::{BorrowedDevice, Context, DepthStencilFormat};
use std::ffi::c_char;
use std::sync::Arc;

/// `<vulkan/vulkan.h>`'s `PFN_vkGetInstanceProcAddr`, nullable (the header uses Vulkan's own
/// typedef: cbindgen is told not to define it).
#[allow(non_camel_case_types)]
pub type PFN_vkGetInstanceProcAddr =
    Option<unsafe extern "system" fn(vk::Instance, *const c_char) -> vk::PFN_vkVoidFunction>;

/// The engine's device, as `histencil_context_create` borrows it. The engine keeps every handle
/// and destroys them itself, after the context.
#[repr(C)]
pub struct HistencilDeviceDesc {
    /// `sizeof(HistencilDeviceDesc)`.
    pub size: u32,
    /// The queue family of `queue`: graphics, compute and timestamps.
    pub queue_family: u32,
    /// The loader's (or the engine's) `vkGetInstanceProcAddr`, through which histencil loads
    /// every instance and device function it calls.
    pub get_instance_proc_addr: PFN_vkGetInstanceProcAddr,
    /// The engine's instance, created for Vulkan 1.3 or later.
    pub instance: vk::Instance,
    /// The physical device behind `device`.
    pub physical_device: vk::PhysicalDevice,
    /// The engine's device, with the Vulkan 1.3 features histencil needs enabled (the book's
    /// engine chapter lists them; `histencil_context_create` names any that are missing).
    pub device: vk::Device,
    /// A queue of `queue_family`; histencil's engine-facing calls never submit to it.
    pub queue: vk::Queue,
    /// The depth-stencil format every lighting on this context uses
    /// (`VK_FORMAT_D32_SFLOAT_S8_UINT` or `VK_FORMAT_D24_UNORM_S8_UINT`), or
    /// `VK_FORMAT_UNDEFINED` to leave it to each lighting's description.
    pub depth_stencil_format: vk::Format,
    /// Non-zero when `VK_EXT_debug_utils` is enabled on `instance`: histencil then names its
    /// objects and labels its passes.
    pub debug_utils: u32,
    /// The most GPU memory histencil may allocate, in bytes; 0 for no bound.
    pub memory_budget: u64,
}

/// A device lent to histencil, and what hangs off it (its private allocator).
pub struct HistencilContext {
    pub(crate) ctx: Arc<Context>,
    /// Where the hazard check, once turned on (`histencil_context_check_hazards`), keeps its
    /// findings.
    pub(crate) hazards: Arc<histencil::ValidationLog>,
}

/// Makes a context on the engine's device. Creates nothing of Vulkan's but histencil's private
/// memory allocator; checks that the physical device and queue family have what histencil needs.
///
/// Errors: `INVALID_ARGUMENT` for a null pointer or handle, or a wrong `size`; `UNSUPPORTED` when
/// the device or queue family lacks a feature histencil needs (the message lists them);
/// `BAD_SETUP` for a depth-stencil format the device cannot use.
///
/// Cannot be checked (the engine's to keep): that the handles are live and belong together,
/// that `device` was created with the features listed and for Vulkan 1.3, that `debug_utils`
/// tells the truth, and that the handles outlive the context.
///
/// Thread safety: any thread.
///
/// # Safety
/// `desc` is null or points at a live `HistencilDeviceDesc`; `context` is null or writable.
#[no_mangle]
pub unsafe extern "C" fn histencil_context_create(
    desc: *const HistencilDeviceDesc,
    context: *mut *mut HistencilContext,
) -> HistencilResult {
    call(|| {
        if context.is_null() {
            return Err(Failure::invalid("context (the out pointer) is null"));
        }
        // SAFETY: this fn's # Safety: null or a live desc.
        let desc = unsafe { required(desc, "desc") }?;
        check_size::<HistencilDeviceDesc>("HistencilDeviceDesc", desc.size)?;
        let lent = borrowed(desc)?;
        // SAFETY: `Context::from_raw`'s # Safety is the engine's, as the header states it for
        // this call: live handles of one device, kept past the context.
        let ctx = unsafe { Context::from_raw(lent) }?;
        let handle = handles::make(
            HistencilContext {
                ctx: Arc::new(ctx),
                hazards: Arc::default(),
            },
            Kind::Context,
        );
        // SAFETY: checked non-null above; this fn's # Safety makes it writable.
        unsafe { context.write(handle) };
        Ok(())
    })
}

/// The borrowed device `desc` describes, its functions loaded through its
/// `vkGetInstanceProcAddr`.
fn borrowed(desc: &HistencilDeviceDesc) -> Outcome<BorrowedDevice> {
    let nulls = [
        (desc.instance == vk::Instance::null(), "instance"),
        (
            desc.physical_device == vk::PhysicalDevice::null(),
            "physical_device",
        ),
        (desc.device == vk::Device::null(), "device"),
        (desc.queue == vk::Queue::null(), "queue"),
    ];
    if let Some((_, name)) = nulls.iter().find(|(null, _)| *null) {
        return Err(Failure::invalid(format!(
            "HistencilDeviceDesc.{name} is VK_NULL_HANDLE"
        )));
    }
    let get_instance_proc_addr = desc
        .get_instance_proc_addr
        .ok_or_else(|| Failure::invalid("HistencilDeviceDesc.get_instance_proc_addr is null"))?;
    let depth_stencil = match desc.depth_stencil_format {
        vk::Format::UNDEFINED => None,
        f => Some(
            DepthStencilFormat::ALL
                .into_iter()
                .find(|d| d.vk() == f)
                .ok_or_else(|| {
                    Failure::invalid(format!(
                        "HistencilDeviceDesc.depth_stencil_format {f:?} is not one histencil \
                         lights with (D32_SFLOAT_S8_UINT, D24_UNORM_S8_UINT or UNDEFINED)"
                    ))
                })?,
        ),
    };
    let loader = ash::StaticFn {
        get_instance_proc_addr,
    };
    // SAFETY: the engine's live instance and its vkGetInstanceProcAddr (the header's contract
    // for this call); loading only looks functions up.
    let instance = unsafe { ash::Instance::load(&loader, desc.instance) };
    // SAFETY: the engine's live device of that instance; loading only looks functions up.
    let device = unsafe { ash::Device::load(instance.fp_v1_0(), desc.device) };
    Ok(BorrowedDevice {
        instance,
        device,
        physical_device: desc.physical_device,
        queue_family: desc.queue_family,
        queue: desc.queue,
        allocator: None,
        debug_utils: desc.debug_utils != 0,
        depth_stencil,
        memory_budget: (desc.memory_budget != 0).then_some(desc.memory_budget),
        pipeline_cache: None,
    })
}

/// Frees the context. Refused (`IN_FLIGHT`, nothing freed) while a lighting made on it lives:
/// destroy those first. Waits for the device to go idle when a lighting dropped in flight left
/// objects behind (none does through this API: a lighting in flight is never freed).
///
/// Thread safety: not while any other call uses this context or a lighting made on it.
///
/// # Safety
/// `context` is null, or a handle from `histencil_context_create` (a freed one is refused).
#[no_mangle]
pub unsafe extern "C" fn histencil_context_destroy(
    context: *mut HistencilContext,
) -> HistencilResult {
    call(|| {
        // SAFETY: the header's thread-safety rule: no other call uses it now.
        let held = unsafe { handles::get(context, Kind::Context, "context") }?;
        let lightings = Arc::strong_count(&held.ctx) - 1;
        if lightings > 0 {
            return Err(Failure {
                result: HistencilResult::InFlight,
                message: format!(
                    "the context still has {lightings} lighting(s) or lightmaps made on it: destroy them first"
                ),
            });
        }
        // SAFETY: as above.
        drop(unsafe { handles::take(context, Kind::Context, "context") }?);
        Ok(())
    })
}

/// Whether histencil can light on `physical_device` of `instance` with `queue_family`, asked
/// before the engine creates its device: writes 1 to `suits` if so, else 0 with the reason in
/// `histencil_last_error()` (the features or limits the device lacks, or what the family
/// cannot do), which `histencil_context_create` would refuse with.
///
/// Errors: `INVALID_ARGUMENT` for a null pointer or handle.
///
/// Thread safety: any thread.
///
/// # Safety
/// `instance` is live, created for Vulkan 1.3 with `get_instance_proc_addr`'s loader, and
/// `physical_device` enumerated from it; `suits` is null or writable.
#[no_mangle]
pub unsafe extern "C" fn histencil_device_suits(
    get_instance_proc_addr: PFN_vkGetInstanceProcAddr,
    instance: vk::Instance,
    physical_device: vk::PhysicalDevice,
    queue_family: u32,
    suits: *mut u32,
) -> HistencilResult {
    call(|| {
        let get_instance_proc_addr = get_instance_proc_addr
            .ok_or_else(|| Failure::invalid("get_instance_proc_addr is null"))?;
        if instance == vk::Instance::null() || physical_device == vk::PhysicalDevice::null() {
            return Err(Failure::invalid(
                "instance or physical_device is VK_NULL_HANDLE",
            ));
        }
        if suits.is_null() {
            return Err(Failure::invalid("suits is null"));
        }
        let loader = ash::StaticFn {
            get_instance_proc_addr,
        };
        // SAFETY: this fn's # Safety: a live instance of that loader.
        let instance = unsafe { ash::Instance::load(&loader, instance) };
        let requirements = histencil::REQUIREMENTS;
        // SAFETY: this fn's # Safety: the physical device belongs to the live instance, made
        // for Vulkan 1.3.
        let missing = unsafe { requirements.missing(&instance, physical_device) };
        // SAFETY: as above.
        let family =
            unsafe { requirements.queue_family_fits(&instance, physical_device, queue_family) };
        let why = if !missing.is_empty() {
            Some(format!("the device lacks {}", missing.join(", ")))
        } else if !family {
            Some(format!(
                "queue family {queue_family} of the device cannot draw, compute and write \
                 timestamps"
            ))
        } else {
            None
        };
        // SAFETY: checked non-null; writable by this fn's # Safety.
        unsafe { suits.write(u32::from(why.is_none())) };
        if let Some(why) = why {
            crate::set_last_error(&why);
        }
        Ok(())
    })
}
