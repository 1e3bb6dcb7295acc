//! What a report must say about the device under test besides its name, and the proof that the
//! validation layer is listening.
//!
//! Two lavapipe builds call their device by the same name (`llvmpipe (LLVM 15.0.6, 256 bits)`
//! for both Mesa 22.3.6 and 25.0.7), so a report that names only the device cannot tell two
//! drivers apart: [`DriverInfo`] carries what `VkPhysicalDeviceDriverProperties` says, and the
//! validation layer's own version.
//!
//! A validation verdict rests on the layer reporting what it finds, and the layer reads settings
//! from the environment and from `vk_layer_settings.txt` that can silence it (a message-id
//! filter, a duplicate-message limit, disabled checks). [`Context::validation_canary`] makes one
//! known invalid call on purpose, [`CANARY_CALLS`] times, and counts what came back: anything
//! short of every call reported means the verdict cannot be trusted.

use crate::gpu::context::Context;
use ash::vk;
use std::ffi::CStr;
use std::fmt;

/// The device's driver as Vulkan names it, and the validation layer in use.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct DriverInfo {
    /// `VkPhysicalDeviceDriverProperties::driverName`, e.g. `llvmpipe`.
    pub name: String,
    /// `driverInfo`, e.g. `Mesa 25.0.7-2~bpo12+1 (LLVM 19.1.7)`: the build that tells two
    /// releases of one driver apart.
    pub info: String,
    /// The Vulkan conformance test suite version the driver claims, `major.minor.sub.patch`
    /// (`0.0.0.0` for a driver that claims none).
    pub conformance: String,
    /// The device's Vulkan version, `major.minor.patch`.
    pub api_version: String,
    /// `VK_LAYER_KHRONOS_validation`'s version (`spec version, implementation version`) where
    /// the layer is enabled; `None` without validation or on a lent device.
    pub validation_layer: Option<String>,
    /// `driverID`: what the quirk table is keyed by ([`crate::QUIRKS`]).
    pub id: vk::DriverId,
    /// `VkPhysicalDeviceProperties::driverVersion`, in the driver's own encoding.
    pub version: u32,
    /// The quirks in force on the device with their reasons, as [`crate::Quirks::describe`]
    /// writes them.
    pub quirks: String,
    /// The device limits histencil needs above the spec's minimum, with the device's values, as
    /// [`crate::describe_limits`] writes them.
    pub limits: String,
}

impl fmt::Display for DriverInfo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} ({}), Vulkan {}, conformance {}, quirks: {}, limits: {}",
            self.name, self.info, self.api_version, self.conformance, self.quirks, self.limits
        )?;
        if let Some(layer) = &self.validation_layer {
            write!(f, ", validation layer {layer}")?;
        }
        Ok(())
    }
}

fn version_text(v: u32) -> String {
    format!(
        "{}.{}.{}",
        vk::api_version_major(v),
        vk::api_version_minor(v),
        vk::api_version_patch(v)
    )
}

fn c_text(bytes: &[std::ffi::c_char]) -> String {
    // SAFETY-free: the arrays are NUL-terminated by the Vulkan spec; a missing NUL reads as empty.
    let bytes: Vec<u8> = bytes.iter().map(|&c| c as u8).collect();
    CStr::from_bytes_until_nul(&bytes)
        .map(|c| c.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// The driver properties of `physical_device`.
///
/// # Safety
/// `physical_device` was enumerated from the live `instance`, and both are at Vulkan 1.2 or
/// later (the instance was created with such an `apiVersion`): `VkPhysicalDeviceDriverProperties`
/// is core there.
pub(crate) unsafe fn driver_info(
    instance: &ash::Instance,
    physical_device: vk::PhysicalDevice,
    validation_layer: Option<String>,
) -> DriverInfo {
    let mut driver = vk::PhysicalDeviceDriverProperties::default();
    let mut props = vk::PhysicalDeviceProperties2::default().push_next(&mut driver);
    // SAFETY: the caller upholds this fn's # Safety: `physical_device` is `instance`'s, and
    // both are at Vulkan 1.2 or later, where `get_physical_device_properties2` (1.1) and the
    // chained `driver` struct (1.2) are core. `props` and `driver` outlive the call.
    unsafe { instance.get_physical_device_properties2(physical_device, &mut props) };
    let api_version = version_text(props.properties.api_version);
    let driver_version = props.properties.driver_version;
    let limits = crate::gpu::limits::describe(
        crate::gpu::limits::NEEDS,
        &crate::gpu::limits::DeviceLimits::new(&props.properties.limits),
    );
    let c = driver.conformance_version;
    DriverInfo {
        name: c_text(&driver.driver_name),
        info: c_text(&driver.driver_info),
        conformance: format!("{}.{}.{}.{}", c.major, c.minor, c.subminor, c.patch),
        api_version,
        validation_layer,
        id: driver.driver_id,
        version: driver_version,
        quirks: String::new(),
        limits,
    }
}

/// The version of `layer` as `vkEnumerateInstanceLayerProperties` gives it.
pub(crate) fn layer_version(props: &vk::LayerProperties) -> String {
    format!(
        "{} (implementation {})",
        version_text(props.spec_version),
        props.implementation_version
    )
}

/// How many times the canary makes its invalid call: more than the layer's default duplicate
/// limit (10 in the layer's manifest), so a limit in force shows as missing reports.
pub const CANARY_CALLS: usize = 12;

/// The message id the canary's call must draw: a buffer of size zero.
pub const CANARY_ID: &str = "VUID-VkBufferCreateInfo-size-00912";

/// What the canary saw.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Canary {
    /// Invalid calls made.
    pub calls: usize,
    /// Of them, reported by the layer with [`CANARY_ID`].
    pub reported: usize,
}

impl Canary {
    /// Every call was reported: the layer is listening and repeats itself.
    pub fn heard(&self) -> bool {
        self.reported >= self.calls
    }
}

impl fmt::Display for Canary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} of {} deliberate {CANARY_ID} calls reported by the validation layer",
            self.reported, self.calls
        )
    }
}

impl Context {
    /// Makes [`CANARY_CALLS`] deliberately invalid `vkCreateBuffer` calls (size zero) and counts
    /// the validation messages with [`CANARY_ID`] that arrived for them. Their messages stay in
    /// the log: take a mark after this call. On a context without validation (or a lent one,
    /// whose messages go to the engine's messenger) `reported` is 0.
    ///
    /// The layer is asked to stop each call it reports (histencil's messenger returns TRUE for
    /// [`CANARY_ID`], and the layer then returns `VK_ERROR_VALIDATION_FAILED_EXT`). A muted layer
    /// reports nothing and so passes the call on: the driver sees a buffer of size zero, which
    /// the drivers tried (lavapipe 22.3.6 and 25.0.7) create; it is destroyed at once.
    pub fn validation_canary(&self) -> Canary {
        let log = self.validation_log();
        let mark = log.len();
        let info = vk::BufferCreateInfo::default()
            .size(0)
            .usage(vk::BufferUsageFlags::STORAGE_BUFFER)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        for _ in 0..CANARY_CALLS {
            // SAFETY: invalid on purpose (size zero). A listening layer stops it; a muted one
            // passes it to the driver, and a buffer made of it is destroyed before any use.
            if let Ok(buffer) = unsafe { self.device.create_buffer(&info, None) } {
                // SAFETY: the buffer was just made, never bound or used.
                unsafe { self.device.destroy_buffer(buffer, None) };
            }
        }
        let reported = log.since(mark).iter().filter(|m| m.id == CANARY_ID).count();
        Canary {
            calls: CANARY_CALLS,
            reported,
        }
    }
}
