//! Driver quirks as data: where histencil shapes its work differently for one driver, the rule
//! lives in one table keyed by the driver Vulkan names (`VkDriverId`) and its version, each with
//! its reason, instead of branches on the device's type scattered through the passes. A report
//! prints the quirks in force with their reasons ([`Quirks::describe`], in every driver line), and [`crate::ContextDesc::general_path`]
//! turns them all off, so any device can run the path every other device takes.
//!
//! None of these changes an image: each shapes work whose result is the same bit for bit
//! (`tests/tests/techniques.rs` holds both tile sides and both classification shapes to it).

use ash::vk;

/// One way histencil's work is shaped for a driver.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Quirk {
    /// Tiled lighting in 8x8-pixel tiles instead of HDRP's 16x16 ([`crate::TileSide`]).
    SmallTiles,
    /// Tile classification one invocation per tile, reading its pixels in a loop, instead of a
    /// workgroup per tile combined in shared memory ([`crate::TileClassify`]).
    ClassifyPerInvocation,
}

impl Quirk {
    /// The quirk's name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Quirk::SmallTiles => "small-tiles",
            Quirk::ClassifyPerInvocation => "classify-per-invocation",
        }
    }
}

/// A row of the table: a quirk for a driver's versions, and why.
#[derive(Clone, Copy, Debug)]
pub struct QuirkRule {
    /// The driver, as `VkPhysicalDeviceDriverProperties::driverID` names it.
    pub driver: vk::DriverId,
    /// `VkPhysicalDeviceProperties::driverVersion` from and to, inclusive (the driver's own
    /// encoding).
    pub versions: (u32, u32),
    /// What is shaped differently.
    pub quirk: Quirk,
    /// Why, with where it was measured.
    pub reason: &'static str,
}

/// Every version of a driver.
const ALL: (u32, u32) = (0, u32::MAX);

/// The table. A driver not named here takes the general path.
pub const QUIRKS: &[QuirkRule] = &[
    QuirkRule {
        driver: vk::DriverId::MESA_LLVMPIPE,
        versions: ALL,
        quirk: Quirk::SmallTiles,
        reason: "8x8 tiles as fast or faster within the noise wherever measured on lavapipe, and \
                 clearly faster with full-screen lights on a striped wall and on town (README)",
    },
    QuirkRule {
        driver: vk::DriverId::MESA_LLVMPIPE,
        versions: ALL,
        quirk: Quirk::ClassifyPerInvocation,
        reason: "llvmpipe runs a workgroup with barriers one invocation at a time, switching at \
                 each barrier",
    },
    QuirkRule {
        driver: vk::DriverId::GOOGLE_SWIFTSHADER,
        versions: ALL,
        quirk: Quirk::SmallTiles,
        reason: "a CPU rasteriser, which took llvmpipe's shape when the rule was the device type; \
                 not measured on SwiftShader itself",
    },
    QuirkRule {
        driver: vk::DriverId::GOOGLE_SWIFTSHADER,
        versions: ALL,
        quirk: Quirk::ClassifyPerInvocation,
        reason: "a CPU rasteriser, which took llvmpipe's shape when the rule was the device type; \
                 not measured on SwiftShader itself",
    },
];

/// The quirks in force on one device.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Quirks {
    rules: Vec<QuirkRule>,
}

impl PartialEq for QuirkRule {
    fn eq(&self, other: &Self) -> bool {
        (self.driver, self.versions, self.quirk) == (other.driver, other.versions, other.quirk)
    }
}

impl Eq for QuirkRule {}

impl Quirks {
    /// The rules of `table` that name `driver` at `version`.
    pub fn of(table: &[QuirkRule], driver: vk::DriverId, version: u32) -> Self {
        let rules = table
            .iter()
            .filter(|r| r.driver == driver && (r.versions.0..=r.versions.1).contains(&version))
            .copied()
            .collect();
        Self { rules }
    }

    /// No quirk: the general path.
    pub fn none() -> Self {
        Self::default()
    }

    /// Whether `quirk` is in force.
    pub fn has(&self, quirk: Quirk) -> bool {
        self.rules.iter().any(|r| r.quirk == quirk)
    }

    /// `small-tiles, classify-per-invocation`, or `none`: the quirks' names.
    pub fn names(&self) -> String {
        if self.rules.is_empty() {
            return "none".into();
        }
        let names: Vec<_> = self.rules.iter().map(|r| r.quirk.name()).collect();
        names.join(", ")
    }

    /// What a report's driver line says: each quirk in force with its reason,
    /// `small-tiles (why: ...), classify-per-invocation (why: ...)`, or `none`. A reader of a
    /// report from a device whose work was shaped differently learns how, and on what evidence,
    /// without the source.
    pub fn describe(&self) -> String {
        if self.rules.is_empty() {
            return "none".into();
        }
        let rules: Vec<_> = self
            .rules
            .iter()
            .map(|r| format!("{} (why: {})", r.quirk.name(), r.reason))
            .collect();
        rules.join(", ")
    }

    /// The rules in force, with their reasons.
    pub fn rules(&self) -> &[QuirkRule] {
        &self.rules
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cpu_rasterisers_take_their_shapes_and_every_other_driver_the_general_path() {
        for driver in [
            vk::DriverId::MESA_LLVMPIPE,
            vk::DriverId::GOOGLE_SWIFTSHADER,
        ] {
            let q = Quirks::of(QUIRKS, driver, 0);
            assert!(q.has(Quirk::SmallTiles) && q.has(Quirk::ClassifyPerInvocation));
            assert_eq!(q.names(), "small-tiles, classify-per-invocation");
            let line = q.describe();
            assert!(line.starts_with("small-tiles (why: "), "{line}");
            assert!(line.contains("), classify-per-invocation (why: "), "{line}");
            assert!(q.rules().iter().all(|r| line.contains(r.reason)), "{line}");
        }
        for driver in [
            vk::DriverId::NVIDIA_PROPRIETARY,
            vk::DriverId::MESA_RADV,
            vk::DriverId::MESA_TURNIP,
        ] {
            let q = Quirks::of(QUIRKS, driver, 7);
            assert_eq!(q, Quirks::none());
            assert_eq!((q.names(), q.describe()), ("none".into(), "none".into()));
        }
    }

    #[test]
    fn a_rule_holds_only_for_its_versions() {
        let table = [QuirkRule {
            driver: vk::DriverId::MESA_RADV,
            versions: (10, 20),
            quirk: Quirk::SmallTiles,
            reason: "a test",
        }];
        assert!(!Quirks::of(&table, vk::DriverId::MESA_RADV, 9).has(Quirk::SmallTiles));
        assert!(Quirks::of(&table, vk::DriverId::MESA_RADV, 10).has(Quirk::SmallTiles));
        assert!(Quirks::of(&table, vk::DriverId::MESA_RADV, 20).has(Quirk::SmallTiles));
        assert!(!Quirks::of(&table, vk::DriverId::MESA_RADV, 21).has(Quirk::SmallTiles));
        assert!(!Quirks::of(&table, vk::DriverId::MESA_TURNIP, 15).has(Quirk::SmallTiles));
    }
}
