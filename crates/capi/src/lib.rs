//! histencil for C and C++ engines: the engine API of the `histencil` crate behind a C ABI, as
//! `include/histencil.h` declares it (generated from this crate by cbindgen; a test fails when
//! the header drifts from the source).
//!
//! The ABI follows the libraries engines already integrate (FSR2's `ffx_fsr2.h`, wgpu-native's
//! `webgpu.h`):
//! - **Opaque handles** ([`HistencilContext`], [`HistencilLighting`]), made by a `_create` call
//!   and freed by a `_destroy` call. A handle is checked against the live ones before use: a
//!   null, freed or foreign handle is an error, not a crash.
//! - **Sized structs**: every struct an engine passes in starts with `size`, which it sets to
//!   `sizeof` the struct; a size histencil does not know is refused, so the ABI can grow.
//! - **A result for every call** ([`HistencilResult`]) and, on an error, the message
//!   ([`histencil_last_error`], per thread), in the words the Rust errors print.
//! - **No unwinding across the boundary**: a panic is caught and returned as
//!   [`HistencilResult::Internal`], its message kept.
//! - **Enums travel as `uint32_t`** and are checked, so an unknown value is an error.

mod device;
mod frame;
mod gbuffer;
mod handles;
mod hazards;
mod lighting;
mod lightmaps;
mod lut;
mod materials;
mod shaders;

pub use device::{
    histencil_context_create, histencil_context_destroy, histencil_device_suits, HistencilContext,
    HistencilDeviceDesc, PFN_vkGetInstanceProcAddr,
};
pub use frame::{
    HistencilBox, HistencilBrdfBounds, HistencilFrame, HistencilImage, HistencilLight,
    HistencilStepTime, HistencilTargets, HistencilView, HISTENCIL_FALLOFF_GLTF,
    HISTENCIL_FALLOFF_INVERSE_SQUARE, HISTENCIL_FALLOFF_SQUARED_WINDOW,
    HISTENCIL_LIGHT_DIRECTIONAL, HISTENCIL_LIGHT_POINT, HISTENCIL_LIGHT_SPOT,
    HISTENCIL_PLATFORM_NATIVE, HISTENCIL_PLATFORM_PS3, HISTENCIL_PLATFORM_X360,
    HISTENCIL_PLATFORM_X360_SAVE_RESTORE, HISTENCIL_TECHNIQUE_BRANCHING,
    HISTENCIL_TECHNIQUE_DEPTH_ID, HISTENCIL_TECHNIQUE_LUT, HISTENCIL_TECHNIQUE_STENCIL,
    HISTENCIL_TECHNIQUE_TILED,
};
pub use gbuffer::{
    histencil_brdf_encode, histencil_device_features, histencil_gbuffer_formats,
    histencil_shading_inputs, HistencilBrdfParam, HISTENCIL_API_VERSION,
    HISTENCIL_FRAME_UNIFORMS_BYTES, HISTENCIL_GBUFFER_IMAGES, HISTENCIL_GPU_LIGHT_BYTES,
};
pub use hazards::{
    histencil_context_check_hazards, histencil_context_hazards, histencil_note_begin,
    histencil_note_submit, histencil_note_wait,
};
pub use lighting::{
    histencil_lighting_create, histencil_lighting_destroy, histencil_lighting_in_flight,
    histencil_lighting_record, histencil_lighting_resize, histencil_lighting_slot_finished,
    histencil_lighting_stencil_reference, histencil_lighting_step_timings, HistencilHooks,
    HistencilLighting, HistencilLightingDesc,
};
pub use lightmaps::{
    histencil_lightmaps_create, histencil_lightmaps_destroy, histencil_lightmaps_entity_buffer,
    histencil_lightmaps_record, histencil_lightmaps_slot_finished, HistencilAlphaEntity,
    HistencilLightmapFrame, HistencilLightmaps, HistencilLightmapsDesc, HistencilMesh,
    HistencilParticle, HistencilVertex, HISTENCIL_ENTITY_OBJECT, HISTENCIL_ENTITY_PARTICLES,
    HISTENCIL_PARTICLES_AUTO, HISTENCIL_PARTICLES_BILLBOARD, HISTENCIL_PARTICLES_DUST,
    HISTENCIL_PARTICLES_RIBBON, HISTENCIL_PARTICLES_SLICES,
};
pub use lut::{
    histencil_lighting_set_lut_tables, histencil_lut_tables_create, histencil_lut_tables_destroy,
    HistencilLutTables, HistencilMaterial,
};
pub use materials::{
    histencil_lighting_check_materials, histencil_material_rows_write, HISTENCIL_MATERIAL_ROW_BYTES,
};
pub use shaders::{
    histencil_shaders_compile, histencil_shaders_destroy, histencil_shaders_load,
    histencil_shaders_write_includes, HistencilShaders,
};

use std::cell::RefCell;
use std::ffi::{c_char, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};

/// The major version of this header and library: a change that breaks the ABI raises it.
pub const HISTENCIL_VERSION_MAJOR: u32 = 0;
/// The minor version: calls and struct fields added without breaking the ABI.
pub const HISTENCIL_VERSION_MINOR: u32 = 1;
/// The patch version.
pub const HISTENCIL_VERSION_PATCH: u32 = 0;

/// What every call returns. On anything but `HISTENCIL_RESULT_SUCCESS`,
/// `histencil_last_error()` says what, on the calling thread.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HistencilResult {
    /// The call did what it says.
    Success = 0,
    /// A null or freed handle, a null pointer, a struct `size` histencil does not know, an
    /// unknown enum value or a count out of range: nothing was done.
    InvalidArgument = 1,
    /// A description histencil cannot make a lighting from (formats, BRDF names, frames in
    /// flight, stencil bits): nothing was made.
    BadSetup = 2,
    /// A frame that does not fit its lighting (a slot, lights, a view, targets): nothing was
    /// recorded.
    BadFrame = 3,
    /// A slot recorded and not declared finished (`histencil_lighting_slot_finished`): the
    /// recording, resize or destroy was refused, and nothing changed.
    InFlight = 4,
    /// Past one of the device's limits.
    DeviceLimit = 5,
    /// What this histencil does not do (yet), or a device that lacks what it needs.
    Unsupported = 6,
    /// A Vulkan call failed, or memory could not be allocated.
    Vulkan = 7,
    /// A bug in histencil (a panic, caught at the boundary): please report the message.
    Internal = 8,
}

/// An error on its way out: the result and the message `histencil_last_error` gives.
pub(crate) struct Failure {
    result: HistencilResult,
    message: String,
}

impl Failure {
    pub(crate) fn invalid(message: impl Into<String>) -> Self {
        Failure {
            result: HistencilResult::InvalidArgument,
            message: message.into(),
        }
    }
}

/// Refuses to destroy an object while one of its slots is in flight, naming the call that
/// declares a slot finished.
pub(crate) fn refuse_destroy_in_flight(in_flight: bool, slot_finished: &str) -> Outcome {
    if in_flight {
        return Err(Failure {
            result: HistencilResult::InFlight,
            message: format!(
                "frames in flight: destroy while a slot may still be read by the GPU: wait for \
                 those frames, and say so with {slot_finished}, first"
            ),
        });
    }
    Ok(())
}

impl From<histencil::Error> for Failure {
    fn from(e: histencil::Error) -> Self {
        use histencil::Error as E;
        let result = match &e {
            E::BadSetup(_)
            | E::Layout(_)
            | E::BrdfSet(_)
            | E::MissingFormat(_)
            | E::Lut(_)
            | E::LutUntabulable { .. }
            | E::LutTexturedParameters { .. }
            | E::TooManyMaterials { .. }
            | E::BadResolution { width: 0, .. }
            | E::BadResolution { height: 0, .. } => HistencilResult::BadSetup,
            E::BadFrame(_) | E::Plan(_) | E::Scene(_) | E::Lightmap(_) => HistencilResult::BadFrame,
            E::InFlight(_) => HistencilResult::InFlight,
            E::DeviceLimit(_) | E::LutTooLarge { .. } | E::BadResolution { .. } => {
                HistencilResult::DeviceLimit
            }
            E::Unsupported(_) | E::NoDevice(_) | E::Loading(_) => HistencilResult::Unsupported,
            // A Vulkan call or allocation that failed, a stalled GPU; and what a later version
            // adds (the enum is non-exhaustive), until it is sorted here.
            _ => HistencilResult::Vulkan,
        };
        Failure {
            result,
            message: e.to_string(),
        }
    }
}

pub(crate) type Outcome<T = ()> = Result<T, Failure>;

thread_local! {
    /// The message of the last failed call on this thread.
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

pub(crate) fn set_last_error(message: &str) {
    // A message with a NUL in it (from a name the engine passed) is cut there.
    let message = message.split('\0').next().unwrap_or_default();
    let message = CString::new(message).unwrap_or_default();
    LAST_ERROR.with(|last| *last.borrow_mut() = message);
}

/// Runs one call's body: its error becomes the result and the thread's last error, and a panic
/// is caught here, never unwinding into the engine's C or C++ frames.
pub(crate) fn call(body: impl FnOnce() -> Outcome) -> HistencilResult {
    match catch_unwind(AssertUnwindSafe(body)) {
        Ok(Ok(())) => HistencilResult::Success,
        Ok(Err(failure)) => {
            set_last_error(&failure.message);
            failure.result
        }
        Err(panic) => {
            let what = (panic.downcast_ref::<&str>().copied())
                .or_else(|| panic.downcast_ref::<String>().map(String::as_str))
                .unwrap_or("a panic without a message");
            set_last_error(&format!(
                "histencil panicked (a bug; please report it): {what}"
            ));
            HistencilResult::Internal
        }
    }
}

/// The message of the last call on this thread that did not succeed: UTF-8, never null, empty
/// when none failed. Valid until the next histencil call on this thread.
///
/// Thread safety: any thread; each thread has its own.
#[no_mangle]
pub extern "C" fn histencil_last_error() -> *const c_char {
    LAST_ERROR.with(|last| last.borrow().as_ptr())
}

/// The library's version, `(major << 22) | (minor << 12) | patch` as Vulkan packs its own: an
/// engine holds it against the `HISTENCIL_VERSION_*` of the header it was compiled with.
///
/// Thread safety: any thread.
#[no_mangle]
pub extern "C" fn histencil_version() -> u32 {
    (HISTENCIL_VERSION_MAJOR << 22) | (HISTENCIL_VERSION_MINOR << 12) | HISTENCIL_VERSION_PATCH
}

/// Refuses a struct whose `size` is not one this library knows (the C side's `sizeof`).
pub(crate) fn check_size<T>(what: &str, size: u32) -> Outcome {
    let known = std::mem::size_of::<T>();
    if size as usize != known {
        return Err(Failure::invalid(format!(
            "{what}.size is {size}, and this histencil knows {what} of {known} bytes: set it to \
             sizeof({what}), from the histencil.h this library was built with"
        )));
    }
    Ok(())
}

/// `ptr` as a reference, or an error naming it when null.
///
/// # Safety
/// A non-null `ptr` points at a live, aligned `T` for as long as the reference is used.
pub(crate) unsafe fn required<'a, T>(ptr: *const T, what: &str) -> Outcome<&'a T> {
    // SAFETY: the caller's: non-null means a live, aligned T.
    unsafe { ptr.as_ref() }.ok_or_else(|| Failure::invalid(format!("{what} is null")))
}

/// `count` elements at `ptr` as a slice: empty for a zero count (any pointer), an error for a
/// null pointer with a non-zero count.
///
/// # Safety
/// A non-null `ptr` points at `count` live, aligned `T`s for as long as the slice is used.
pub(crate) unsafe fn slice<'a, T>(ptr: *const T, count: u32, what: &str) -> Outcome<&'a [T]> {
    if count == 0 {
        return Ok(&[]);
    }
    if ptr.is_null() {
        return Err(Failure::invalid(format!(
            "{what} is null with a count of {count}"
        )));
    }
    // SAFETY: the caller's: `count` live, aligned elements at a non-null `ptr`.
    Ok(unsafe { std::slice::from_raw_parts(ptr, count as usize) })
}
