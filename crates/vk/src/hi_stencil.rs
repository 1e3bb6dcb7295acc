//! Console hi-stencil, emulated on the GPU exactly as `histencil_model::TileSurface` specifies,
//! so the CPU simulator is an oracle for it.
//!
//! The coarse surface is one word per [`HI_STENCIL_TILE`]-pixel tile, in two buffers: `pending`
//! (what write-enabled draws evaluated) and `active` (what testing draws see). A hi-stencil
//! write is a *split pass*: the draw marks the tiles it rasterises and lists each once
//! (`hi_stencil_touch.frag`), rendering ends, the stencil is copied out and
//! `hi_stencil_update.comp`, dispatched indirectly over that list, re-evaluates the listed
//! tiles into `pending`: a small light's write costs its own tiles, not the screen's. A flush, or the next write while one is unflushed (the latest
//! point hardware could retire it), copies `pending` to `active`. Testing draws reject
//! fragments of failing tiles in the light shader (`LIGHT_DRAW_HI_STENCIL_TEST`).
//!
//! Statistics are optional because counting needs extra draws and atomics: with them on, each
//! testing draw is preceded by `hi_stencil_count.frag` over the same geometry, and light shaders
//! count the fragments they shade.

use crate::access::{memory_barrier, transition, Contents, ImageAccess, ImageRef};
use crate::compute::ComputePipeline;
use crate::context::Context;
use crate::descriptors::{create_storage_buffer_set, HI_STENCIL_UPDATE_SET};
use crate::error::Result;
use crate::readback::{copy_image_to_buffer, host_readable};
use crate::resources::Buffer;
use crate::shader_consts::HI_STENCIL_TILE;
use crate::shaders;
use crate::state::compare_op;
use ash::vk;
use gpu_allocator::MemoryLocation;
use histencil_model::{HiStencilState, TileStats};

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
}

/// Words of the statistics buffer (`HiStencilStats` in include/hi_stencil.glsl).
const STATS_WORDS: usize = 4;

/// The tile surface, its scratch buffers and the update pipeline.
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
    stencil_copy: Buffer,
    saved: Buffer,
    update: ComputePipeline,
    pool: vk::DescriptorPool,
    set: vk::DescriptorSet,
    /// A write since the last flush has not become active yet (see the module doc).
    unflushed: bool,
}

/// The touched list's header: the update's dispatch arguments and the tile count.
const LIST_HEADER_BYTES: u64 = 16;

/// Bytes of a buffer holding one stencil byte per pixel, rounded up to whole words.
fn stencil_bytes(extent: vk::Extent2D) -> u64 {
    (u64::from(extent.width) * u64::from(extent.height)).next_multiple_of(4)
}

impl HiStencilSurface {
    pub fn new(ctx: &Context, extent: vk::Extent2D) -> Result<Self> {
        let tiles_x = extent.width.div_ceil(HI_STENCIL_TILE);
        let tiles_y = extent.height.div_ceil(HI_STENCIL_TILE);
        let tile_bytes = u64::from(tiles_x * tiles_y) * 4;
        use vk::BufferUsageFlags as U;
        let gpu = |name, size, usage| Buffer::new(ctx, name, size, usage, MemoryLocation::GpuOnly);
        let storage = U::STORAGE_BUFFER | U::TRANSFER_DST;
        let mut made: Vec<Buffer> = Vec::new();
        let result = (|| -> Result<()> {
            made.push(gpu("hi-stencil-active", tile_bytes, storage)?);
            made.push(gpu(
                "hi-stencil-pending",
                tile_bytes,
                storage | U::TRANSFER_SRC,
            )?);
            made.push(gpu("hi-stencil-touched", tile_bytes, storage)?);
            made.push(gpu(
                "hi-stencil-touched-list",
                LIST_HEADER_BYTES + tile_bytes,
                storage | U::INDIRECT_BUFFER,
            )?);
            made.push(Buffer::new(
                ctx,
                "hi-stencil-stats",
                (STATS_WORDS * 4) as u64,
                storage,
                MemoryLocation::GpuToCpu,
            )?);
            made.push(gpu("stencil-copy", stencil_bytes(extent), storage)?);
            made.push(gpu("saved-stencil", stencil_bytes(extent), storage)?);
            Ok(())
        })();
        if let Err(e) = result {
            for mut b in made {
                b.destroy(ctx);
            }
            return Err(e);
        }
        // In the order made: active, pending, touched, touched list, stats, stencil copy, saved.
        let handle = |i: usize| made[i].handle;
        let update_set = [handle(5), handle(3), handle(1)];
        let update = ComputePipeline::new(
            ctx,
            "hi-stencil-update",
            HI_STENCIL_UPDATE_SET,
            ("hi-stencil-update-comp", shaders::HI_STENCIL_UPDATE_COMP),
            std::mem::size_of::<UpdatePush>() as u32,
        );
        let update = update.and_then(|mut update| {
            match create_storage_buffer_set(
                ctx,
                "hi-stencil-update",
                update.set_layout,
                &update_set,
            ) {
                Ok(pool_set) => Ok((update, pool_set)),
                Err(e) => {
                    update.destroy(ctx);
                    Err(e)
                }
            }
        });
        let (update, (pool, set)) = match update {
            Ok(made) => made,
            Err(e) => {
                for mut b in made {
                    b.destroy(ctx);
                }
                return Err(e);
            }
        };
        let Ok([active, pending, touched, touched_list, stats, stencil_copy, saved]) =
            <[Buffer; 7]>::try_from(made)
        else {
            unreachable!("seven buffers were made")
        };
        Ok(Self {
            extent,
            tiles_x,
            active,
            pending,
            touched,
            touched_list,
            stats,
            stencil_copy,
            saved,
            update,
            pool,
            set,
            unflushed: false,
        })
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
            self.clear_list(ctx, cmd);
        }
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

    /// Outside rendering, after a write draw listed the tiles it touched: retires an
    /// unflushed earlier write, then evaluates `hi` on the listed tiles into pending state and
    /// empties the list for the next write.
    pub fn record_update(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        depth_stencil: &mut ImageRef,
        hi: &HiStencilState,
    ) {
        if self.unflushed {
            self.record_flush(ctx, cmd);
        }
        self.copy_stencil(ctx, cmd, depth_stencil, CopyTo::Scratch);
        let push = UpdatePush {
            compare: compare_op(hi.compare).as_raw() as u32,
            reference: u32::from(hi.reference),
            read_mask: u32::from(hi.read_mask.unwrap_or(0xFF)),
            width: self.extent.width,
            height: self.extent.height,
            tiles_x: self.tiles_x,
        };
        self.update
            .bind(ctx, cmd, self.set, bytemuck::bytes_of(&push));
        unsafe {
            ctx.device
                .cmd_dispatch_indirect(cmd, self.touched_list.handle, 0)
        };
        // The list's counts are read (as dispatch arguments too) before they are zeroed.
        memory_barrier(ctx, cmd);
        self.clear_list(ctx, cmd);
        memory_barrier(ctx, cmd);
        self.unflushed = true;
    }

    /// Outside rendering: copies the stencil aside for a later restore (`restore_preserved.frag`).
    pub fn record_save(&self, ctx: &Context, cmd: vk::CommandBuffer, depth_stencil: &mut ImageRef) {
        self.copy_stencil(ctx, cmd, depth_stencil, CopyTo::Saved);
    }

    fn copy_stencil(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        depth_stencil: &mut ImageRef,
        to: CopyTo,
    ) {
        let buffer = match to {
            CopyTo::Scratch => &self.stencil_copy,
            CopyTo::Saved => &self.saved,
        };
        copy_image_to_buffer(
            ctx,
            cmd,
            depth_stencil,
            vk::ImageAspectFlags::STENCIL,
            buffer,
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

    pub fn destroy(&mut self, ctx: &Context) {
        self.update.destroy(ctx);
        unsafe { ctx.device.destroy_descriptor_pool(self.pool, None) };
        for b in [
            &mut self.active,
            &mut self.pending,
            &mut self.touched,
            &mut self.touched_list,
            &mut self.stats,
            &mut self.stencil_copy,
            &mut self.saved,
        ] {
            b.destroy(ctx);
        }
    }
}

#[derive(Clone, Copy)]
enum CopyTo {
    /// For the tile update.
    Scratch,
    /// For restoring preserved bits after lighting.
    Saved,
}
