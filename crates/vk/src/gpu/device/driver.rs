//! What a report must say about the device under test besides its name.
//!
//! Two lavapipe builds call their device by the same name (`llvmpipe (LLVM 15.0.6, 256 bits)`
//! for both Mesa 22.3.6 and 25.0.7), so a report that names only the device cannot tell two
//! drivers apart: [`DriverInfo`] carries what `VkPhysicalDeviceDriverProperties` says, and the
//! validation layer's own version. The proof that the layer is listening is the canary's
//! (`canary.rs`).

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
    let limits = crate::gpu::device::limits::describe(
        crate::gpu::device::limits::NEEDS,
        &crate::gpu::device::limits::DeviceLimits::new(&props.properties.limits),
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
