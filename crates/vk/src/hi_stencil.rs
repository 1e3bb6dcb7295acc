//! Console hi-stencil, emulated on the GPU exactly as `histencil_model::TileSurface` specifies,
//! so the CPU simulator is an oracle for it.
//!
//! The coarse surface is one word per [`HI_STENCIL_TILE`]-pixel tile, in two buffers: `pending`
//! (what write-enabled draws evaluated) and `active` (what testing draws see). A hi-stencil
//! write is a *split pass*: the write draw itself is the platform's (the same stencil-only
//! pipeline as native), rendering ends, and the emulator learns which tiles it rasterised by
//! drawing the same volume with the same faces once more, without a fragment shader, into a
//! depth-only *touch image* whose viewport pins every fragment's depth to a marker unique to
//! the write (a fragment shader with a side effect would run for every covered pixel, which a
//! CPU rasteriser pays for many times over a depth-only draw). `hi_stencil_update.comp` then
//! looks at the tiles of the light's screen rectangle (`PlannedLight::screen_rect`) and
//! re-evaluates into `pending` those holding the marker, reading the stencil where it is
//! through a stencil-aspect view: a small light's write costs its own tiles, not the screen's,
//! and nothing is copied. Two writes need no touch draw ([`plan_touches`]): a full-screen one
//! touches every tile, and one that draws the same volume with the same faces as its light's
//! previous write touches that write's tiles, whose marker is still in the touch image. A
//! flush, or the next write while one is unflushed (the latest point hardware could retire
//! it), copies `pending` to `active`. Testing draws reject fragments of failing tiles in the
//! light shader (`LIGHT_DRAW_HI_STENCIL_TEST`).
//!
//! Statistics are optional because counting needs extra draws and atomics: with them on, each
//! testing draw is preceded by `hi_stencil_count.frag` over the same geometry, and light shaders
//! count the fragments they shade.

use crate::access::{access_info, memory_barrier, transition, Contents, ImageAccess, ImageRef};
use crate::compute::ComputePipeline;
use crate::context::Context;
use crate::descriptors::{sets_of, write_storage_buffers, HI_STENCIL_UPDATE_SET};
use crate::error::{Result, VkCall};
use crate::passes::{attachment, Load};
use crate::readback::{copy_image_to_buffer, host_readable};
use crate::resources::{Buffer, Image};
use crate::shader_consts::{HI_STENCIL_TILE, HI_STENCIL_UPDATE_GROUP};
use crate::shaders;
use crate::state::compare_op;
use crate::teardown::{build, Destroy};
use ash::vk;
use gpu_allocator::MemoryLocation;
use histencil_model::{CullMode, FramePlan, Geometry, HiStencilState, NdcRect, Step, TileStats};

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
}

/// The touch image's format: depth-only, the one every Vulkan device renders to and samples.
pub const TOUCH_FORMAT: vk::Format = vk::Format::D16_UNORM;

/// Markers are codes of the 16-bit touch image four apart. Vulkan lets a device store a depth
/// as either neighbouring code of its exact value, so marker `m` is stored as `m - 1`, `m` or
/// `m + 1`, and the update takes a code within one of `m` as `m`'s: no two markers, nor a marker
/// and the cleared image's 0, can then be taken for each other.
const MARKER_STEP: u32 = 4;
const MAX_MARKER: u32 = (u16::MAX as u32 - 1) / MARKER_STEP * MARKER_STEP;

/// The marker after `marker` (0: none yet this frame), and whether the touch image must be
/// cleared whole first: before the frame's first marker, and when they run out and start again.
fn next_marker(marker: u32) -> (u32, bool) {
    if marker == 0 || marker >= MAX_MARKER {
        (MARKER_STEP, true)
    } else {
        (marker + MARKER_STEP, false)
    }
}

/// Which tiles a hi-stencil write touched, for its update.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TouchedTiles {
    /// Those its volume rasterises, drawn again into the touch image: a light volume's.
    Drawn,
    /// Those the light's previous write touched: the same volume with the same faces
    /// rasterises the same pixels whatever its depth and stencil tests, so its marker serves
    /// (the talk's mask pass per BRDF of one light).
    Kept,
    /// Every tile: a full-screen draw rasterises every pixel (a console's mask pass has no
    /// fragment shader either).
    All,
}

/// Per step of `plan`, how its hi-stencil write learns its tiles (`None` where the step writes
/// none): a full-screen write touches all; a volume write draws its own unless the light's
/// previous write drew the same volume with the same faces, whose tiles it keeps.
pub fn plan_touches(plan: &FramePlan) -> Vec<Option<TouchedTiles>> {
    let mut touches = vec![None; plan.steps.len()];
    // The light and culled faces of the last volume write since the last full-screen one.
    let mut last: Option<(usize, CullMode)> = None;
    for (index, step) in plan.steps.iter().enumerate() {
        let Step::Pass { light, pass } = step else {
            continue;
        };
        if !pass.state.writes_hi_stencil() {
            continue;
        }
        touches[index] = Some(match pass.geometry {
            Geometry::FullScreen => {
                last = None;
                TouchedTiles::All
            }
            Geometry::Volume => {
                let raster = (*light, pass.state.cull);
                let previous = last.replace(raster);
                if previous == Some(raster) {
                    TouchedTiles::Kept
                } else {
                    TouchedTiles::Drawn
                }
            }
        });
    }
    touches
}

/// The tiles a hi-stencil write touched: how its update learns them, and the rectangle they lie
/// in (the light's on screen, or the frame).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WriteTiles {
    pub touched: TouchedTiles,
    pub rect: TileRect,
}

/// A rectangle of tiles: the first tile's column and row, and the size in tiles.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TileRect {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

impl TileRect {
    /// Every tile of a frame of `extent`.
    pub fn frame(extent: vk::Extent2D) -> Self {
        Self {
            width: extent.width.div_ceil(HI_STENCIL_TILE),
            height: extent.height.div_ceil(HI_STENCIL_TILE),
            ..Self::default()
        }
    }

    pub fn is_empty(self) -> bool {
        self.width == 0 || self.height == 0
    }

    /// Its pixels in a frame of `extent`.
    pub fn pixels(self, extent: vk::Extent2D) -> vk::Rect2D {
        let (x, y) = (self.x * HI_STENCIL_TILE, self.y * HI_STENCIL_TILE);
        let width = (self.width * HI_STENCIL_TILE).min(extent.width.saturating_sub(x));
        let height = (self.height * HI_STENCIL_TILE).min(extent.height.saturating_sub(y));
        vk::Rect2D {
            offset: vk::Offset2D {
                x: x as i32,
                y: y as i32,
            },
            extent: vk::Extent2D { width, height },
        }
    }
}

/// The tiles of a frame of `extent` that hold every pixel inside `ndc` (the whole frame for
/// `None`), with a pixel to spare on each side for the GPU's single-precision transforms.
pub fn tile_rect(extent: vk::Extent2D, ndc: Option<NdcRect>) -> TileRect {
    let frame = TileRect::frame(extent);
    let Some(ndc) = ndc.filter(|r| r.min.iter().chain(&r.max).all(|v| v.is_finite())) else {
        return frame;
    };
    let size = [extent.width, extent.height].map(f64::from);
    let tiles = [frame.width, frame.height];
    let span = |axis: usize| -> (u32, u32) {
        let pixel = |v: f64| (v + 1.0) * 0.5 * size[axis];
        let (lo, hi) = (pixel(ndc.min[axis]) - 1.0, pixel(ndc.max[axis]) + 1.0);
        if !(lo < size[axis] && hi >= 0.0) {
            return (0, 0);
        }
        let tile = |p: f64| (p.max(0.0) as u32 / HI_STENCIL_TILE).min(tiles[axis] - 1);
        let (first, last) = (tile(lo), tile(hi));
        (first, last + 1 - first)
    };
    let ((x, width), (y, height)) = (span(0), span(1));
    let rect = TileRect {
        x,
        y,
        width,
        height,
    };
    if rect.is_empty() {
        TileRect::default()
    } else {
        rect
    }
}

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
    unsafe { ctx.device.update_descriptor_sets(&[write], &[]) };
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
            use vk::ImageUsageFlags as I;
            let touch_usage = I::DEPTH_STENCIL_ATTACHMENT | I::SAMPLED;
            h.touch = Image::new(ctx, "hi-stencil-touch", TOUCH_FORMAT, extent, touch_usage)?;
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

    /// The pool and every slot's update set, with the touch image and pending surface written
    /// (the stencil view is written per frame).
    fn create_sets(
        &mut self,
        ctx: &Context,
        layout: vk::DescriptorSetLayout,
        slots: u32,
    ) -> Result<()> {
        let sizes = [
            (vk::DescriptorType::STORAGE_BUFFER, 1),
            (vk::DescriptorType::SAMPLED_IMAGE, 2),
        ];
        (self.pool, self.sets) = sets_of(ctx, "hi-stencil-update-set", layout, slots, &sizes)?;
        self.views = vec![vk::ImageView::null(); slots as usize];
        for &set in &self.sets {
            write_storage_buffers(ctx, set, &[self.pending.handle]);
            write_read_only_view(ctx, set, 1, self.touch.view);
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
        memory_barrier(ctx, cmd);
        self.unflushed = false;
        // The frame's first touch draw clears the touch image whole, so no frame depends on
        // what an earlier one (recorded, perhaps never submitted) left there.
        self.marker = 0;
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

    /// Outside rendering, after a volume write draw: begins rendering into the touch image
    /// alone, over `rect` (where the write's volume lies), with a new marker as every
    /// fragment's depth, and sets the viewport and scissor. The caller draws the write's volume
    /// with the touch pipeline (`LightShader::TouchTiles`) and the write's faces, then calls
    /// [`Self::end_touch`].
    pub fn begin_touch(&mut self, ctx: &Context, cmd: vk::CommandBuffer, rect: TileRect) {
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
        transition(ctx, cmd, &mut self.touch, access, contents);
        let depth = attachment(&self.touch, self.touch.state.layout, load);
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
        unsafe {
            ctx.device.cmd_begin_rendering(cmd, &info);
            ctx.device.cmd_set_viewport(cmd, 0, &[viewport]);
            ctx.device.cmd_set_scissor(cmd, 0, &[area]);
        }
    }

    /// Ends the touch draw's rendering.
    pub fn end_touch(&self, ctx: &Context, cmd: vk::CommandBuffer) {
        unsafe { ctx.device.cmd_end_rendering(cmd) };
    }

    /// Outside rendering, after a write draw touched `tiles`, in a frame recorded into `slot`
    /// (prepared with this `depth_stencil`, [`HiStencilSurface::prepare_slot`]): retires an
    /// unflushed earlier write, then evaluates `hi` on those tiles into pending state, reading
    /// the stencil in place. Leaves the depth-stencil image attached-ready.
    pub fn record_update(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        slot: u32,
        depth_stencil: &mut ImageRef,
        hi: &HiStencilState,
        tiles: WriteTiles,
    ) {
        if self.unflushed {
            self.record_flush(ctx, cmd);
        }
        self.unflushed = true;
        let WriteTiles { touched, rect } = tiles;
        let rect_tiles = rect.width * rect.height;
        if rect.is_empty() {
            // The volume lies off screen: it rasterised nothing.
            return;
        }
        let stencil_read = ImageAccess::ComputeDepthStencilSampled;
        transition(ctx, cmd, depth_stencil, stencil_read, Contents::Keep);
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
            transition(ctx, cmd, &mut self.touch, stencil_read, contents);
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
            width: self.extent.width,
            height: self.extent.height,
            tiles_x: self.tiles_x,
            rect_x: rect.x,
            rect_y: rect.y,
            rect_width: rect.width,
            rect_tiles,
            marker,
        };
        let set = self.sets[slot as usize];
        let update = self.update.as_ref().expect("made with the surface");
        update.bind(ctx, cmd, set, bytemuck::bytes_of(&push));
        let groups = rect_tiles.div_ceil(HI_STENCIL_UPDATE_GROUP);
        unsafe { ctx.device.cmd_dispatch(cmd, groups, 1, 1) };
        let attached = ImageAccess::DepthStencilAttachment;
        transition(ctx, cmd, depth_stencil, attached, Contents::Keep);
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

    fn writes(plan: &FramePlan) -> Vec<(usize, CullMode, Geometry, TouchedTiles)> {
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

    /// A volume write draws its tiles unless the light's previous write drew the same faces,
    /// whose tiles it keeps; a full-screen write touches all.
    #[test]
    fn writes_keep_tiles_only_for_the_same_lights_same_faces() {
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
            assert!(writes.iter().any(|w| w.3 == TouchedTiles::Kept));
            for (i, &(light, cull, geometry, touch)) in writes.iter().enumerate() {
                let expected = match geometry {
                    Geometry::FullScreen => TouchedTiles::All,
                    Geometry::Volume => {
                        let previous = i.checked_sub(1).map(|p| writes[p]);
                        let same = previous
                            .is_some_and(|w| (w.0, w.1, w.2) == (light, cull, Geometry::Volume));
                        if same {
                            TouchedTiles::Kept
                        } else {
                            TouchedTiles::Drawn
                        }
                    }
                };
                assert_eq!(touch, expected, "write {i}");
            }
        }
    }

    /// Markers are 16-bit codes four apart, never within one of 0 or of 65535's overflow, each
    /// new until they run out, and the image is cleared whole exactly when a code could come
    /// round again.
    #[test]
    fn markers_are_new_even_codes_until_a_whole_clear() {
        let (mut marker, mut clears, mut count) = (0, 0, 0);
        let mut seen = std::collections::HashSet::new();
        while clears < 2 {
            let (next, clear) = next_marker(marker);
            if clear {
                clears += 1;
                seen.clear();
            }
            assert!(next > 1 && next < u32::from(u16::MAX) && next % MARKER_STEP == 0);
            assert!(seen.insert(next), "{next} came round without a clear");
            (marker, count) = (next, count + 1);
        }
        assert_eq!(count, MAX_MARKER / MARKER_STEP + 1);
    }

    fn ndc(min: [f64; 2], max: [f64; 2]) -> Option<NdcRect> {
        Some(NdcRect { min, max })
    }

    /// Tile rectangles hold every pixel of their NDC rectangle with a pixel to spare, clamp to
    /// the frame, and are empty only off screen; unknown or broken rectangles mean the frame.
    #[test]
    fn tile_rectangles_hold_their_pixels_and_clamp_to_the_frame() {
        let extent = vk::Extent2D {
            width: 100,
            height: 60,
        };
        let frame = TileRect {
            x: 0,
            y: 0,
            width: 13,
            height: 8,
        };
        assert_eq!(tile_rect(extent, None), frame);
        assert_eq!(tile_rect(extent, ndc([f64::NAN, 0.0], [1.0, 1.0])), frame);
        assert_eq!(tile_rect(extent, ndc([-5.0, -5.0], [5.0, 5.0])), frame);
        // Pixels 50..=58 across (NDC 0 to 0.16), rows 30..=33: with a pixel to spare, tiles
        // 6..=7 across and 3..=4 down.
        let r = tile_rect(extent, ndc([0.0, 0.0], [0.16, 0.1]));
        assert_eq!((r.x, r.width, r.y, r.height), (6, 2, 3, 2));
        // Exactly on a tile edge: the spare pixel reaches the tile before.
        let r = tile_rect(extent, ndc([-0.68, -1.0], [-0.6, -0.9]));
        assert_eq!((r.x, r.width, r.y, r.height), (1, 2, 0, 1));
        let off = tile_rect(extent, ndc([1.1, 0.0], [2.0, 0.5]));
        assert_eq!(off.width * off.height, 0);
        let above = tile_rect(extent, ndc([0.0, -3.0], [0.5, -1.1]));
        assert_eq!(above.width * above.height, 0);
        // In pixels, the last column and row of tiles stop at the frame's edge.
        let edge = frame.pixels(extent);
        assert_eq!((edge.offset.x, edge.offset.y), (0, 0));
        assert_eq!((edge.extent.width, edge.extent.height), (100, 60));
        let corner = TileRect {
            x: 12,
            y: 6,
            width: 1,
            height: 2,
        };
        let corner = corner.pixels(extent);
        assert_eq!((corner.offset.x, corner.offset.y), (96, 48));
        assert_eq!((corner.extent.width, corner.extent.height), (4, 12));
    }
}
