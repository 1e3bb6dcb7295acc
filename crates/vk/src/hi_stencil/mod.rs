//! Console hi-stencil, emulated on the GPU exactly as `histencil_model::TileSurface` specifies,
//! so the CPU simulator is an oracle for it.
//!
//! The coarse surface is one word per `HI_STENCIL_TILE`-pixel tile (8x8), in two buffers: `pending`
//! (what write-enabled draws evaluated) and `active` (what testing draws see). A hi-stencil write
//! is a *split pass*: the write draw itself is the platform's (the same stencil-only pipeline as
//! native), rendering ends, and the emulator learns which tiles it rasterised by drawing the same
//! volume with the same faces once more, without a fragment shader, into a depth-only *touch image*
//! whose viewport pins every fragment's depth to a marker unique to the write (a fragment shader
//! with a side effect would run for every covered pixel, which a CPU rasteriser pays for many times
//! over a depth-only draw). `hi_stencil_update.comp` then looks at the tiles of the light's screen
//! rectangle (`PlannedLight::screen_rect`) and re-evaluates into `pending` those holding the
//! marker, reading the stencil where it is through a stencil-aspect view: a small light's write
//! costs its own tiles, not the screen's, and nothing is copied. Two writes need no touch draw
//! ([`plan_touches`], in `touch.rs` with the other pure rules): a full-screen one touches every
//! tile, and one that draws the same volume with the same faces as its light's previous write
//! touches that write's tiles, whose marker is still in the touch image. A flush, or the next write
//! while one is unflushed (the latest point hardware could retire it), copies `pending` to
//! `active`. Testing draws reject fragments of failing tiles in the light shader
//! (`LIGHT_DRAW_HI_STENCIL_TEST`).
//!
//! Statistics are optional because counting needs extra draws and atomics: with them on, each
//! testing draw is preceded by `hi_stencil_count.frag` over the same geometry, and light shaders
//! count the fragments they shade.

use crate::gpu::access::{access_info, BufferAccess, Contents, ImageAccess, ImageRef, Use};
use crate::gpu::device::context::Context;
use crate::gpu::device::descriptors::{
    binding, sets_of, write_storage_buffers, BindingDesc, BindingKind,
};
use crate::gpu::device::error::{Result, VkCall};
use crate::gpu::device::resources::{Buffer, Image};
use crate::gpu::device::teardown::{build, Destroy};
use crate::gpu::encoder::compute::ComputePipeline;
use crate::gpu::encoder::recording::Recording;
use crate::gpu::frame::attachments::{depth_stencil_attachment, Load};
use crate::gpu::frame::state::compare_op;
use crate::shader_consts::{
    HI_STENCIL_MODE_AND_OR, HI_STENCIL_MODE_CONSOLE, HI_STENCIL_MODE_PRETESTS,
    HI_STENCIL_UPDATE_GROUP,
};
use crate::shaders;
use ash::vk;
use gpu_allocator::MemoryLocation;
use histencil_model::{HiStencilState, TileStats};

mod amd;
mod touch;

pub use amd::{GpuHierarchy, TileTest};

use touch::next_marker;

/// Set 2 of the light pipelines: the hi-stencil emulation (include/hi_stencil.glsl).
pub(crate) const HI_STENCIL_SET: &[BindingDesc] = &[
    binding(0, BindingKind::StorageBuffer, ""),
    binding(1, BindingKind::StorageBuffer, ""),
    binding(2, BindingKind::StorageBuffer, "hi_stats"),
    binding(3, BindingKind::StorageBuffer, ""),
];
/// The tile update's pending surface (written), touch image (read) and stencil (a
/// stencil-aspect view, read): the update's set (`hi_stencil_update.comp`).
pub(crate) const HI_STENCIL_UPDATE_SET: &[BindingDesc] = &[
    binding(0, BindingKind::StorageBuffer, ""),
    binding(1, BindingKind::SampledImage, "touch_depth"),
    binding(2, BindingKind::SampledImage, "stencil_image"),
];
pub use touch::{plan_touches, tile_rect, TileRect, TouchedTiles, WriteTiles};

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
    /// The tiles looked at: `rect_x, rect_y` the first, `rect_width` per row.
    rect_x: u32,
    rect_y: u32,
    rect_width: u32,
    rect_tiles: u32,
    /// The touch image's code of the write's marker; 0: every tile of the rectangle was touched.
    marker: u32,
    /// What is evaluated: `HI_STENCIL_MODE_*` (`shader_consts`), by [`TileTest`].
    mode: u32,
    /// With the pretests: how many, the first in `read_mask` / `reference`, the second here.
    tests: u32,
    mask2: u32,
    value2: u32,
}

/// The touch image's format: depth-only, the one every Vulkan device renders to and samples.
pub const TOUCH_FORMAT: vk::Format = vk::Format::D16_UNORM;

/// Points `binding` of an update set at a view of a depth-stencil image read in
/// `DEPTH_STENCIL_READ_ONLY_OPTIMAL` (the touch image; the frame's stencil).
fn write_read_only_view(ctx: &Context, set: vk::DescriptorSet, binding: u32, view: vk::ImageView) {
    let image = [vk::DescriptorImageInfo::default()
        .image_view(view)
        .image_layout(vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL)];
    let write = vk::WriteDescriptorSet::default()
        .dst_set(set)
        .dst_binding(binding)
        .descriptor_type(vk::DescriptorType::SAMPLED_IMAGE)
        .image_info(&image);
    // SAFETY: `set` and `view` were made from this context's device; the set is not bound by a
    // pending command buffer (the surface's sets are written at creation, at a resize once no
    // slot is in flight, and per slot once that slot's frame is declared finished).
    unsafe { crate::gpu::device::descriptors::update_sets(ctx, &[write]) };
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
    /// The stamp of the last statistics draw that covered each tile (`hi_stencil_count.frag`).
    touched: Buffer,
    /// Where the last volume writes rasterised, as their markers' depths (the module doc).
    touch: Image,
    /// The code of the marker the last touch draw wrote; 0 before the frame's first.
    marker: u32,
    stats: Buffer,
    saved: Buffer,
    update: Option<ComputePipeline>,
    pool: vk::DescriptorPool,
    /// The update's set of each frame-in-flight slot: the touch image, the pending surface and
    /// that slot's frame's stencil view.
    sets: Vec<vk::DescriptorSet>,
    /// The stencil-aspect view of each slot's last depth-stencil image (`prepare_slot`).
    views: Vec<vk::ImageView>,
    /// A write since the last flush has not become active yet (see the module doc).
    unflushed: bool,
}

/// Bytes of a buffer holding one stencil byte per pixel, rounded up to whole words.
fn stencil_bytes(extent: vk::Extent2D) -> u64 {
    (u64::from(extent.width) * u64::from(extent.height)).next_multiple_of(4)
}

impl Destroy for HiStencilSurface {
    fn destroy(&mut self, ctx: &Context) {
        if let Some(mut update) = self.update.take() {
            update.destroy(ctx);
        }
        // SAFETY: the pool and views were made from this context's device, or are null (a
        // surface made half way), which destroying ignores; the GPU is done with them: the
        // owner destroys the surface once no frame that used it is in flight (teardown rule).
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
            &mut self.stats,
            &mut self.saved,
        ] {
            b.destroy(ctx);
        }
        self.touch.destroy(ctx);
    }
}

impl HiStencilSurface {
    /// The surface for `extent`, with an update set for each of `slots` frames in flight; a
    /// failure half way frees what was made.
    pub fn new(ctx: &Context, extent: vk::Extent2D, slots: u32) -> Result<Self> {
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST;
        build(ctx, |h: &mut Self| {
            h.make_sized(ctx, extent)?;
            h.stats = Buffer::new(
                ctx,
                "hi-stencil-stats",
                (STATS_WORDS * 4) as u64,
                storage,
                MemoryLocation::GpuToCpu,
            )?;
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

    /// Makes the parts `extent` sizes, into this surface's empty fields: the tile surfaces, the
    /// touch image and the saved-stencil buffer (what `new` makes first and `resize` anew).
    fn make_sized(&mut self, ctx: &Context, extent: vk::Extent2D) -> Result<()> {
        let frame = TileRect::frame(extent);
        let tile_bytes = u64::from(frame.width * frame.height) * 4;
        use vk::BufferUsageFlags as U;
        let gpu = |name, size, usage| Buffer::new(ctx, name, size, usage, MemoryLocation::GpuOnly);
        let storage = U::STORAGE_BUFFER | U::TRANSFER_DST;
        self.extent = extent;
        self.tiles_x = frame.width;
        self.active = gpu("hi-stencil-active", tile_bytes, storage)?;
        self.pending = gpu("hi-stencil-pending", tile_bytes, storage | U::TRANSFER_SRC)?;
        self.touched = gpu("hi-stencil-touched", tile_bytes, storage)?;
        use vk::ImageUsageFlags as I;
        let touch_usage = I::DEPTH_STENCIL_ATTACHMENT | I::SAMPLED;
        self.touch = Image::new(ctx, "hi-stencil-touch", TOUCH_FORMAT, extent, touch_usage)?;
        self.saved = gpu("saved-stencil", stencil_bytes(extent), storage)?;
        Ok(())
    }

    /// The extent its surfaces are made for.
    pub fn extent(&self) -> vk::Extent2D {
        self.extent
    }

    /// The surface for a new `extent`: the tile surfaces, the touch image and the saved-stencil
    /// buffer made anew, the update pipeline and sets kept (the sets re-pointed). A failure
    /// leaves the surface as it was. The GPU has finished every frame that used it.
    pub fn resize(&mut self, ctx: &Context, extent: vk::Extent2D) -> Result<()> {
        let mut fresh = Self::default();
        if let Err(e) = fresh.make_sized(ctx, extent) {
            fresh.destroy(ctx);
            return Err(e);
        }
        std::mem::swap(&mut self.active, &mut fresh.active);
        std::mem::swap(&mut self.pending, &mut fresh.pending);
        std::mem::swap(&mut self.touched, &mut fresh.touched);
        std::mem::swap(&mut self.touch, &mut fresh.touch);
        std::mem::swap(&mut self.saved, &mut fresh.saved);
        (self.extent, self.tiles_x) = (fresh.extent, fresh.tiles_x);
        // `fresh` holds the old extent's objects now, and nothing else.
        fresh.destroy(ctx);
        self.marker = 0;
        self.unflushed = false;
        self.point_sets(ctx);
        Ok(())
    }

    /// The pool and every slot's update set, with the touch image and pending surface written
    /// (the stencil view is written per frame).
    fn create_sets(
        &mut self,
        ctx: &Context,
        layout: vk::DescriptorSetLayout,
        slots: u32,
    ) -> Result<()> {
        let table = HI_STENCIL_UPDATE_SET;
        (self.pool, self.sets) = sets_of(ctx, "hi-stencil-update-set", layout, slots, table)?;
        self.views = vec![vk::ImageView::null(); slots as usize];
        self.point_sets(ctx);
        Ok(())
    }

    /// Points every slot's update set at the pending surface and the touch image.
    fn point_sets(&self, ctx: &Context) {
        for &set in &self.sets {
            write_storage_buffers(ctx, set, &[self.pending.handle]);
            write_read_only_view(ctx, set, 1, self.touch.view);
        }
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
        // SAFETY: the slot's last view is ours (or null) and no pending frame reads it: the
        // lighting records into a slot only once its last frame is declared finished.
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
        // SAFETY: `info` names the caller's live depth-stencil image (the # Safety of the
        // lighting's `record`), whose usage holds SAMPLED (checked by `check_usage`), and a
        // stencil aspect its depth-stencil format has.
        *view = unsafe { ctx.device.create_image_view(&info, None) }.call("vkCreateImageView")?;
        ctx.name(*view, &format!("hi-stencil-stencil-view-{slot}"));
        write_read_only_view(ctx, set, 2, *view);
        Ok(())
    }

    /// The buffers of set 2 of the light pipelines (`HI_STENCIL_SET`), in binding order.
    pub fn light_set_buffers(&self) -> [vk::Buffer; 4] {
        [
            self.active.handle,
            self.touched.handle,
            self.stats.handle,
            self.saved.handle,
        ]
    }

    /// Outside rendering, before lighting: every tile passes, no tile is marked, statistics zero.
    pub fn record_reset(&mut self, rec: &Recording) {
        let surface = [
            self.active.handle,
            self.pending.handle,
            self.touched.handle,
            self.stats.handle,
        ];
        // The fills wait for every earlier declared use (the previous frame's lighting, in
        // flight in an earlier submission, may still use the surface); each next use declares
        // itself (the light passes' reads and counts, the tile updates' writes, a flush).
        rec.declare_buffers(&surface.map(|b| (b, BufferAccess::TransferWrite)));
        // SAFETY: outside rendering (the lighting pass resets before it begins rendering;
        // `fill` checks it); the buffers are ours, made with TRANSFER_DST, and the declaration
        // above orders the fills after every earlier use.
        unsafe {
            rec.fill(self.active.handle, 1);
            rec.fill(self.pending.handle, 1);
            rec.fill(self.touched.handle, 0);
            rec.fill(self.stats.handle, 0);
        }
        self.unflushed = false;
        // The frame's first touch draw clears the touch image whole, so no frame depends on
        // what an earlier one (recorded, perhaps never submitted) left there.
        self.marker = 0;
    }

    /// Outside rendering: pending state becomes active.
    pub fn record_flush(&mut self, rec: &Recording) {
        use BufferAccess::{TransferRead, TransferWrite};
        let (pending, active) = (self.pending.handle, self.active.handle);
        // After the tile updates' writes of the pending tiles and the light shaders' reads of
        // the active ones; the next updates and light draws declare themselves.
        rec.declare_buffers(&[(pending, TransferRead), (active, TransferWrite)]);
        let region = [vk::BufferCopy::default().size(self.pending.size)];
        // SAFETY: outside rendering (a flush closes rendering first; `copy_buffer` checks it);
        // both buffers are ours and of one size, pending with TRANSFER_SRC and active with
        // TRANSFER_DST, and the declaration above orders the copy after their earlier uses.
        unsafe { rec.copy_buffer(pending, active, &region) };
        self.unflushed = false;
    }

    /// Outside rendering, after a volume write draw: begins rendering into the touch image
    /// alone, over `rect` (where the write's volume lies), with a new marker as every
    /// fragment's depth, and sets the viewport and scissor. The caller draws the write's volume
    /// with the touch pipeline (`LightShader::TouchTiles`) and the write's faces, then calls
    /// [`Self::end_touch`].
    pub fn begin_touch(&mut self, rec: &Recording, rect: TileRect) {
        // The image is cleared whole at the frame's first touch draw and when the markers run
        // out, so no pixel outside this draw's area can hold its marker, and the draw renders
        // its rectangle only (a CPU rasteriser pays for a rendering's whole area).
        let clear;
        (self.marker, clear) = next_marker(self.marker);
        let whole = vk::Rect2D::default().extent(self.extent);
        let (load, contents, area) = if clear {
            let zero = vk::ClearValue {
                depth_stencil: vk::ClearDepthStencilValue {
                    depth: 0.0,
                    stencil: 0,
                },
            };
            (Load::Clear(zero), Contents::Discard, whole)
        } else {
            (Load::Keep, Contents::Keep, rect.pixels(self.extent))
        };
        let access = ImageAccess::DepthStencilAttachment;
        rec.transition(&mut self.touch, access, contents);
        let depth = depth_stencil_attachment(&self.touch, load);
        let info = vk::RenderingInfo::default()
            .render_area(area)
            .layer_count(1)
            .depth_attachment(&depth);
        // Depth clamping (light volume pipelines clamp) pins every fragment to min_depth.
        let marker = self.marker as f32 / f32::from(u16::MAX);
        let viewport = vk::Viewport {
            x: 0.0,
            y: 0.0,
            width: self.extent.width as f32,
            height: self.extent.height as f32,
            min_depth: marker,
            max_depth: marker,
        };
        // Outside rendering (the write's bookkeeping split it); the touch image is ours,
        // transitioned to an attachment above.
        rec.begin_rendering(&info);
        rec.set_viewport(viewport);
        rec.set_scissor(area);
    }

    /// Ends the touch draw's rendering.
    pub fn end_touch(&self, rec: &Recording) {
        rec.end_rendering();
    }

    /// Outside rendering, after a write draw touched `tiles`, in a frame recorded into `slot`
    /// (prepared with this `depth_stencil`, [`HiStencilSurface::prepare_slot`]): retires an
    /// unflushed earlier write, then evaluates `hi` on those tiles into pending state, reading
    /// the stencil in place. Leaves the depth-stencil image attached-ready.
    pub fn record_update(
        &mut self,
        rec: &Recording,
        slot: u32,
        depth_stencil: &mut ImageRef,
        hi: &HiStencilState,
        tiles: WriteTiles,
    ) {
        // Not a flush the plan left out: the hardware's own retiring of an update, at the latest
        // point it could happen (the next write starts), which the model defines and the
        // simulator runs (`histencil_model::TileSurface::begin_write`); the plan's flushes are
        // the ones an engine records. The same rule in both is what lets the simulator be the
        // oracle for `FlushPolicy::Never`, where a test sees the write before the last.
        if self.unflushed {
            self.record_flush(rec);
        }
        self.unflushed = true;
        let WriteTiles { touched, rect } = tiles;
        if rect.is_empty() {
            // The volume lies off screen: it rasterised nothing.
            return;
        }
        let marker = match touched {
            TouchedTiles::All => 0,
            TouchedTiles::Drawn | TouchedTiles::Kept => {
                assert_ne!(self.marker, 0, "a kept write follows a touch draw");
                self.marker
            }
        };
        let push = UpdatePush {
            compare: compare_op(hi.compare).as_raw() as u32,
            reference: u32::from(hi.reference),
            read_mask: u32::from(hi.read_mask.unwrap_or(0xFF)),
            marker,
            ..self.update_push(rect)
        };
        self.dispatch_update(rec, slot, depth_stencil, &push);
    }

    /// The update's settings over the tiles of `rect`, evaluating nothing yet (mode 0, no
    /// compare, every tile of the rectangle touched).
    fn update_push(&self, rect: TileRect) -> UpdatePush {
        UpdatePush {
            compare: 0,
            reference: 0,
            read_mask: 0,
            width: self.extent.width,
            height: self.extent.height,
            tiles_x: self.tiles_x,
            rect_x: rect.x,
            rect_y: rect.y,
            rect_width: rect.width,
            rect_tiles: rect.width * rect.height,
            marker: 0,
            mode: HI_STENCIL_MODE_CONSOLE,
            tests: 0,
            mask2: 0,
            value2: 0,
        }
    }

    /// Runs the tile update with `push` over its rectangle, reading the stencil in place, into
    /// the pending surface; leaves the depth-stencil image attached-ready.
    fn dispatch_update(
        &mut self,
        rec: &Recording,
        slot: u32,
        depth_stencil: &mut ImageRef,
        push: &UpdatePush,
    ) {
        let stencil_read = ImageAccess::ComputeDepthStencilSampled;
        let mut uses: Vec<Use> = vec![(depth_stencil, stencil_read, Contents::Keep)];
        // The update's set holds the touch image whether or not this update looks at it, so it
        // is always in the layout the set names (its contents are kept only after a touch draw).
        let (read_layout, ..) = access_info(stencil_read);
        if self.touch.state.layout != read_layout {
            let drawn = self.touch.state.layout != vk::ImageLayout::UNDEFINED;
            let contents = if drawn {
                Contents::Keep
            } else {
                Contents::Discard
            };
            uses.push((&mut self.touch, stencil_read, contents));
        }
        rec.declare(&mut uses);
        // The stencil back from the declared uses, for its transition after the dispatch.
        let depth_stencil = uses.swap_remove(0).0;
        drop(uses);
        // The update writes the pending tiles.
        rec.declare_buffers(&[(self.pending.handle, BufferAccess::ComputeWrite)]);
        let set = self.sets[slot as usize];
        let update = self.update.as_ref().expect("made with the surface");
        update.bind(rec, set, bytemuck::bytes_of(push));
        let groups = push.rect_tiles.div_ceil(HI_STENCIL_UPDATE_GROUP);
        // SAFETY: outside rendering (`dispatch` checks it), with the update pipeline, its set
        // and push bound just above; the set's images were declared in the layouts it reads.
        unsafe { rec.dispatch([groups, 1, 1]) };
        let attached = ImageAccess::DepthStencilAttachment;
        rec.transition(depth_stencil, attached, Contents::Keep);
    }

    /// Outside rendering, before a draw of a frame recorded into `slot` that tests stencil, on
    /// a platform whose GPU keeps its own hierarchy (AMD's, [`TileTest`]): evaluates `test` on
    /// every tile of `rect` from the stencil as it is now, and makes that the active surface the
    /// draw's light shader and statistics read. Each tile's hierarchy state is exact for its
    /// current values on such a GPU (made from the G-buffer pass's stencil, updated wherever a
    /// draw writes), so evaluating it here from the values is evaluating the state. Leaves the
    /// depth-stencil image attached-ready.
    pub fn record_evaluate(
        &mut self,
        rec: &Recording,
        slot: u32,
        depth_stencil: &mut ImageRef,
        test: TileTest,
        rect: TileRect,
    ) {
        if rect.is_empty() {
            return;
        }
        let (mode, tests, first, second, compare) = match test {
            TileTest::Pretests(p) => {
                let held: Vec<(u8, u8)> = p.into_iter().flatten().collect();
                let pair = |i: usize| held.get(i).map_or((0, 0), |(m, v)| (*m, v & m));
                let tests = held.len() as u32;
                (HI_STENCIL_MODE_PRETESTS, tests, pair(0), pair(1), 0)
            }
            TileTest::AndOr {
                compare,
                mask,
                reference,
            } => (
                HI_STENCIL_MODE_AND_OR,
                0,
                (mask, reference),
                (0, 0),
                compare_op(compare).as_raw() as u32,
            ),
        };
        let push = UpdatePush {
            compare,
            reference: u32::from(first.1),
            read_mask: u32::from(first.0),
            mode,
            tests,
            mask2: u32::from(second.0),
            value2: u32::from(second.1),
            ..self.update_push(rect)
        };
        self.dispatch_update(rec, slot, depth_stencil, &push);
        // The tiles outside `rect` are not the draw's: active there is whatever it was.
        self.record_flush(rec);
    }

    /// Outside rendering: copies the stencil aside for a later restore (`restore_preserved.frag`).
    pub fn record_save(&self, rec: &Recording, depth_stencil: &mut ImageRef) {
        use BufferAccess::{FragmentRead, TransferWrite};
        let saved = self.saved.handle;
        // The last restore (an earlier frame's) read what this copy overwrites.
        rec.declare_buffers(&[(saved, TransferWrite)]);
        rec.copy_image_to_buffer(depth_stencil, vk::ImageAspectFlags::STENCIL, &self.saved);
        rec.transition(
            depth_stencil,
            ImageAccess::DepthStencilAttachment,
            Contents::Keep,
        );
        // The restore reads it inside the lighting's rendering, where no barrier may go.
        rec.declare_buffers(&[(saved, FragmentRead)]);
    }

    /// The buffers light shaders write, with atomics: the touched marks and the statistics. A
    /// split of the lighting's rendering hands them from the draws before to those after.
    pub fn fragment_written(&self) -> [vk::Buffer; 2] {
        [self.touched.handle, self.stats.handle]
    }

    /// The buffer light shaders read: the active tiles (a flush rewrites it).
    pub fn fragment_read(&self) -> vk::Buffer {
        self.active.handle
    }

    /// Makes the statistics visible to the host; record after the last lighting draw.
    pub fn record_stats_readable(&self, rec: &Recording) {
        rec.host_readable(vk::PipelineStageFlags2::FRAGMENT_SHADER);
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
