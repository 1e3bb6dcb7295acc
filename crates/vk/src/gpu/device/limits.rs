//! The device limits histencil's own work reaches above what the Vulkan spec guarantees every
//! device ("Required Limits"), as data: each limit with the spec's minimum, what histencil needs
//! at most and why ([`NEEDS`]). Every driver line reports them against the device
//! ([`describe`]), and the pipeline layouts and pipelines check the device's value before Vulkan
//! sees them ([`crate::Context`] records the largest need met), so a device below a need gets an
//! error that names the limit, never a driver's undefined behaviour.

use ash::vk;

/// What a binding holds: the subset of Vulkan's descriptor types histencil's shaders use
/// (separate images and samplers, no combined image samplers), and the kinds the device's
/// per-kind descriptor limits count (`SetCounts`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BindingKind {
    /// A `uniform` block (`UNIFORM_BUFFER`).
    UniformBuffer,
    /// A `buffer` block (`STORAGE_BUFFER`).
    StorageBuffer,
    /// A `texture2D` (`SAMPLED_IMAGE`).
    SampledImage,
    /// A `sampler` (`SAMPLER`).
    Sampler,
    /// An `image2D` written by a compute pass (`STORAGE_IMAGE`).
    StorageImage,
}

impl BindingKind {
    /// Every kind, in the order of `SetCounts`' counts.
    pub const ALL: [BindingKind; 5] = [
        BindingKind::UniformBuffer,
        BindingKind::StorageBuffer,
        BindingKind::SampledImage,
        BindingKind::Sampler,
        BindingKind::StorageImage,
    ];

    pub(crate) fn descriptor_type(self) -> vk::DescriptorType {
        match self {
            BindingKind::UniformBuffer => vk::DescriptorType::UNIFORM_BUFFER,
            BindingKind::StorageBuffer => vk::DescriptorType::STORAGE_BUFFER,
            BindingKind::SampledImage => vk::DescriptorType::SAMPLED_IMAGE,
            BindingKind::Sampler => vk::DescriptorType::SAMPLER,
            BindingKind::StorageImage => vk::DescriptorType::STORAGE_IMAGE,
        }
    }
}

/// A `VkPhysicalDeviceLimits` member histencil's work depends on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Limit {
    /// `maxBoundDescriptorSets`: the sets one pipeline layout holds.
    BoundDescriptorSets,
    /// `maxPushConstantsSize`: bytes of one pipeline layout's push constants.
    PushConstantsSize,
    /// `maxPerStageDescriptorUniformBuffers`.
    PerStageUniformBuffers,
    /// `maxPerStageDescriptorStorageBuffers`.
    PerStageStorageBuffers,
    /// `maxPerStageDescriptorSampledImages`.
    PerStageSampledImages,
    /// `maxPerStageDescriptorSamplers`.
    PerStageSamplers,
    /// `maxPerStageDescriptorStorageImages`.
    PerStageStorageImages,
    /// `maxPerStageResources`: every descriptor of a stage (the spec adds a fragment stage's
    /// colour attachments, at most 4 here, against a minimum of 128).
    PerStageResources,
    /// `maxDescriptorSetStorageBuffers`: storage buffers over a pipeline layout's sets.
    SetStorageBuffers,
    /// `maxDescriptorSetSampledImages`.
    SetSampledImages,
    /// `maxColorAttachments`: the colour targets one graphics pipeline renders.
    ColorAttachments,
    /// `maxComputeWorkGroupInvocations`: invocations of one workgroup.
    ComputeWorkGroupInvocations,
    /// `maxComputeWorkGroupSize[0]` (the y size is the same for every square workgroup
    /// histencil dispatches, and its minimum is the same).
    ComputeWorkGroupSize,
}

impl Limit {
    /// Every limit, in report order.
    pub const ALL: [Limit; 13] = [
        Limit::BoundDescriptorSets,
        Limit::PushConstantsSize,
        Limit::PerStageUniformBuffers,
        Limit::PerStageStorageBuffers,
        Limit::PerStageSampledImages,
        Limit::PerStageSamplers,
        Limit::PerStageStorageImages,
        Limit::PerStageResources,
        Limit::SetStorageBuffers,
        Limit::SetSampledImages,
        Limit::ColorAttachments,
        Limit::ComputeWorkGroupInvocations,
        Limit::ComputeWorkGroupSize,
    ];

    /// The member's name in the Vulkan spec.
    pub fn vk_name(self) -> &'static str {
        match self {
            Limit::BoundDescriptorSets => "maxBoundDescriptorSets",
            Limit::PushConstantsSize => "maxPushConstantsSize",
            Limit::PerStageUniformBuffers => "maxPerStageDescriptorUniformBuffers",
            Limit::PerStageStorageBuffers => "maxPerStageDescriptorStorageBuffers",
            Limit::PerStageSampledImages => "maxPerStageDescriptorSampledImages",
            Limit::PerStageSamplers => "maxPerStageDescriptorSamplers",
            Limit::PerStageStorageImages => "maxPerStageDescriptorStorageImages",
            Limit::PerStageResources => "maxPerStageResources",
            Limit::SetStorageBuffers => "maxDescriptorSetStorageBuffers",
            Limit::SetSampledImages => "maxDescriptorSetSampledImages",
            Limit::ColorAttachments => "maxColorAttachments",
            Limit::ComputeWorkGroupInvocations => "maxComputeWorkGroupInvocations",
            Limit::ComputeWorkGroupSize => "maxComputeWorkGroupSize",
        }
    }

    /// What every Vulkan 1.3 device offers at least (the spec's "Required Limits" table).
    pub fn spec_minimum(self) -> u32 {
        match self {
            Limit::BoundDescriptorSets => 4,
            Limit::PushConstantsSize => 128,
            Limit::PerStageUniformBuffers => 12,
            Limit::PerStageStorageBuffers => 4,
            Limit::PerStageSampledImages => 16,
            Limit::PerStageSamplers => 16,
            Limit::PerStageStorageImages => 4,
            Limit::PerStageResources => 128,
            Limit::SetStorageBuffers => 24,
            Limit::SetSampledImages => 96,
            Limit::ColorAttachments => 4,
            Limit::ComputeWorkGroupInvocations => 128,
            Limit::ComputeWorkGroupSize => 128,
        }
    }

    /// The device's value.
    pub fn of(self, limits: &vk::PhysicalDeviceLimits) -> u32 {
        match self {
            Limit::BoundDescriptorSets => limits.max_bound_descriptor_sets,
            Limit::PushConstantsSize => limits.max_push_constants_size,
            Limit::PerStageUniformBuffers => limits.max_per_stage_descriptor_uniform_buffers,
            Limit::PerStageStorageBuffers => limits.max_per_stage_descriptor_storage_buffers,
            Limit::PerStageSampledImages => limits.max_per_stage_descriptor_sampled_images,
            Limit::PerStageSamplers => limits.max_per_stage_descriptor_samplers,
            Limit::PerStageStorageImages => limits.max_per_stage_descriptor_storage_images,
            Limit::PerStageResources => limits.max_per_stage_resources,
            Limit::SetStorageBuffers => limits.max_descriptor_set_storage_buffers,
            Limit::SetSampledImages => limits.max_descriptor_set_sampled_images,
            Limit::ColorAttachments => limits
                .max_color_attachments
                .min(limits.max_fragment_output_attachments),
            Limit::ComputeWorkGroupInvocations => limits.max_compute_work_group_invocations,
            Limit::ComputeWorkGroupSize => {
                limits.max_compute_work_group_size[0].min(limits.max_compute_work_group_size[1])
            }
        }
    }

    fn index(self) -> usize {
        Limit::ALL.iter().position(|&l| l == self).unwrap_or(0)
    }
}

/// One limit histencil's own pipelines can reach: the most any of them needs, and why.
#[derive(Clone, Copy, Debug)]
pub struct Need {
    /// The limit.
    pub limit: Limit,
    /// The most histencil's own pipelines need (an engine's hooks can add to the descriptor
    /// counts; their pipelines are checked as they are made).
    pub most: u32,
    /// Which work needs that much.
    pub why: &'static str,
    /// What histencil does instead on a device that offers less, where it has a smaller shape
    /// of the work; `None`: the work is refused ([`crate::Error::DeviceLimit`]).
    pub instead: Option<&'static str>,
}

/// What histencil's own pipelines need at most. `tests/tests/techniques.rs` builds every
/// technique on one context and holds this table to what was recorded (`assert_needs_hold`), so
/// it cannot drift from the code.
pub const NEEDS: &[Need] = &[
    Need {
        limit: Limit::BoundDescriptorSets,
        most: 4,
        why: "the tiled technique with an engine's visibility hook folded into set 1",
        instead: None,
    },
    Need {
        limit: Limit::PerStageStorageBuffers,
        most: 7,
        why: "every light pipeline's layout: the lights, the hi-stencil emulation's four \
              buffers and the LUT technique's two tables (the tiled kernels: the lights, four \
              tile buffers and the two tables); Roadmap 2022 devices offer 30",
        instead: None,
    },
    Need {
        limit: Limit::ComputeWorkGroupInvocations,
        most: 256,
        why: "16x16 tiles, one invocation per pixel",
        instead: Some("8x8 tiles"),
    },
    Need {
        limit: Limit::ComputeWorkGroupSize,
        most: 16,
        why: "16x16 tiles",
        instead: Some("8x8 tiles"),
    },
];

/// The device's value of every [`Limit`], read once.
#[derive(Clone, Copy, Debug, Default)]
pub struct DeviceLimits([u32; Limit::ALL.len()]);

impl DeviceLimits {
    /// The values of `limits`.
    pub fn new(limits: &vk::PhysicalDeviceLimits) -> Self {
        Self(Limit::ALL.map(|l| l.of(limits)))
    }

    /// These values capped at the spec's minimum: a device that offers no more than every
    /// device must ([`crate::ContextDesc::spec_minimum_limits`]).
    pub fn at_spec_minimum(self) -> Self {
        let mut capped = self;
        for (v, l) in capped.0.iter_mut().zip(Limit::ALL) {
            *v = (*v).min(l.spec_minimum());
        }
        capped
    }

    /// The device's value of `limit`.
    pub fn get(&self, limit: Limit) -> u32 {
        self.0[limit.index()]
    }

    /// Says why not when `need` passes the device's `limit`; `what` names the work.
    pub fn check(&self, limit: Limit, need: u32, what: &str) -> Result<(), String> {
        let has = self.get(limit);
        if need <= has {
            return Ok(());
        }
        Err(format!(
            "{what} needs {need} for {} and this device offers {has} (every device offers {})",
            limit.vk_name(),
            limit.spec_minimum()
        ))
    }
}

/// The largest need of each [`Limit`] met so far on a context.
#[derive(Debug, Default)]
pub(crate) struct LimitsUsed(std::sync::Mutex<[u32; Limit::ALL.len()]>);

impl LimitsUsed {
    /// Notes `need` of `limit`.
    pub fn note(&self, limit: Limit, need: u32) {
        let mut used = self.0.lock().unwrap_or_else(|e| e.into_inner());
        let slot = &mut used[limit.index()];
        *slot = (*slot).max(need);
    }

    /// The largest need of `limit` noted.
    pub fn get(&self, limit: Limit) -> u32 {
        self.0.lock().unwrap_or_else(|e| e.into_inner())[limit.index()]
    }
}

/// The report's `limits:` text: histencil's needs above the spec's minimum, each with the
/// device's value, and whether all are met (a need unmet turns that work into an error that
/// names the limit, or into a smaller shape where one exists: 8x8 tiles).
pub fn describe(needs: &[Need], device: &DeviceLimits) -> String {
    let above: Vec<&Need> = needs
        .iter()
        .filter(|n| n.most > n.limit.spec_minimum())
        .collect();
    if above.is_empty() {
        return "every need within the spec's minimums".into();
    }
    let unmet: Vec<String> = above
        .iter()
        .filter(|n| device.get(n.limit) < n.most)
        .map(|n| {
            let instead = n.instead.map(|i| format!(": {i}")).unwrap_or_default();
            format!(
                "{} {} < {}{instead}",
                n.limit.vk_name(),
                device.get(n.limit),
                n.most
            )
        })
        .collect();
    let listed: Vec<String> = above
        .iter()
        .map(|n| {
            format!(
                "{} {} (spec {})",
                n.limit.vk_name(),
                n.most,
                n.limit.spec_minimum()
            )
        })
        .collect();
    let verdict = if unmet.is_empty() {
        "all met".to_string()
    } else {
        format!("unmet: {}", unmet.join(", "))
    };
    format!(
        "{} above the spec's minimum ({}), {verdict}",
        above.len(),
        listed.join(", ")
    )
}

/// The descriptors of a set layout's bindings that share one stage mask, by kind: what the
/// per-stage and per-set limits are checked against (a layout is one or more of these).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct SetCounts {
    /// The stages these bindings are visible to.
    pub stages: vk::ShaderStageFlags,
    /// Descriptors per kind, indexed as [`BindingKind::ALL`].
    kinds: [u32; BindingKind::ALL.len()],
}

impl SetCounts {
    /// No descriptor yet, visible to `stages`.
    pub fn new(stages: vk::ShaderStageFlags) -> Self {
        Self {
            stages,
            kinds: [0; BindingKind::ALL.len()],
        }
    }

    /// Counts `count` more descriptors of `kind`.
    pub fn add(&mut self, kind: BindingKind, count: u32) {
        self.kinds[kind as usize] += count;
    }

    /// The descriptors of `kind`.
    pub fn of(&self, kind: BindingKind) -> u32 {
        self.kinds[kind as usize]
    }

    /// The counts of an engine's layout from the bindings it was created with, one entry per
    /// distinct stage mask (descriptor types histencil's limits do not track are not counted).
    pub fn of_bindings(bindings: &[vk::DescriptorSetLayoutBinding]) -> Vec<SetCounts> {
        let mut groups: Vec<SetCounts> = Vec::new();
        for b in bindings {
            let kinds: &[BindingKind] =
                match b.descriptor_type {
                    vk::DescriptorType::UNIFORM_BUFFER
                    | vk::DescriptorType::UNIFORM_BUFFER_DYNAMIC => &[BindingKind::UniformBuffer],
                    vk::DescriptorType::STORAGE_BUFFER
                    | vk::DescriptorType::STORAGE_BUFFER_DYNAMIC => &[BindingKind::StorageBuffer],
                    vk::DescriptorType::SAMPLED_IMAGE
                    | vk::DescriptorType::UNIFORM_TEXEL_BUFFER => &[BindingKind::SampledImage],
                    vk::DescriptorType::SAMPLER => &[BindingKind::Sampler],
                    vk::DescriptorType::STORAGE_IMAGE
                    | vk::DescriptorType::STORAGE_TEXEL_BUFFER => &[BindingKind::StorageImage],
                    // A sampled image and a sampler, each counted against its limit.
                    vk::DescriptorType::COMBINED_IMAGE_SAMPLER => {
                        &[BindingKind::SampledImage, BindingKind::Sampler]
                    }
                    _ => &[],
                };
            for kind in kinds {
                group(&mut groups, b.stage_flags).add(*kind, b.descriptor_count);
            }
        }
        groups
    }
}

/// The entry of `groups` for `stages`, added where missing.
fn group(groups: &mut Vec<SetCounts>, stages: vk::ShaderStageFlags) -> &mut SetCounts {
    let at = match groups.iter().position(|g| g.stages == stages) {
        Some(i) => i,
        None => {
            groups.push(SetCounts::new(stages));
            groups.len() - 1
        }
    };
    &mut groups[at]
}

/// The per-stage limit on descriptors of `kind`.
fn per_stage_limit(kind: BindingKind) -> Limit {
    match kind {
        BindingKind::UniformBuffer => Limit::PerStageUniformBuffers,
        BindingKind::StorageBuffer => Limit::PerStageStorageBuffers,
        BindingKind::SampledImage => Limit::PerStageSampledImages,
        BindingKind::Sampler => Limit::PerStageSamplers,
        BindingKind::StorageImage => Limit::PerStageStorageImages,
    }
}

/// The per-stage and per-layout needs of a pipeline layout of `set_count` sets whose bindings
/// are `sets` (a set may be several entries, one per stage mask), with `push_constant_bytes`:
/// `(limit, need)` pairs, the largest over its stages.
pub(crate) fn layout_needs(
    sets: &[SetCounts],
    set_count: u32,
    push_constant_bytes: u32,
) -> Vec<(Limit, u32)> {
    let mut needs = vec![
        (Limit::BoundDescriptorSets, set_count),
        (Limit::PushConstantsSize, push_constant_bytes),
    ];
    let stages = [
        vk::ShaderStageFlags::VERTEX,
        vk::ShaderStageFlags::FRAGMENT,
        vk::ShaderStageFlags::COMPUTE,
    ];
    let mut most = [0u32; BindingKind::ALL.len()];
    let mut resources = 0;
    for stage in stages {
        let visible = || sets.iter().filter(|s| s.stages.contains(stage));
        let sum = BindingKind::ALL.map(|kind| visible().map(|s| s.of(kind)).sum::<u32>());
        for (m, s) in most.iter_mut().zip(sum) {
            *m = (*m).max(s);
        }
        resources = resources.max(sum.iter().sum::<u32>());
    }
    needs.extend(BindingKind::ALL.map(per_stage_limit).into_iter().zip(most));
    needs.push((Limit::PerStageResources, resources));
    let total = |kind| sets.iter().map(|s| s.of(kind)).sum::<u32>();
    needs.push((Limit::SetStorageBuffers, total(BindingKind::StorageBuffer)));
    needs.push((Limit::SetSampledImages, total(BindingKind::SampledImage)));
    needs
}

#[cfg(test)]
mod tests {
    use super::*;

    fn device(f: impl FnOnce(&mut vk::PhysicalDeviceLimits)) -> DeviceLimits {
        let mut l = vk::PhysicalDeviceLimits::default();
        for limit in Limit::ALL {
            // Every device at the spec's minimum: no member is shared between two limits
            // except the two halves of ColorAttachments and ComputeWorkGroupSize.
            let min = limit.spec_minimum();
            match limit {
                Limit::BoundDescriptorSets => l.max_bound_descriptor_sets = min,
                Limit::PushConstantsSize => l.max_push_constants_size = min,
                Limit::PerStageUniformBuffers => l.max_per_stage_descriptor_uniform_buffers = min,
                Limit::PerStageStorageBuffers => l.max_per_stage_descriptor_storage_buffers = min,
                Limit::PerStageSampledImages => l.max_per_stage_descriptor_sampled_images = min,
                Limit::PerStageSamplers => l.max_per_stage_descriptor_samplers = min,
                Limit::PerStageStorageImages => l.max_per_stage_descriptor_storage_images = min,
                Limit::PerStageResources => l.max_per_stage_resources = min,
                Limit::SetStorageBuffers => l.max_descriptor_set_storage_buffers = min,
                Limit::SetSampledImages => l.max_descriptor_set_sampled_images = min,
                Limit::ColorAttachments => {
                    l.max_color_attachments = min;
                    l.max_fragment_output_attachments = min;
                }
                Limit::ComputeWorkGroupInvocations => l.max_compute_work_group_invocations = min,
                Limit::ComputeWorkGroupSize => l.max_compute_work_group_size = [min, min, 64],
            }
        }
        f(&mut l);
        DeviceLimits::new(&l)
    }

    #[test]
    fn a_device_at_the_spec_minimum_is_told_what_it_lacks() {
        let minimal = device(|_| {});
        for limit in Limit::ALL {
            assert_eq!(minimal.get(limit), limit.spec_minimum(), "{limit:?}");
        }
        let text = describe(NEEDS, &minimal);
        assert!(
            text.contains("unmet: maxPerStageDescriptorStorageBuffers 4 < 7"),
            "{text}"
        );
        assert!(
            text.contains("maxComputeWorkGroupInvocations 128 < 256: 8x8 tiles"),
            "{text}"
        );
        let roomy = device(|l| {
            l.max_per_stage_descriptor_storage_buffers = 8;
            l.max_compute_work_group_invocations = 1024;
            l.max_compute_work_group_size = [1024, 1024, 64];
        });
        assert!(describe(NEEDS, &roomy).ends_with("all met"));
        let err = minimal
            .check(Limit::PerStageStorageBuffers, 7, "pipeline layout `tiled`")
            .unwrap_err();
        assert_eq!(
            err,
            "pipeline layout `tiled` needs 7 for maxPerStageDescriptorStorageBuffers and this \
             device offers 4 (every device offers 4)"
        );
    }

    #[test]
    fn a_table_with_nothing_above_the_minimum_says_so() {
        let need = Need {
            limit: Limit::BoundDescriptorSets,
            most: 4,
            why: "",
            instead: None,
        };
        assert_eq!(
            describe(&[need], &device(|_| {})),
            "every need within the spec's minimums"
        );
    }

    #[test]
    fn a_layout_counts_each_stage_and_the_whole_layout() {
        use BindingKind::{SampledImage, StorageBuffer, StorageImage, UniformBuffer};
        let counts = |stages, kinds: &[(BindingKind, u32)]| {
            let mut c = SetCounts::new(stages);
            for &(kind, n) in kinds {
                c.add(kind, n);
            }
            c
        };
        let vertex_fragment = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT;
        let frame = counts(vertex_fragment, &[(UniformBuffer, 1), (StorageBuffer, 1)]);
        let gbuffer = counts(vk::ShaderStageFlags::FRAGMENT, &[(SampledImage, 3)]);
        let compute = vk::ShaderStageFlags::COMPUTE;
        let tiled = counts(compute, &[(StorageBuffer, 4), (StorageImage, 1)]);
        let needs = layout_needs(&[frame, gbuffer, tiled], 3, 96);
        let get = |l| needs.iter().find(|(n, _)| *n == l).map(|&(_, v)| v);
        assert_eq!(get(Limit::BoundDescriptorSets), Some(3));
        assert_eq!(get(Limit::PushConstantsSize), Some(96));
        // Per stage: the fragment stage sees frame + gbuffer, compute sees tiled alone.
        assert_eq!(get(Limit::PerStageStorageBuffers), Some(4));
        assert_eq!(get(Limit::PerStageSampledImages), Some(3));
        assert_eq!(get(Limit::PerStageResources), Some(5));
        // The layout: every set.
        assert_eq!(get(Limit::SetStorageBuffers), Some(5));
        assert_eq!(get(Limit::SetSampledImages), Some(3));
        // An engine's layout, from its bindings: a combined image sampler counts as both, and
        // each stage mask apart.
        let bindings = [
            vk::DescriptorSetLayoutBinding::default()
                .descriptor_type(vk::DescriptorType::COMBINED_IMAGE_SAMPLER)
                .descriptor_count(2)
                .stage_flags(vk::ShaderStageFlags::FRAGMENT),
            vk::DescriptorSetLayoutBinding::default()
                .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                .descriptor_count(1)
                .stage_flags(vk::ShaderStageFlags::COMPUTE),
        ];
        let engine = SetCounts::of_bindings(&bindings);
        assert_eq!(engine.len(), 2);
        let needs = layout_needs(&engine, 1, 0);
        let get = |l| needs.iter().find(|(n, _)| *n == l).map(|&(_, v)| v);
        assert_eq!(get(Limit::PerStageSampledImages), Some(2));
        assert_eq!(get(Limit::PerStageSamplers), Some(2));
        assert_eq!(get(Limit::PerStageStorageBuffers), Some(1));
        assert_eq!(get(Limit::BoundDescriptorSets), Some(1));
    }
}
