//! What histencil needs of a Vulkan device, as data. An engine that lends histencil its own
//! device ([`crate::Context::from_raw`]) enables these when it creates that device, merged with
//! its own; [`DeviceRequirements::missing`] says beforehand what a physical device lacks.
//! histencil's own [`crate::Context::new`] enables exactly these.

use ash::vk;
use std::ffi::CStr;

/// Vulkan version, features and queue histencil records with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DeviceRequirements {
    /// `VK_API_VERSION_1_3`: dynamic rendering and synchronisation 2 are core there.
    pub api_version: u32,
    /// `depthClamp`: light volumes crossing the far plane keep their back faces at the far depth.
    pub depth_clamp: bool,
    /// `fragmentStoresAndAtomics`: the hi-stencil emulation marks and counts tiles from fragment
    /// shaders (every desktop driver and lavapipe have it).
    pub fragment_stores_and_atomics: bool,
    /// Vulkan 1.3 `dynamicRendering`: passes render without render-pass objects.
    pub dynamic_rendering: bool,
    /// Vulkan 1.3 `synchronization2`: every barrier is a `vkCmdPipelineBarrier2`.
    pub synchronization2: bool,
    /// Device extensions beyond the core version: none.
    pub device_extensions: &'static [&'static CStr],
    /// The queue family's capabilities: graphics (compute is implied), and timestamps for the
    /// per-pass timings.
    pub queue_flags: vk::QueueFlags,
    /// The queue family writes timestamps (`timestampValidBits` above 0), for the timings.
    pub timestamps: bool,
}

/// What histencil needs.
pub const REQUIREMENTS: DeviceRequirements = DeviceRequirements {
    api_version: vk::API_VERSION_1_3,
    depth_clamp: true,
    fragment_stores_and_atomics: true,
    dynamic_rendering: true,
    synchronization2: true,
    device_extensions: &[],
    queue_flags: vk::QueueFlags::GRAPHICS,
    timestamps: true,
};

impl DeviceRequirements {
    /// Core features to enable (`VkDeviceCreateInfo::pEnabledFeatures`, or merged into the
    /// engine's own).
    pub fn features(&self) -> vk::PhysicalDeviceFeatures {
        vk::PhysicalDeviceFeatures::default()
            .depth_clamp(self.depth_clamp)
            .fragment_stores_and_atomics(self.fragment_stores_and_atomics)
    }

    /// Vulkan 1.3 features to chain into `VkDeviceCreateInfo`.
    pub fn features13(&self) -> vk::PhysicalDeviceVulkan13Features<'static> {
        vk::PhysicalDeviceVulkan13Features::default()
            .dynamic_rendering(self.dynamic_rendering)
            .synchronization2(self.synchronization2)
    }

    /// Whether queue family `family` of `physical_device` can run histencil's work.
    ///
    /// # Safety
    /// `physical_device` was enumerated from `instance`, which is alive.
    pub unsafe fn queue_family_fits(
        &self,
        instance: &ash::Instance,
        physical_device: vk::PhysicalDevice,
        family: u32,
    ) -> bool {
        // SAFETY: the caller upholds this fn's # Safety: `physical_device` belongs to the live
        // `instance` (a Vulkan 1.0 query, needing nothing more).
        let families =
            unsafe { instance.get_physical_device_queue_family_properties(physical_device) };
        families.get(family as usize).is_some_and(|f| {
            f.queue_flags.contains(self.queue_flags)
                && (!self.timestamps || f.timestamp_valid_bits > 0)
        })
    }

    /// What `physical_device` lacks, by Vulkan name; empty when it has everything. A device
    /// cannot be asked which features were enabled on it, so an engine that lends its device
    /// promises that separately ([`crate::Context::from_raw`]).
    ///
    /// # Safety
    /// `physical_device` was enumerated from `instance`, which is alive and was created with an
    /// `apiVersion` of 1.3 or later (the features are read with `vkGetPhysicalDeviceFeatures2`,
    /// Vulkan 1.3's among them).
    pub unsafe fn missing(
        &self,
        instance: &ash::Instance,
        physical_device: vk::PhysicalDevice,
    ) -> Vec<String> {
        // SAFETY: the caller upholds this fn's # Safety: `physical_device` belongs to the live
        // `instance`.
        let props = unsafe { instance.get_physical_device_properties(physical_device) };
        let mut missing = Vec::new();
        if props.api_version < self.api_version {
            missing.push(format!(
                "Vulkan {}.{} (the device has {}.{})",
                vk::api_version_major(self.api_version),
                vk::api_version_minor(self.api_version),
                vk::api_version_major(props.api_version),
                vk::api_version_minor(props.api_version)
            ));
            return missing;
        }
        let mut features13 = vk::PhysicalDeviceVulkan13Features::default();
        let mut features = vk::PhysicalDeviceFeatures2::default().push_next(&mut features13);
        // SAFETY: this fn's # Safety: `physical_device` is `instance`'s, an instance of 1.3 or
        // later, and the device is at 1.3 too (checked just above): the query (core in 1.1)
        // and the chained `features13` are both supported. Both structs outlive the call.
        unsafe { instance.get_physical_device_features2(physical_device, &mut features) };
        let core = features.features;
        let wanted = [
            ("depthClamp", self.depth_clamp, core.depth_clamp),
            (
                "fragmentStoresAndAtomics",
                self.fragment_stores_and_atomics,
                core.fragment_stores_and_atomics,
            ),
            (
                "dynamicRendering",
                self.dynamic_rendering,
                features13.dynamic_rendering,
            ),
            (
                "synchronization2",
                self.synchronization2,
                features13.synchronization2,
            ),
        ];
        for (name, needed, has) in wanted {
            if needed && has == vk::FALSE {
                missing.push(name.to_string());
            }
        }
        if !self.device_extensions.is_empty() {
            // SAFETY: this fn's # Safety: `physical_device` belongs to the live `instance`.
            let available =
                unsafe { instance.enumerate_device_extension_properties(physical_device) }
                    .unwrap_or_default();
            for ext in self.device_extensions {
                if !available
                    .iter()
                    .any(|e| e.extension_name_as_c_str() == Ok(*ext))
                {
                    missing.push(ext.to_string_lossy().into_owned());
                }
            }
        }
        missing
    }
}
