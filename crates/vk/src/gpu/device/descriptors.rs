//! Descriptor set layouts as data, the pipeline layouts built from them, and the sets of a frame.
//! The sets every pass shares (the frame's, the G-buffer's) are here; each pass keeps its own
//! set's table, and `crate::shader_layouts` gathers them for the reflection test.

use crate::gpu::device::context::Context;
use crate::gpu::device::error::{Result, VkCall};
use crate::gpu::device::limits::{layout_needs, SetCounts};
use crate::gpu::device::teardown::build;
use ash::vk;

pub use crate::gpu::device::limits::BindingKind;

/// Bytes of push-constant space every pipeline layout declares: the largest block, the mesh
/// passes' `Draw` (`passes::geometry::DrawPush`, which asserts it is this size; every other
/// pass's block is smaller, and a layout's range must cover it).
pub const PUSH_CONSTANT_BYTES: u32 = 96;

// 128 bytes is the push-constant space every Vulkan device guarantees.
const _: () = assert!(PUSH_CONSTANT_BYTES <= 128);

/// One binding of a set: its number, what it holds, and the GLSL name that declares it.
#[derive(Clone, Copy, Debug)]
pub struct BindingDesc {
    /// The `binding =` number in the set.
    pub binding: u32,
    /// What it holds.
    pub kind: BindingKind,
    /// The variable the GLSL declares there, which the reflection test checks; empty for an
    /// anonymous block, which SPIR-V leaves unnamed.
    pub glsl_name: &'static str,
}

pub(crate) const fn binding(
    binding: u32,
    kind: BindingKind,
    glsl_name: &'static str,
) -> BindingDesc {
    BindingDesc {
        binding,
        kind,
        glsl_name,
    }
}

/// Set 0 of every pipeline (include/frame.glsl).
pub const FRAME_SET: &[BindingDesc] = &[
    binding(0, BindingKind::UniformBuffer, "frame"),
    binding(1, BindingKind::StorageBuffer, "lights"),
];
/// Set 1 of the deferred light pipelines (include/gbuffer.glsl).
pub const GBUFFER_SET: &[BindingDesc] = &[
    binding(0, BindingKind::SampledImage, "gbuffer_albedo"),
    binding(1, BindingKind::SampledImage, "gbuffer_normal_depth"),
    binding(2, BindingKind::SampledImage, "gbuffer_material"),
];

/// The stages of the graphics passes: every binding and push constant is visible to both.
pub(crate) const GRAPHICS_STAGES: vk::ShaderStageFlags = vk::ShaderStageFlags::from_raw(
    vk::ShaderStageFlags::VERTEX.as_raw() | vk::ShaderStageFlags::FRAGMENT.as_raw(),
);

/// The Vulkan bindings of `set`, each visible to `stages`.
pub(crate) fn layout_bindings(
    set: &[BindingDesc],
    stages: vk::ShaderStageFlags,
) -> Vec<vk::DescriptorSetLayoutBinding<'static>> {
    set.iter()
        .map(|b| {
            vk::DescriptorSetLayoutBinding::default()
                .binding(b.binding)
                .descriptor_type(b.kind.descriptor_type())
                .descriptor_count(1)
                .stage_flags(stages)
        })
        .collect()
}

/// A named set layout with every binding of `set` visible to `stages`.
pub(crate) fn create_set_layout(
    ctx: &Context,
    name: &str,
    set: &[BindingDesc],
    stages: vk::ShaderStageFlags,
) -> Result<vk::DescriptorSetLayout> {
    let bindings = layout_bindings(set, stages);
    let info = vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings);
    // SAFETY: `info` and `bindings` live until the call returns; the tables give each binding
    // a distinct number, one descriptor of a plain type, and no immutable samplers.
    let layout = unsafe { ctx.device.create_descriptor_set_layout(&info, None) }
        .call("vkCreateDescriptorSetLayout")?;
    ctx.name(layout, name);
    let mut counts = SetCounts::new(stages);
    for b in set {
        counts.add(b.kind, 1);
    }
    ctx.set_counts
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .insert(layout, vec![counts]);
    Ok(layout)
}

/// A pool holding one set of `layout` whose bindings 0, 1, ... are the storage buffers
/// `buffers`, named `{name}-descriptor-pool` and `{name}-set`. The caller destroys the pool.
pub(crate) fn create_storage_buffer_set(
    ctx: &Context,
    name: &str,
    layout: vk::DescriptorSetLayout,
    buffers: &[vk::Buffer],
) -> Result<(vk::DescriptorPool, vk::DescriptorSet)> {
    let d = &ctx.device;
    let sizes = [vk::DescriptorPoolSize::default()
        .ty(vk::DescriptorType::STORAGE_BUFFER)
        .descriptor_count(buffers.len() as u32)];
    // SAFETY: the create info and `sizes` live until the call returns; one set at most.
    let pool = unsafe {
        d.create_descriptor_pool(
            &vk::DescriptorPoolCreateInfo::default()
                .max_sets(1)
                .pool_sizes(&sizes),
            None,
        )
    }
    .call("vkCreateDescriptorPool")?;
    ctx.name(pool, &format!("{name}-descriptor-pool"));
    let layouts = [layout];
    // SAFETY: `pool` was just made and is ours alone (its external synchronisation), sized for
    // one set of storage buffers; `layout` is a live set layout of this device (the caller's).
    let allocated = unsafe {
        d.allocate_descriptor_sets(
            &vk::DescriptorSetAllocateInfo::default()
                .descriptor_pool(pool)
                .set_layouts(&layouts),
        )
    }
    .call("vkAllocateDescriptorSets");
    let set = match allocated {
        Ok(sets) => sets[0],
        Err(e) => {
            // SAFETY: the pool was just made here, holds no set and is unused.
            unsafe { d.destroy_descriptor_pool(pool, None) };
            return Err(e);
        }
    };
    ctx.name(set, &format!("{name}-set"));
    write_storage_buffers(ctx, set, buffers);
    Ok((pool, set))
}

/// Points a [`FRAME_SET`] at the frame's uniform buffer and light buffer.
pub(crate) fn write_frame_set(
    ctx: &Context,
    set: vk::DescriptorSet,
    uniforms: vk::Buffer,
    lights: vk::Buffer,
) {
    let info = |buffer| {
        [vk::DescriptorBufferInfo::default()
            .buffer(buffer)
            .range(vk::WHOLE_SIZE)]
    };
    let (ubo, ssbo) = (info(uniforms), info(lights));
    let writes = [
        vk::WriteDescriptorSet::default()
            .dst_set(set)
            .dst_binding(0)
            .descriptor_type(vk::DescriptorType::UNIFORM_BUFFER)
            .buffer_info(&ubo),
        vk::WriteDescriptorSet::default()
            .dst_set(set)
            .dst_binding(1)
            .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
            .buffer_info(&ssbo),
    ];
    // SAFETY: `writes` and the buffer infos they point at live until the call returns. Every
    // caller passes a set of a `FRAME_SET` layout that no pending command buffer uses (fresh,
    // or a slot's after the slot finished) and live buffers with uniform / storage usage.
    unsafe { update_sets(ctx, &writes) };
}

/// Points bindings 0, 1, ... of `set` at the sampled images `views`, read in
/// `SHADER_READ_ONLY_OPTIMAL`.
pub(crate) fn write_sampled_images(ctx: &Context, set: vk::DescriptorSet, views: &[vk::ImageView]) {
    let infos: Vec<_> = views
        .iter()
        .map(|v| {
            vk::DescriptorImageInfo::default()
                .image_view(*v)
                .image_layout(vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL)
        })
        .collect();
    write_in_order(
        ctx,
        set,
        vk::DescriptorType::SAMPLED_IMAGE,
        &infos,
        |w, info| w.image_info(info),
    );
}

/// Points bindings 0, 1, ... of `set` at the storage buffers `buffers`.
pub(crate) fn write_storage_buffers(ctx: &Context, set: vk::DescriptorSet, buffers: &[vk::Buffer]) {
    let infos: Vec<_> = buffers
        .iter()
        .map(|b| {
            vk::DescriptorBufferInfo::default()
                .buffer(*b)
                .range(vk::WHOLE_SIZE)
        })
        .collect();
    write_in_order(
        ctx,
        set,
        vk::DescriptorType::STORAGE_BUFFER,
        &infos,
        |w, info| w.buffer_info(info),
    );
}

/// One write per element of `infos`, to bindings 0, 1, ... of `set`.
fn write_in_order<'a, T>(
    ctx: &Context,
    set: vk::DescriptorSet,
    ty: vk::DescriptorType,
    infos: &'a [T],
    attach: impl Fn(vk::WriteDescriptorSet<'a>, &'a [T]) -> vk::WriteDescriptorSet<'a>,
) {
    let writes: Vec<_> = (0..infos.len())
        .map(|i| {
            let write = vk::WriteDescriptorSet::default()
                .dst_set(set)
                .dst_binding(i as u32)
                .descriptor_type(ty);
            attach(write, &infos[i..=i])
        })
        .collect();
    // SAFETY: `writes` and the `infos` they point at live until the call returns; binding `i`
    // of `set` has type `ty` (the callers' layouts). Every caller updates a set that no pending
    // command buffer uses: a fresh one, a slot's whose frame finished (`slot_finished`), or one
    // whose owner refuses while in flight or whose caller promises it (`set_lut_tables`).
    unsafe { update_sets(ctx, &writes) };
}

/// `vkUpdateDescriptorSets` with `writes` alone, the buffers they bind journaled for the
/// hazard check: every descriptor write of histencil's goes through here.
///
/// # Safety
/// As `vkUpdateDescriptorSets`: each write names a live set that no pending command buffer
/// uses, a binding of its layout of the write's type, and live resources with the usage the
/// type needs; the infos each write points at live until the call returns.
pub(crate) unsafe fn update_sets(ctx: &Context, writes: &[vk::WriteDescriptorSet]) {
    if let Some(hazards) = ctx.hazards.get() {
        hazards.descriptor_writes(writes);
    }
    // SAFETY: this fn's # Safety.
    unsafe { ctx.device.update_descriptor_sets(writes, &[]) };
}

/// The renderer's frame set (set 0 of its mesh, alpha and tonemap passes): its layout, pool
/// and the one set, pointing at the frame's uniforms and lights. Each pass owns the rest of
/// its layout (`passes/`); the lighting has its own (`lighting/`).
#[derive(Default)]
pub struct Descriptors {
    /// The layout of [`FRAME_SET`], set 0 of the passes' pipeline layouts.
    pub frame_layout: vk::DescriptorSetLayout,
    pool: vk::DescriptorPool,
    /// The one set, bound at set 0 by each pass.
    pub frame_set: vk::DescriptorSet,
}

/// A pool's sizes for `sets`: each a binding table (what its set layout was made from) and how
/// many sets of it the pool holds, the descriptors summed by type. The pools are sized from the
/// tables the layouts and shaders are held to, not counted by hand beside them. Pure, so it is
/// unit-tested.
pub(crate) fn pool_sizes(sets: &[(&[BindingDesc], u32)]) -> Vec<vk::DescriptorPoolSize> {
    BindingKind::ALL
        .iter()
        .filter_map(|kind| {
            let count: u32 = (sets.iter())
                .map(|(table, n)| n * table.iter().filter(|b| b.kind == *kind).count() as u32)
                .sum();
            (count > 0).then(|| {
                vk::DescriptorPoolSize::default()
                    .ty(kind.descriptor_type())
                    .descriptor_count(count)
            })
        })
        .collect()
}

/// A pool holding one set of `layout` (made from `table`), and that set, named `name` (the
/// pool `name-pool`). Nothing is left behind on an error.
pub(crate) fn one_set(
    ctx: &Context,
    name: &str,
    layout: vk::DescriptorSetLayout,
    table: &[BindingDesc],
) -> Result<(vk::DescriptorPool, vk::DescriptorSet)> {
    let (pool, sets) = sets_of(ctx, name, layout, 1, table)?;
    ctx.name(sets[0], name);
    Ok((pool, sets[0]))
}

/// A pool named `{name}-pool` and `count` sets of `layout` from it (one per frame in flight),
/// named `{name}-0`, `{name}-1`, ...; `table` is the binding table `layout` was made from.
/// On failure nothing is left.
pub(crate) fn sets_of(
    ctx: &Context,
    name: &str,
    layout: vk::DescriptorSetLayout,
    count: u32,
    table: &[BindingDesc],
) -> Result<(vk::DescriptorPool, Vec<vk::DescriptorSet>)> {
    let sizes = pool_sizes(&[(table, count)]);
    let pool_info = vk::DescriptorPoolCreateInfo::default()
        .max_sets(count)
        .pool_sizes(&sizes);
    // SAFETY: `pool_info` and `sizes` live until the call returns.
    let pool = unsafe { ctx.device.create_descriptor_pool(&pool_info, None) }
        .call("vkCreateDescriptorPool")?;
    ctx.name(pool, &format!("{name}-pool"));
    let layouts = vec![layout; count as usize];
    let alloc = vk::DescriptorSetAllocateInfo::default()
        .descriptor_pool(pool)
        .set_layouts(&layouts);
    // SAFETY: `pool` was just made and is ours alone, sized for `count` sets of `sizes`;
    // `layout` is a live set layout of this device whose bindings `sizes` covers (the caller's).
    match unsafe { ctx.device.allocate_descriptor_sets(&alloc) }.call("vkAllocateDescriptorSets") {
        Ok(sets) => {
            for (i, set) in sets.iter().enumerate() {
                ctx.name(*set, &format!("{name}-{i}"));
            }
            Ok((pool, sets))
        }
        Err(e) => {
            // SAFETY: the pool was just made here, holds no set and is unused.
            unsafe { ctx.device.destroy_descriptor_pool(pool, None) };
            Err(e)
        }
    }
}

/// The layouts of a renderer pass whose set 0 is the frame set and set 1 its own `set`: that
/// set's layout (`name-set-layout`) and the pipeline layout (`name-pipeline-layout`), with the
/// graphics push constants. Nothing is left behind on an error.
pub(crate) fn pass_layouts(
    ctx: &Context,
    name: &str,
    frame_layout: vk::DescriptorSetLayout,
    set: &[BindingDesc],
) -> Result<(vk::DescriptorSetLayout, vk::PipelineLayout)> {
    let own = create_set_layout(ctx, &format!("{name}-set-layout"), set, GRAPHICS_STAGES)?;
    let sets = [frame_layout, own];
    let layout_name = format!("{name}-pipeline-layout");
    match create_pipeline_layout(
        ctx,
        &layout_name,
        &sets,
        GRAPHICS_STAGES,
        PUSH_CONSTANT_BYTES,
    ) {
        Ok(layout) => Ok((own, layout)),
        Err(e) => {
            // SAFETY: `own` was just made here and nothing uses it: its pipeline layout failed.
            unsafe { ctx.device.destroy_descriptor_set_layout(own, None) };
            Err(e)
        }
    }
}

/// A named pipeline layout: `sets` in order, and `push_constant_bytes` visible to `stages`.
pub(crate) fn create_pipeline_layout(
    ctx: &Context,
    name: &str,
    sets: &[vk::DescriptorSetLayout],
    stages: vk::ShaderStageFlags,
    push_constant_bytes: u32,
) -> Result<vk::PipelineLayout> {
    // Each need checked before Vulkan sees the layout: a device below one gets an error that
    // names the limit, not a driver's undefined behaviour.
    let counts: Vec<SetCounts> = {
        let known = ctx.set_counts.lock().unwrap_or_else(|e| e.into_inner());
        sets.iter()
            .flat_map(|s| known.get(s).cloned().unwrap_or_default())
            .collect()
    };
    for (limit, need) in layout_needs(&counts, sets.len() as u32, push_constant_bytes) {
        ctx.need(limit, need, &format!("pipeline layout `{name}`"))?;
    }
    let ranges = [vk::PushConstantRange::default()
        .stage_flags(stages)
        .size(push_constant_bytes)];
    let info = vk::PipelineLayoutCreateInfo::default()
        .set_layouts(sets)
        .push_constant_ranges(&ranges);
    // SAFETY: `info`, `sets` and `ranges` live until the call returns; the limits the layout
    // needs were checked against the device just above.
    let layout =
        unsafe { ctx.device.create_pipeline_layout(&info, None) }.call("vkCreatePipelineLayout")?;
    ctx.name(layout, name);
    Ok(layout)
}

impl Descriptors {
    /// The layout, pool and set, written for the frame's uniform and light buffers; a failure
    /// half way frees what was made.
    pub fn new(ctx: &Context, frame_uniforms: vk::Buffer, lights: vk::Buffer) -> Result<Self> {
        let d = build(ctx, |d: &mut Self| {
            // The compute stage too: the layout must match the lighting's frame set layout,
            // whose pipeline layout the simulator's footprint capture binds this set with.
            let stages = GRAPHICS_STAGES | vk::ShaderStageFlags::COMPUTE;
            d.frame_layout = create_set_layout(ctx, "frame-set-layout", FRAME_SET, stages)?;
            (d.pool, d.frame_set) = one_set(ctx, "frame-set", d.frame_layout, FRAME_SET)?;
            Ok(())
        })?;
        write_frame_set(ctx, d.frame_set, frame_uniforms, lights);
        Ok(d)
    }

    /// Frees the pool (and with it the set) and the layout; a second call does nothing.
    pub fn destroy(&mut self, ctx: &Context) {
        // SAFETY: the pool and layout are this value's own; null ones (empty, or destroyed
        // before) are no-ops. Owners call `destroy` only once the GPU is done with the set
        // (teardown.rs: after their fence wait or device idle, or on a failed creation).
        unsafe {
            ctx.device.destroy_descriptor_pool(self.pool, None);
            ctx.device
                .destroy_descriptor_set_layout(self.frame_layout, None);
        }
        *self = Self::default();
    }
}

crate::gpu::device::teardown::destroy_by_method!(Descriptors);

#[cfg(test)]
mod pool_tests {
    use super::*;

    /// The pools come from the tables: the lighting's, for two slots with the built-in decode,
    /// holds two frame sets' uniform and light buffers, two G-buffer sets' images and the
    /// hi-stencil and LUT sets' buffers, and no type it has no binding of.
    #[test]
    fn pool_sizes_sum_each_tables_descriptors_by_type() {
        let storage = [
            binding(0, BindingKind::StorageBuffer, "a"),
            binding(1, BindingKind::StorageBuffer, "b"),
        ];
        let sizes = pool_sizes(&[(FRAME_SET, 2), (GBUFFER_SET, 2), (&storage, 1)]);
        let count = |ty| {
            (sizes.iter())
                .find(|s| s.ty == ty)
                .map(|s| s.descriptor_count)
        };
        assert_eq!(count(vk::DescriptorType::UNIFORM_BUFFER), Some(2));
        assert_eq!(count(vk::DescriptorType::STORAGE_BUFFER), Some(2 + 2));
        assert_eq!(
            count(vk::DescriptorType::SAMPLED_IMAGE),
            Some(2 * GBUFFER_SET.len() as u32)
        );
        assert_eq!(count(vk::DescriptorType::SAMPLER), None);
        // A table of no sets adds nothing.
        assert!(pool_sizes(&[(FRAME_SET, 0)]).is_empty());
    }
}
