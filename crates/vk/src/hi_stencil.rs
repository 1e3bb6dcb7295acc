//! Console hi-stencil, emulated on the GPU exactly as `histencil_model::TileSurface` specifies,
//! so the CPU simulator is an oracle for it.
//!
//! The coarse surface is one word per [`HI_STENCIL_TILE`]-pixel tile, in two buffers: `pending`
//! (what write-enabled draws evaluated) and `active` (what testing draws see). A hi-stencil
//! write is a *split pass*: the draw marks the tiles it rasterises and lists each once
//! (`hi_stencil_touch.frag`), rendering ends, and `hi_stencil_update.comp`, dispatched
//! indirectly over that list, re-evaluates the listed tiles into `pending`, reading the stencil
//! where it is through a stencil-aspect view: a small light's write costs its own tiles, not
//! the screen's, and nothing is copied. Two writes need no listing fragment shader
//! ([`plan_touches`]): a full-screen one touches every tile, and one that draws the same
//! volume with the same faces as its light's previous write touches that write's tiles. A
//! flush, or the next write while one is unflushed (the latest point hardware could retire
//! it), copies `pending` to `active`. Testing draws reject
//! fragments of failing tiles in the light shader (`LIGHT_DRAW_HI_STENCIL_TEST`).
//!
//! Statistics are optional because counting needs extra draws and atomics: with them on, each
//! testing draw is preceded by `hi_stencil_count.frag` over the same geometry, and light shaders
//! count the fragments they shade.

use crate::access::{memory_barrier, transition, Contents, ImageAccess, ImageRef};
use crate::compute::ComputePipeline;
use crate::context::Context;
use crate::descriptors::{sets_of, write_storage_buffers, HI_STENCIL_UPDATE_SET};
use crate::error::{Result, VkCall};
use crate::readback::{copy_image_to_buffer, host_readable};
use crate::resources::Buffer;
use crate::shader_consts::{HI_STENCIL_TILE, HI_STENCIL_UPDATE_GROUP};
use crate::shaders;
use crate::state::compare_op;
use crate::teardown::{build, Destroy};
use ash::vk;
use gpu_allocator::MemoryLocation;
use histencil_model::{CullMode, FramePlan, Geometry, HiStencilState, Step, TileStats};

/// Push constants of `hi_stencil_update.comp`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct UpdatePush {
    compare: u32,
    reference: u32,
    read_mask: u32,
    width: u32,
    height: u32,
    tiles_x: u32,
    /// 1: update every tile (after a full-screen write); 0: the listed tiles.
    all_tiles: u32,
}

/// Which tiles a hi-stencil write touched, for its update.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TouchedTiles {
    /// Those its draw lists (`hi_stencil_touch.frag`): a light volume's.
    Listed,
    /// Those the light's previous write listed: the same volume with the same faces
    /// rasterises the same pixels whatever its depth and stencil tests, so its draw needs no
    /// fragment shader (the talk's mask pass per BRDF of one light).
    Kept,
    /// Every tile: a full-screen draw rasterises every pixel, so it needs no fragment shader
    /// to list them (a console's mask pass has none either).
    All,
}

/// How one hi-stencil write learns the tiles it touched, and whether the next write of the
/// same raster keeps its list.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Touch {
    pub tiles: TouchedTiles,
    /// The list stays for the next write ([`TouchedTiles::Kept`]) instead of being emptied.
    pub keep: bool,
}

/// Per step of `plan`, how its hi-stencil write learns its tiles (`None` where the step writes
/// none): a full-screen write touches all; a volume write lists its own unless the light's
/// previous write drew the same volume with the same faces, whose list it keeps.
pub fn plan_touches(plan: &FramePlan) -> Vec<Option<Touch>> {
    let mut touches: Vec<Option<Touch>> = vec![None; plan.steps.len()];
    // The last volume write since the last full-screen one: its step, light and culled faces.
    let mut last: Option<(usize, usize, CullMode)> = None;
    for (index, step) in plan.steps.iter().enumerate() {
        let Step::Pass { light, pass } = step else {
            continue;
        };
        if !pass.state.writes_hi_stencil() {
            continue;
        }
        let tiles = match pass.geometry {
            Geometry::FullScreen => {
                last = None;
                TouchedTiles::All
            }
            Geometry::Volume => {
                let raster = (*light, pass.state.cull);
                let previous = last.filter(|&(_, l, c)| (l, c) == raster);
                last = Some((index, raster.0, raster.1));
                match previous {
                    Some((at, ..)) => {
                        if let Some(t) = touches[at].as_mut() {
                            t.keep = true;
                        }
                        TouchedTiles::Kept
                    }
                    None => TouchedTiles::Listed,
                }
            }
        };
        touches[index] = Some(Touch { tiles, keep: false });
    }
    touches
}

/// Words of the statistics buffer (`HiStencilStats` in include/hi_stencil.glsl).
const STATS_WORDS: usize = 4;

/// The tile surface, its scratch buffers and the update pipeline.
#[derive(Default)]
pub struct HiStencilSurface {
    extent: vk::Extent2D,
    tiles_x: u32,
    active: Buffer,
    pending: Buffer,
    touched: Buffer,
    /// The tiles the current write draw touched, behind the update's indirect dispatch
    /// arguments and their count (`HiStencilTouchedList` in include/hi_stencil.glsl).
    touched_list: Buffer,
    stats: Buffer,
    saved: Buffer,
    update: Option<ComputePipeline>,
    pool: vk::DescriptorPool,
    /// The update's set of each frame-in-flight slot: the touched list, the pending surface and
    /// that slot's frame's stencil view.
    sets: Vec<vk::DescriptorSet>,
    /// The stencil-aspect view of each slot's last depth-stencil image (`prepare_slot`).
    views: Vec<vk::ImageView>,
    /// A write since the last flush has not become active yet (see the module doc).
    unflushed: bool,
}

/// The touched list's header: the update's dispatch arguments and the tile count.
const LIST_HEADER_BYTES: u64 = 16;

/// Bytes of a buffer holding one stencil byte per pixel, rounded up to whole words.
fn stencil_bytes(extent: vk::Extent2D) -> u64 {
    (u64::from(extent.width) * u64::from(extent.height)).next_multiple_of(4)
}

impl Destroy for HiStencilSurface {
    fn destroy(&mut self, ctx: &Context) {
        if let Some(mut update) = self.update.take() {
            update.destroy(ctx);
        }
        unsafe {
            ctx.device.destroy_descriptor_pool(self.pool, None);
            for view in self.views.drain(..) {
                ctx.device.destroy_image_view(view, None);
            }
        }
        self.pool = vk::DescriptorPool::null();
        self.sets.clear();
        for b in [
            &mut self.active,
            &mut self.pending,
            &mut self.touched,
            &mut self.touched_list,
            &mut self.stats,
            &mut self.saved,
        ] {
            b.destroy(ctx);
        }
    }
}

impl HiStencilSurface {
    /// The surface for `extent`, with an update set for each of `slots` frames in flight; a
    /// failure half way frees what was made.
    pub fn new(ctx: &Context, extent: vk::Extent2D, slots: u32) -> Result<Self> {
        let tiles_x = extent.width.div_ceil(HI_STENCIL_TILE);
        let tiles_y = extent.height.div_ceil(HI_STENCIL_TILE);
        let tile_bytes = u64::from(tiles_x * tiles_y) * 4;
        use vk::BufferUsageFlags as U;
        let gpu = |name, size, usage| Buffer::new(ctx, name, size, usage, MemoryLocation::GpuOnly);
        let storage = U::STORAGE_BUFFER | U::TRANSFER_DST;
        build(ctx, |h: &mut Self| {
            h.extent = extent;
            h.tiles_x = tiles_x;
            h.active = gpu("hi-stencil-active", tile_bytes, storage)?;
            let pending_usage = storage | U::TRANSFER_SRC;
            h.pending = gpu("hi-stencil-pending", tile_bytes, pending_usage)?;
            h.touched = gpu("hi-stencil-touched", tile_bytes, storage)?;
            let list_bytes = LIST_HEADER_BYTES + tile_bytes;
            let list_usage = storage | U::INDIRECT_BUFFER;
            h.touched_list = gpu("hi-stencil-touched-list", list_bytes, list_usage)?;
            h.stats = Buffer::new(
                ctx,
                "hi-stencil-stats",
                (STATS_WORDS * 4) as u64,
                storage,
                MemoryLocation::GpuToCpu,
            )?;
            h.saved = gpu("saved-stencil", stencil_bytes(extent), storage)?;
            let update = ComputePipeline::new(
                ctx,
                "hi-stencil-update",
                HI_STENCIL_UPDATE_SET,
                ("hi-stencil-update-comp", shaders::HI_STENCIL_UPDATE_COMP),
                size_of::<UpdatePush>() as u32,
            )?;
            let set_layout = update.set_layout;
            h.update = Some(update);
            h.create_sets(ctx, set_layout, slots)
        })
    }

    /// The pool and every slot's update set, with the touched list and pending surface written
    /// (the stencil view is written per frame).
    fn create_sets(
        &mut self,
        ctx: &Context,
        layout: vk::DescriptorSetLayout,
        slots: u32,
    ) -> Result<()> {
        let sizes = [
            (vk::DescriptorType::STORAGE_BUFFER, 2),
            (vk::DescriptorType::SAMPLED_IMAGE, 1),
        ];
        (self.pool, self.sets) = sets_of(ctx, "hi-stencil-update-set", layout, slots, &sizes)?;
        self.views = vec![vk::ImageView::null(); slots as usize];
        for set in &self.sets {
            write_storage_buffers(ctx, *set, &[self.touched_list.handle, self.pending.handle]);
        }
        Ok(())
    }

    /// Points `slot`'s update set at a stencil-aspect view of `depth_stencil`, made anew (the
    /// slot's last view goes: its frame has finished, which recording into the slot promises).
    pub fn prepare_slot(
        &mut self,
        ctx: &Context,
        slot: u32,
        depth_stencil: &ImageRef,
    ) -> Result<()> {
        let (set, view) = (self.sets[slot as usize], &mut self.views[slot as usize]);
        unsafe { ctx.device.destroy_image_view(*view, None) };
        *view = vk::ImageView::null();
        let info = vk::ImageViewCreateInfo::default()
            .image(depth_stencil.image)
            .view_type(vk::ImageViewType::TYPE_2D)
            .format(depth_stencil.format)
            .subresource_range(
                vk::ImageSubresourceRange::default()
                    .aspect_mask(vk::ImageAspectFlags::STENCIL)
                    .level_count(1)
                    .layer_count(1),
            );
        *view = unsafe { ctx.device.create_image_view(&info, None) }.call("vkCreateImageView")?;
        ctx.name(*view, &format!("hi-stencil-stencil-view-{slot}"));
        let image = [vk::DescriptorImageInfo::default()
            .image_view(*view)
            .image_layout(vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL)];
        let write = vk::WriteDescriptorSet::default()
            .dst_set(set)
            .dst_binding(2)
            .descriptor_type(vk::DescriptorType::SAMPLED_IMAGE)
            .image_info(&image);
        unsafe { ctx.device.update_descriptor_sets(&[write], &[]) };
        Ok(())
    }

    /// The buffers of set 2 of the light pipelines (`HI_STENCIL_SET`), in binding order.
    pub fn light_set_buffers(&self) -> [vk::Buffer; 5] {
        [
            self.active.handle,
            self.touched.handle,
            self.stats.handle,
            self.saved.handle,
            self.touched_list.handle,
        ]
    }

    /// Outside rendering, before lighting: every tile passes, no tile is marked, statistics zero.
    pub fn record_reset(&mut self, ctx: &Context, cmd: vk::CommandBuffer) {
        let d = &ctx.device;
        // The previous frame's lighting (in flight, in an earlier submission) may still use
        // the surface.
        memory_barrier(ctx, cmd);
        unsafe {
            d.cmd_fill_buffer(cmd, self.active.handle, 0, vk::WHOLE_SIZE, 1);
            d.cmd_fill_buffer(cmd, self.pending.handle, 0, vk::WHOLE_SIZE, 1);
            d.cmd_fill_buffer(cmd, self.touched.handle, 0, vk::WHOLE_SIZE, 0);
            d.cmd_fill_buffer(cmd, self.stats.handle, 0, vk::WHOLE_SIZE, 0);
        }
        self.clear_list(ctx, cmd);
        memory_barrier(ctx, cmd);
        self.unflushed = false;
    }

    /// Outside rendering: pending state becomes active.
    pub fn record_flush(&mut self, ctx: &Context, cmd: vk::CommandBuffer) {
        // Light shaders may still be reading the active surface.
        memory_barrier(ctx, cmd);
        let region = [vk::BufferCopy::default().size(self.pending.size)];
        unsafe {
            ctx.device
                .cmd_copy_buffer(cmd, self.pending.handle, self.active.handle, &region)
        };
        memory_barrier(ctx, cmd);
        self.unflushed = false;
    }

    /// Empties the touched list: no update workgroups (y = z = 1), no tiles.
    fn clear_list(&self, ctx: &Context, cmd: vk::CommandBuffer) {
        let header: [u32; 4] = [0, 1, 1, 0];
        let bytes = bytemuck::bytes_of(&header);
        unsafe {
            ctx.device
                .cmd_update_buffer(cmd, self.touched_list.handle, 0, bytes)
        };
    }

    /// Outside rendering, after a write draw touched tiles as `touch` says, in a frame recorded
    /// into `slot` (prepared with this `depth_stencil`, [`HiStencilSurface::prepare_slot`]):
    /// retires an unflushed earlier write, then evaluates `hi` on those tiles into pending
    /// state, reading the stencil in place, and empties the list for the next write unless it
    /// keeps it. Leaves the depth-stencil image attached-ready.
    pub fn record_update(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        slot: u32,
        depth_stencil: &mut ImageRef,
        hi: &HiStencilState,
        touch: Touch,
    ) {
        if self.unflushed {
            self.record_flush(ctx, cmd);
        }
        let stencil_read = ImageAccess::ComputeDepthStencilSampled;
        transition(ctx, cmd, depth_stencil, stencil_read, Contents::Keep);
        let push = UpdatePush {
            compare: compare_op(hi.compare).as_raw() as u32,
            reference: u32::from(hi.reference),
            read_mask: u32::from(hi.read_mask.unwrap_or(0xFF)),
            width: self.extent.width,
            height: self.extent.height,
            tiles_x: self.tiles_x,
            all_tiles: u32::from(touch.tiles == TouchedTiles::All),
        };
        let set = self.sets[slot as usize];
        let update = self.update.as_ref().expect("made with the surface");
        update.bind(ctx, cmd, set, bytemuck::bytes_of(&push));
        match touch.tiles {
            TouchedTiles::Listed | TouchedTiles::Kept => unsafe {
                ctx.device
                    .cmd_dispatch_indirect(cmd, self.touched_list.handle, 0)
            },
            TouchedTiles::All => {
                let tiles = self.tiles_x * self.extent.height.div_ceil(HI_STENCIL_TILE);
                let groups = tiles.div_ceil(HI_STENCIL_UPDATE_GROUP);
                unsafe { ctx.device.cmd_dispatch(cmd, groups, 1, 1) };
            }
        }
        let attached = ImageAccess::DepthStencilAttachment;
        transition(ctx, cmd, depth_stencil, attached, Contents::Keep);
        if !touch.keep {
            // The list's counts are read (as dispatch arguments too) before they are zeroed.
            memory_barrier(ctx, cmd);
            self.clear_list(ctx, cmd);
            memory_barrier(ctx, cmd);
        }
        self.unflushed = true;
    }

    /// Outside rendering: copies the stencil aside for a later restore (`restore_preserved.frag`).
    pub fn record_save(&self, ctx: &Context, cmd: vk::CommandBuffer, depth_stencil: &mut ImageRef) {
        copy_image_to_buffer(
            ctx,
            cmd,
            depth_stencil,
            vk::ImageAspectFlags::STENCIL,
            &self.saved,
        );
        transition(
            ctx,
            cmd,
            depth_stencil,
            ImageAccess::DepthStencilAttachment,
            Contents::Keep,
        );
        memory_barrier(ctx, cmd);
    }

    /// Makes the statistics visible to the host; record after the last lighting draw.
    pub fn record_stats_readable(&self, ctx: &Context, cmd: vk::CommandBuffer) {
        host_readable(ctx, cmd, vk::PipelineStageFlags2::FRAGMENT_SHADER);
    }

    /// The statistics of the last frame that counted; `flushes` is the caller's to fill in.
    pub fn read_stats(&self) -> TileStats {
        let words: &[u32] = bytemuck::cast_slice(self.stats.read());
        TileStats {
            tiles_tested: u64::from(words[0]),
            tiles_culled: u64::from(words[1]),
            fragments_shaded: u64::from(words[2]),
            flushes: 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use histencil_model::{FlushPolicy, LightCase, LightRequest, LightTechnique, Ps3Like};
    use histencil_model::{StencilLayout, X360Like};

    fn writes(plan: &FramePlan) -> Vec<(usize, CullMode, Geometry, Touch)> {
        plan.steps
            .iter()
            .zip(plan_touches(plan))
            .filter_map(|(step, touch)| match step {
                Step::Pass { light, pass } => {
                    assert_eq!(touch.is_some(), pass.state.writes_hi_stencil());
                    touch.map(|t| (*light, pass.state.cull, pass.geometry, t))
                }
                _ => {
                    assert!(touch.is_none());
                    None
                }
            })
            .collect()
    }

    /// A volume write lists its tiles unless the light's previous write drew the same faces,
    /// whose list that write kept; a full-screen write touches all.
    #[test]
    fn writes_keep_a_list_only_for_the_same_lights_same_faces() {
        let layout = StencilLayout::new(3, 0).unwrap();
        let request = |case| LightRequest {
            case,
            affected: vec![0, 1, 2],
            technique: LightTechnique::Stencil,
        };
        let requests = [
            request(LightCase::Outside),
            request(LightCase::Outside),
            request(LightCase::ViewerInside),
        ];
        for plan in [
            FramePlan::from_requests(&layout, &Ps3Like, &requests, FlushPolicy::Auto).unwrap(),
            FramePlan::from_requests(&layout, &X360Like::default(), &requests, FlushPolicy::Auto)
                .unwrap(),
        ] {
            let writes = writes(&plan);
            assert!(writes.iter().any(|w| w.3.tiles == TouchedTiles::Kept));
            for (i, &(light, cull, geometry, touch)) in writes.iter().enumerate() {
                let next = writes.get(i + 1);
                let same = |w: &(usize, CullMode, Geometry, Touch)| {
                    (w.0, w.1, w.2) == (light, cull, Geometry::Volume)
                };
                match geometry {
                    Geometry::FullScreen => assert_eq!(touch.tiles, TouchedTiles::All),
                    Geometry::Volume => {
                        let kept = i > 0 && same(&writes[i - 1]);
                        let expected = if kept {
                            TouchedTiles::Kept
                        } else {
                            TouchedTiles::Listed
                        };
                        assert_eq!(touch.tiles, expected, "write {i}");
                    }
                }
                let keeps = geometry == Geometry::Volume && next.is_some_and(same);
                assert_eq!(touch.keep, keeps, "write {i}");
            }
        }
    }
}
