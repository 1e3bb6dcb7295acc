//! The tiled technique, the way engines today light many BRDFs (Unity HDRP's material feature
//! tiles, UE5 Substrate's classification, Battlefield 3's tiled light lists), next to the
//! talk's: a compute pass classifies each 8x8 or 16x16 tile ([`TileSide`]) of the G-buffer (the
//! BRDFs its pixels use, their depth range) into one list of tiles per BRDF with its indirect
//! dispatch arguments, all on the GPU; then one indirect
//! dispatch per BRDF in the frame runs a kernel specialised to that BRDF over its tiles, and each
//! pixel adds the tile's lights by its own BRDF, once. A tile with pixels of several BRDFs is in
//! several lists, and each BRDF's kernel shades only its own pixels there.
//! The lights each tile's pixels can see are listed between the two passes: each light is binned
//! into the tiles of its screen rectangle whose depth range its range sphere reaches.
//! Shaders: `tile_classify.comp`, `tile_lights.comp`, `tile_shade.comp`, `include/tiled.glsl`.

use crate::gpu::access::LeaveOut::{self, Barrier, Declaration};
use crate::gpu::access::{uses_of, BufferAccess, Contents, ImageAccess, ImageRef, LightingTargets};
use crate::gpu::device::context::Context;
use crate::gpu::device::descriptors::{
    binding, create_pipeline_layout, create_set_layout, sets_of, write_storage_buffers,
    BindingDesc, BindingKind,
};
use crate::gpu::device::error::{Error, Result};
use crate::gpu::device::hazards::HandOver;
use crate::gpu::device::limits::Limit;
use crate::gpu::device::pipelines::create_compute_pipeline;
use crate::gpu::device::quirks::Quirk;
use crate::gpu::device::resources::Buffer;
use crate::gpu::device::teardown::{build, Destroy};
use crate::gpu::encoder::recording::Recording;
use crate::passes::light_modules::LightModules;
use crate::shader_consts::TILED_MODELS;
use crate::shaders;
use ash::vk;
use gpu_allocator::MemoryLocation;
use histencil_brdf::BrdfId;

/// Set 2 of the tiled technique's compute passes (include/tiled.glsl): dispatch arguments, tile
/// lists and light masks, and the HDR target as a storage image.
pub(crate) const TILED_SET: &[BindingDesc] = &[
    binding(0, BindingKind::StorageBuffer, ""),
    binding(1, BindingKind::StorageBuffer, ""),
    binding(2, BindingKind::StorageBuffer, ""),
    binding(3, BindingKind::StorageBuffer, ""),
    binding(4, BindingKind::StorageImage, "tiled_hdr"),
];

/// `Tiled` in include/tiled.glsl.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct TiledPush {
    tiles_x: u32,
    tiles: u32,
    words: u32,
    clear: u32,
    mixed: u32,
    slot_of_model: [u32; TILED_MODELS as usize],
}

/// The most BRDF slots the classification's masks and lists hold.
const MAX_SLOTS: usize = 32;
/// The list of mixed tiles shaded once, branching (`TILED_MIXED_SLOT`), after the slots'.
const MIXED_SLOT: usize = MAX_SLOTS;
/// `tiled.mixed` for mixed tiles in each of their BRDFs' lists (`TILED_PER_BRDF`).
const PER_BRDF: u32 = u32::MAX;
/// `SHADED_BRDF` of the branching kernel.
const BRANCH_ON_GBUFFER: u32 = u32::MAX;

/// The side of the tiled technique's tiles (`TILED_TILE` of the stages it picks): one workgroup
/// of a shade kernel covers one tile, as does one of the classification's in its workgroup
/// shape ([`TileClassify`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum TileSide {
    /// 8x8 pixels: fewer wasted invocations on mixed and partly covered tiles, four times the
    /// tiles to classify and list.
    Eight,
    /// 16x16 pixels, as HDRP's classification.
    #[default]
    Sixteen,
}

impl TileSide {
    /// The side for `ctx`'s driver: 8x8 where the quirk table says so
    /// ([`crate::Quirk::SmallTiles`]: lavapipe, where 8x8 tiles were as fast or faster within
    /// the noise wherever measured), else HDRP's 16x16, the common choice on GPUs (the two
    /// measured within a few per cent on an H200). 8x8 too where the device cannot run a 16x16
    /// workgroup (`maxComputeWorkGroupInvocations` 256 and `maxComputeWorkGroupSize` 16 are
    /// above the spec's minimums of 128; 8x8 is within them).
    pub fn for_context(ctx: &Context) -> Self {
        let limits = ctx.device_limits();
        let fits_16 = limits.get(Limit::ComputeWorkGroupInvocations) >= 256
            && limits.get(Limit::ComputeWorkGroupSize) >= 16;
        if ctx.quirks().has(Quirk::SmallTiles) || !fits_16 {
            TileSide::Eight
        } else {
            TileSide::Sixteen
        }
    }

    /// The side in pixels (`TILED_TILE` of the kernels built for it).
    pub fn pixels(self) -> u32 {
        match self {
            TileSide::Eight => 8,
            TileSide::Sixteen => 16,
        }
    }

    /// The classification and shade stages built for this side, from `modules` (histencil's
    /// or an engine's, compiled with its hooks).
    fn modules(self, modules: &LightModules) -> [(&'static str, &'static [u8]); 2] {
        match self {
            TileSide::Eight => [
                ("tile_classify_8.comp", modules.tile_classify_8),
                ("tile_shade_8.comp", modules.tile_shade_8),
            ],
            TileSide::Sixteen => [
                ("tile_classify.comp", modules.tile_classify),
                ("tile_shade.comp", modules.tile_shade),
            ],
        }
    }
}

/// How the classification's work is shaped on the device (the results are the same bit for
/// bit; `tile_classify.glsl`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TileClassify {
    /// A workgroup per tile, an invocation per pixel, combined in shared memory: GPUs, where
    /// a tile's pixels are read side by side.
    Workgroup,
    /// An invocation per tile, reading the tile's pixels in a loop: CPU rasterisers (llvmpipe),
    /// which run a workgroup with barriers one invocation at a time, switching at each barrier.
    PerInvocation,
}

impl TileClassify {
    /// The shape for `ctx`'s driver: per invocation where the quirk table says so
    /// ([`crate::Quirk::ClassifyPerInvocation`]), else a workgroup.
    pub fn for_context(ctx: &Context) -> Self {
        if ctx.quirks().has(Quirk::ClassifyPerInvocation) {
            TileClassify::PerInvocation
        } else {
            TileClassify::Workgroup
        }
    }
}

/// What the tiled technique does with a tile whose pixels use several BRDFs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MixedTiles {
    /// Each of its BRDFs' kernels runs over it, each shading its own pixels (the others idle).
    PerBrdf,
    /// One kernel runs over it, branching on each pixel's BRDF (HDRP's catch-all variant).
    Branching,
}

/// How the tiled classification's tiles are shaded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum TiledShade {
    /// One indirect compute dispatch per BRDF over its tiles (the tiled technique).
    Kernels,
    /// One full-screen pass per BRDF selected by a depth id (the depth-id technique,
    /// `passes/depth_id.rs`).
    DepthId,
}

#[derive(Default)]
pub(crate) struct TiledLighting {
    /// The tiled set's layout (set 2); sets 0, 1, 3 and 4 are the lighting's.
    set_layout: vk::DescriptorSetLayout,
    pipeline_layout: vk::PipelineLayout,
    pool: vk::DescriptorPool,
    /// The tiled set of each frame-in-flight slot (its HDR target written per frame).
    sets: Vec<vk::DescriptorSet>,
    /// The classification, a workgroup per tile.
    classify: vk::Pipeline,
    /// The classification, an invocation per tile (`PER_INVOCATION`).
    classify_alone: vk::Pipeline,
    /// The light lists: a workgroup per light over its tiles.
    light_lists: vk::Pipeline,
    /// The shade kernel of each BRDF slot.
    shade: Vec<vk::Pipeline>,
    /// The branching kernel over mixed tiles.
    branching: vk::Pipeline,
    dispatch: Buffer,
    lists: Buffer,
    masks: Buffer,
    /// Each tile's depth range, from the classification to the light lists.
    depths: Buffer,
    push: Option<TiledPush>,
    tiles_xy: (u32, u32),
    side: TileSide,
}

/// What a [`TiledLighting`] is made for, inside a [`crate::DeferredLighting`].
pub(crate) struct TiledDesc<'a> {
    pub extent: vk::Extent2D,
    pub side: TileSide,
    /// The BRDF of each stencil slot.
    pub brdfs: &'a [BrdfId],
    pub max_lights: u32,
    pub frames_in_flight: u32,
    /// The light shaders: histencil's, or an engine's compiled with its hooks.
    pub modules: &'a LightModules,
    /// The lighting's set layouts for sets 0 (frame), 1 (decode), 3 (a filler where set 4 is
    /// used) and 4 (the visibility hook's, if any): all with the compute stage.
    pub layouts: [vk::DescriptorSetLayout; 2],
    pub visibility: Option<(vk::DescriptorSetLayout, vk::DescriptorSetLayout)>,
}

/// The sets one tiled frame binds: the slot's frame and decode sets, the engine's visibility
/// set if its hook has one.
pub(crate) struct TiledSets {
    pub slot: u32,
    pub frame: vk::DescriptorSet,
    pub decode: vk::DescriptorSet,
    pub visibility: Option<vk::DescriptorSet>,
}

impl Destroy for TiledLighting {
    fn destroy(&mut self, ctx: &Context) {
        let d = &ctx.device;
        // SAFETY: every handle is null or was made by `new` from this device, and is nulled
        // (or drained) as it goes, so a second call destroys nothing. The GPU is done with them:
        // `build` destroys after a failed `new` (nothing recorded), the lighting's Drop after
        // its slots finished or the device went idle.
        unsafe {
            let single = [
                self.classify,
                self.classify_alone,
                self.light_lists,
                self.branching,
            ];
            for p in self.shade.drain(..).chain(single) {
                d.destroy_pipeline(p, None);
            }
            self.classify = vk::Pipeline::null();
            self.classify_alone = vk::Pipeline::null();
            self.light_lists = vk::Pipeline::null();
            self.branching = vk::Pipeline::null();
            d.destroy_descriptor_pool(self.pool, None);
            self.pool = vk::DescriptorPool::null();
            self.sets.clear();
            d.destroy_pipeline_layout(self.pipeline_layout, None);
            self.pipeline_layout = vk::PipelineLayout::null();
            d.destroy_descriptor_set_layout(self.set_layout, None);
            self.set_layout = vk::DescriptorSetLayout::null();
        }
        self.dispatch.destroy(ctx);
        self.lists.destroy(ctx);
        self.masks.destroy(ctx);
        self.depths.destroy(ctx);
    }
}

impl TiledLighting {
    /// The tiled set layout, the pipeline layout, the pipelines (the classification and one
    /// shade kernel per BRDF slot), the tile buffers for `desc.extent` and a tiled set per slot
    /// pointing at them; a failure half way frees what was made.
    pub fn new(ctx: &Context, desc: &TiledDesc) -> Result<Self> {
        if desc.brdfs.len() > MAX_SLOTS {
            return Err(Error::BadFrame(format!(
                "the tiled technique takes at most {MAX_SLOTS} BRDFs, not {}",
                desc.brdfs.len()
            )));
        }
        let compute = vk::ShaderStageFlags::COMPUTE;
        let e = desc.extent;
        let tile = desc.side.pixels();
        // The classification and shade kernels run one invocation per pixel of a tile.
        let what = format!("the tiled technique's {tile}x{tile} tiles");
        ctx.need(Limit::ComputeWorkGroupInvocations, tile * tile, &what)?;
        ctx.need(Limit::ComputeWorkGroupSize, tile, &what)?;
        let tiles_xy = (e.width.div_ceil(tile), e.height.div_ceil(tile));
        let [classify, shade] = desc.side.modules(desc.modules);
        let tiles = tiles_xy.0 * tiles_xy.1;
        let words = desc.max_lights.div_ceil(32).max(1);
        let mut slot_of_model = [u32::MAX; TILED_MODELS as usize];
        for (slot, brdf) in desc.brdfs.iter().enumerate() {
            slot_of_model[brdf.index() as usize] = slot as u32;
        }
        build(ctx, |t: &mut Self| {
            // The depth-id technique's fragment shaders bind it too (`passes/depth_id.rs`).
            let stages = compute | vk::ShaderStageFlags::FRAGMENT;
            t.set_layout = create_set_layout(ctx, "tiled-set-layout", TILED_SET, stages)?;
            let [frame, decode] = desc.layouts;
            let mut layouts = vec![frame, decode, t.set_layout];
            if let Some((filler, visibility)) = desc.visibility {
                layouts.extend([filler, visibility]);
            }
            let push_bytes = size_of::<TiledPush>() as u32;
            let name = "tiled-pipeline-layout";
            t.pipeline_layout = create_pipeline_layout(ctx, name, &layouts, compute, push_bytes)?;
            let layout = t.pipeline_layout;
            let name = "tiled-classify-pipeline";
            t.classify = create_compute_pipeline(ctx, name, classify, layout, &[0])?;
            let name = "tiled-classify-per-invocation-pipeline";
            t.classify_alone = create_compute_pipeline(ctx, name, classify, layout, &[1])?;
            let name = "tiled-light-lists-pipeline";
            let module = ("tile_lights.comp", shaders::TILE_LIGHTS_COMP);
            t.light_lists = create_compute_pipeline(ctx, name, module, layout, &[tile])?;
            for (slot, brdf) in desc.brdfs.iter().enumerate() {
                let name = format!("tiled-shade-{}-pipeline", brdf.name());
                let constants = [brdf.index(), slot as u32];
                let p = create_compute_pipeline(ctx, &name, shade, layout, &constants)?;
                t.shade.push(p);
            }
            let constants = [BRANCH_ON_GBUFFER, MIXED_SLOT as u32];
            let name = "tiled-shade-branching-pipeline";
            t.branching = create_compute_pipeline(ctx, name, shade, layout, &constants)?;
            use vk::BufferUsageFlags as U;
            let storage = U::STORAGE_BUFFER;
            let gpu = MemoryLocation::GpuOnly;
            t.dispatch = Buffer::new(
                ctx,
                "tiled-dispatch",
                ((MIXED_SLOT + 1) * 16) as u64,
                storage | U::INDIRECT_BUFFER | U::TRANSFER_DST,
                gpu,
            )?;
            // Every slot's list and the mixed tiles' (which the shaders find at MIXED_SLOT).
            let lists = (MIXED_SLOT + 1) as u64 * u64::from(tiles) * 4;
            t.lists = Buffer::new(ctx, "tiled-lists", lists, storage, gpu)?;
            let mask_bytes = u64::from(tiles) * u64::from(words) * 4;
            let zeroed = storage | U::TRANSFER_DST;
            t.masks = Buffer::new(ctx, "tiled-light-masks", mask_bytes, zeroed, gpu)?;
            let depth_bytes = u64::from(tiles) * 8;
            t.depths = Buffer::new(ctx, "tiled-depth-ranges", depth_bytes, storage, gpu)?;
            t.create_sets(ctx, desc.frames_in_flight)?;
            t.push = Some(TiledPush {
                tiles_x: tiles_xy.0,
                tiles,
                words,
                clear: 0,
                mixed: PER_BRDF,
                slot_of_model,
            });
            t.tiles_xy = tiles_xy;
            t.side = desc.side;
            Ok(())
        })
    }

    /// The tile buffers for a new `extent`, the pipelines and sets kept (the sets re-pointed);
    /// a failure leaves the buffers as they were. The GPU has finished every frame that used
    /// them.
    pub fn resize(&mut self, ctx: &Context, extent: vk::Extent2D) -> Result<()> {
        let tile = self.side.pixels();
        let tiles_xy = (extent.width.div_ceil(tile), extent.height.div_ceil(tile));
        let tiles = tiles_xy.0 * tiles_xy.1;
        let push = self.push.as_mut().expect("made with the lighting");
        use vk::BufferUsageFlags as U;
        let (storage, gpu) = (U::STORAGE_BUFFER, MemoryLocation::GpuOnly);
        let lists = (MIXED_SLOT + 1) as u64 * u64::from(tiles) * 4;
        let mut lists = Buffer::new(ctx, "tiled-lists", lists, storage, gpu)?;
        let mask_bytes = u64::from(tiles) * u64::from(push.words) * 4;
        let zeroed = storage | U::TRANSFER_DST;
        let masks = Buffer::new(ctx, "tiled-light-masks", mask_bytes, zeroed, gpu);
        let depths = masks.and_then(|masks| {
            let depths = Buffer::new(
                ctx,
                "tiled-depth-ranges",
                u64::from(tiles) * 8,
                storage,
                gpu,
            );
            match depths {
                Ok(depths) => Ok((masks, depths)),
                Err(e) => {
                    let mut masks = masks;
                    masks.destroy(ctx);
                    Err(e)
                }
            }
        });
        let (mut masks, mut depths) = match depths {
            Ok(made) => made,
            Err(e) => {
                lists.destroy(ctx);
                return Err(e);
            }
        };
        std::mem::swap(&mut self.lists, &mut lists);
        std::mem::swap(&mut self.masks, &mut masks);
        std::mem::swap(&mut self.depths, &mut depths);
        for mut old in [lists, masks, depths] {
            old.destroy(ctx);
        }
        push.tiles_x = tiles_xy.0;
        push.tiles = tiles;
        self.tiles_xy = tiles_xy;
        self.write_sets(ctx);
        Ok(())
    }

    /// The push constants of a frame that clears the HDR target with `clear` and shades mixed
    /// tiles as `mixed` says.
    fn push(&self, clear: bool, mixed: MixedTiles) -> TiledPush {
        TiledPush {
            clear: u32::from(clear),
            mixed: match mixed {
                MixedTiles::PerBrdf => PER_BRDF,
                MixedTiles::Branching => MIXED_SLOT as u32,
            },
            ..self.push.expect("made")
        }
    }

    /// [`TiledLighting::push`] as the bytes a shader reads.
    pub fn push_bytes(&self, clear: bool, mixed: MixedTiles) -> Vec<u8> {
        bytemuck::bytes_of(&self.push(clear, mixed)).to_vec()
    }

    /// The tiled set layout (set 2), visible to compute and fragment shaders.
    pub fn set_layout(&self) -> vk::DescriptorSetLayout {
        self.set_layout
    }

    /// Frame-in-flight `slot`'s tiled set.
    pub fn set(&self, slot: u32) -> vk::DescriptorSet {
        self.sets[slot as usize]
    }

    /// The bytes of the push constants.
    pub const PUSH_BYTES: u32 = size_of::<TiledPush>() as u32;

    /// The pipelines this technique holds.
    pub fn pipeline_count(&self) -> usize {
        4 + self.shade.len()
    }

    /// The pool and every slot's tiled set, its buffers written (the HDR target is written per
    /// frame, [`TiledLighting::set_target`]).
    fn create_sets(&mut self, ctx: &Context, slots: u32) -> Result<()> {
        (self.pool, self.sets) = sets_of(ctx, "tiled-set", self.set_layout, slots, TILED_SET)?;
        self.write_sets(ctx);
        Ok(())
    }

    /// The tile buffers, in the tiled set's binding order.
    pub(crate) fn buffers(&self) -> [vk::Buffer; 4] {
        [
            self.dispatch.handle,
            self.lists.handle,
            self.masks.handle,
            self.depths.handle,
        ]
    }

    /// Points every slot's tiled set at the tile buffers.
    fn write_sets(&self, ctx: &Context) {
        for set in &self.sets {
            write_storage_buffers(ctx, *set, &self.buffers());
        }
    }

    /// Points `slot`'s tiled set at the frame's HDR target (storage, `GENERAL`). The slot's last
    /// frame has finished, which recording into the slot promises.
    pub fn set_target(&self, ctx: &Context, slot: u32, hdr: vk::ImageView) {
        let image = [vk::DescriptorImageInfo::default()
            .image_view(hdr)
            .image_layout(vk::ImageLayout::GENERAL)];
        let write = vk::WriteDescriptorSet::default()
            .dst_set(self.sets[slot as usize])
            .dst_binding(4)
            .descriptor_type(vk::DescriptorType::STORAGE_IMAGE)
            .image_info(&image);
        // SAFETY: `slot`'s set is not in use: `record_tiled_with`, the one caller, refused a
        // slot not declared finished (`PendingSlots::refuse_slot`; `slot_finished`'s # Safety).
        // Binding 4 is `TILED_SET`'s storage image, and `hdr` is the caller's live view with
        // `STORAGE` usage (`record_tiled`'s # Safety, `check_usage`), in `GENERAL` when the
        // kernels run.
        unsafe { crate::gpu::device::descriptors::update_sets(ctx, &[write]) };
    }

    /// Records the classification with `sets` bound: the G-buffer (or the decode hook's
    /// images) read by compute shaders, and with `depth_sampled` the depth aspect too, in
    /// `DEPTH_READ_ONLY_STENCIL_ATTACHMENT_OPTIMAL` as the light passes hold it; the HDR target
    /// (in `sets.slot`'s tiled set, [`TiledLighting::set_target`]) cleared first with `clear`
    /// and left in `GENERAL` for the shade kernels ([`TiledLighting::record_shade`], next);
    /// the work shaped as `shape` says.
    #[allow(clippy::too_many_arguments)]
    pub fn record_classify(
        &self,
        rec: &Recording,
        sets: &TiledSets,
        targets: &mut LightingTargets,
        depth_sampled: bool,
        clear: bool,
        mixed: MixedTiles,
        shape: TileClassify,
    ) {
        let push = self.push(clear, mixed);
        rec.pass(super::names::TILE_CLASSIFY, |rec| {
            let (sampled, keep) = (ImageAccess::ComputeSampled, Contents::Keep);
            let mut uses = uses_of(&mut targets.gbuffer, sampled, keep);
            if depth_sampled {
                let ds = &mut targets.depth_stencil;
                uses.push((ds, ImageAccess::ComputeDepthSampled, keep));
            }
            let hdr_contents = if clear {
                Contents::Discard
            } else {
                Contents::Keep
            };
            uses.push((&mut targets.hdr, ImageAccess::ComputeStorage, hdr_contents));
            rec.declare(&mut uses);
            // Every slot shares the tile buffers: an earlier frame still in flight (an engine's,
            // another slot) may be using them, by the tiled shade's indirect dispatches and
            // kernels or by the depth-id passes' fragment shaders. The reset's writes wait for
            // every use declared before (`declare_buffers` derives the barrier), whichever
            // pass it was. Synchronisation validation does not see this hand-over across
            // submissions; histencil's hazard check does
            // (`hazard_tile_rewrite_removed_across_two_slots_submissions`).
            let write = BufferAccess::TransferWrite;
            let rewrite = [(self.dispatch.handle, write), (self.masks.handle, write)];
            rec.declare_buffers_leaving_out(&rewrite, omitted(HandOver::TileRewrite, Barrier));
            // Each slot's dispatch starts at zero tiles.
            let reset: Vec<u32> = (0..=MIXED_SLOT).flat_map(|_| [0, 1, 1, 0]).collect();
            // SAFETY: outside rendering (`update` and `fill` check it in debug builds;
            // `Recording::new`'s # Safety). `reset` is the dispatch buffer's exact size,
            // `(MIXED_SLOT + 1) * 16` bytes, a multiple of 4 under 64 KiB; both buffers are live
            // with `TRANSFER_DST` usage, and the barrier above orders these writes after every
            // earlier use of them.
            unsafe {
                rec.update(self.dispatch.handle, bytemuck::cast_slice(&reset));
                // Every tile's light mask starts empty; the light lists set bits.
                rec.fill(self.masks.handle, 0);
            }
            // The classification counts its tiles into the dispatch arguments (atomics), and
            // writes the lists and depth ranges.
            use BufferAccess::{ComputeReadWrite, ComputeWrite};
            let classify = [
                (self.dispatch.handle, ComputeReadWrite),
                (self.lists.handle, ComputeWrite),
                (self.depths.handle, ComputeWrite),
            ];
            let left_out = omitted(HandOver::ClassifyDeclaration, Declaration);
            rec.declare_buffers_leaving_out(&classify, left_out);
            // SAFETY: the sets match the layout made in `new`: the lighting's frame and decode
            // sets (sets 0 and 1), this slot's tiled set (2) and the visibility hook's (4, its
            // layout there when it has a set); the push is `TiledPush`, the layout's compute
            // range.
            unsafe {
                let bound = [sets.frame, sets.decode, self.sets[sets.slot as usize]];
                let (compute, layout) = (vk::PipelineBindPoint::COMPUTE, self.pipeline_layout);
                rec.bind_sets(compute, layout, 0, &bound);
                if let Some(set) = sets.visibility {
                    rec.bind_sets(compute, layout, 4, &[set]);
                }
                let stages = vk::ShaderStageFlags::COMPUTE;
                rec.push(layout, stages, 0, bytemuck::bytes_of(&push));
            }
            // SAFETY: outside rendering (`dispatch` checks it); both classification pipelines
            // were made by `new` with this layout, whose sets and push constants are bound just
            // above; a group per tile (or per `tile` x `tile` tiles), far below 65535 a side for
            // any image a device allows.
            unsafe {
                let (x, y) = self.tiles_xy;
                let (pipeline, groups) = match shape {
                    TileClassify::Workgroup => (self.classify, (x, y)),
                    // A workgroup of `tile` x `tile` invocations covers as many tiles.
                    TileClassify::PerInvocation => {
                        let tile = self.side.pixels();
                        (self.classify_alone, (x.div_ceil(tile), y.div_ceil(tile)))
                    }
                };
                rec.bind_pipeline(vk::PipelineBindPoint::COMPUTE, pipeline);
                rec.dispatch([groups.0, groups.1, 1]);
            }
        });
    }

    /// Records the light lists of `lights` lights, after [`TiledLighting::record_classify`] in
    /// the same command buffer (whose sets and push constants stay bound): each light's bit in
    /// the masks of the tiles it can reach, for [`TiledLighting::record_shade`].
    pub fn record_light_lists(&self, rec: &Recording, lights: u32) {
        rec.pass(super::names::TILE_LIGHTS, |rec| {
            // The light lists set bits in the tiles' light masks (after the reset's fill), by
            // the tiles' depth ranges.
            rec.declare_buffers(&[
                (self.masks.handle, BufferAccess::ComputeReadWrite),
                (self.depths.handle, BufferAccess::ComputeRead),
            ]);
            // A workgroup per light, in rows of at most the guaranteed workgroup count.
            const ROW: u32 = 65535;
            let groups = (lights.min(ROW), lights.div_ceil(ROW));
            // SAFETY: outside rendering (`dispatch` checks it), after `record_classify` bound
            // this layout's sets and push constants (`record_tiled_with`, the one caller); the
            // pipeline was made by `new` with that layout; at most 65535 groups along each axis.
            unsafe {
                rec.bind_pipeline(vk::PipelineBindPoint::COMPUTE, self.light_lists);
                rec.dispatch([groups.0, groups.1, 1]);
            }
        });
    }

    /// Records one indirect dispatch per BRDF slot over its tiles, and with
    /// [`MixedTiles::Branching`] one over the mixed tiles, after
    /// [`TiledLighting::record_classify`] with the same `mixed` in the same command buffer
    /// (whose sets and push constants stay bound); the HDR target `hdr` stays in `GENERAL`.
    pub fn record_shade(&self, rec: &Recording, mixed: MixedTiles, hdr: &mut ImageRef) {
        rec.step("tiled-shade", |rec| {
            // The kernels read the tile buffers the classification and light lists wrote, the
            // dispatch buffer as their arguments too.
            let read = BufferAccess::ComputeRead;
            let mut uses = self.buffers().map(|b| (b, read)).to_vec();
            uses.push((self.dispatch.handle, BufferAccess::IndirectRead));
            rec.declare_buffers_leaving_out(&uses, omitted(HandOver::TileLists, Barrier));
            let branching =
                (mixed == MixedTiles::Branching).then_some((MIXED_SLOT, &self.branching));
            for (slot, pipeline) in self.shade.iter().enumerate().chain(branching) {
                rec.step(&format!("tiled-shade-{slot}"), |rec| {
                    // SAFETY: as in `record_light_lists`; `slot <= MIXED_SLOT` (at most `MAX_SLOTS`
                    // kernels, checked in `new`), so the arguments at `slot * 16` lie inside the
                    // dispatch buffer, which has `INDIRECT_BUFFER` usage, written by the
                    // classification and made visible to the indirect read (declared above).
                    unsafe {
                        rec.bind_pipeline(vk::PipelineBindPoint::COMPUTE, *pipeline);
                        rec.dispatch_indirect(self.dispatch.handle, (slot * 16) as u64);
                    }
                });
                // The next BRDF's kernel adds onto the same image (other pixels, but one image).
                rec.transition(hdr, ImageAccess::ComputeStorage, Contents::Keep);
            }
        });
    }
}

/// What a hazard test leaves out of a declaration where it omits `hand_over` (nothing else).
fn omitted(hand_over: HandOver, part: LeaveOut) -> Option<LeaveOut> {
    (!crate::gpu::device::hazards::records(hand_over)).then_some(part)
}
