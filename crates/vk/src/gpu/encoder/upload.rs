//! Work done once at creation: a command buffer recorded, submitted and waited for
//! ([`submit_once`]), and the uploads that use it. Vertex, index and texture data goes through
//! one staging buffer into device-local memory ([`upload`]); the staging memory is freed
//! before the function returns.

use crate::gpu::access::Upload;
use crate::gpu::device::context::Context;
use crate::gpu::device::error::{Result, VkCall};
use crate::gpu::device::resources::Buffer;
use crate::gpu::encoder::recording::Recording;
use ash::vk;
use gpu_allocator::MemoryLocation;

/// Records `record` into a fresh command buffer named after `name`, submits it and waits for
/// it. The pool and the fence are freed whatever happens.
pub(crate) fn submit_once(
    ctx: &Context,
    name: &str,
    record: impl FnOnce(&Recording),
) -> Result<()> {
    let d = &ctx.device;
    let pool_info = vk::CommandPoolCreateInfo::default().queue_family_index(ctx.queue_family);
    // SAFETY: `pool_info` lives until the call returns and names the context's queue family.
    let command_pool = unsafe { d.create_command_pool(&pool_info, None) };
    // SAFETY: a default (unsignalled) fence; the info lives until the call returns.
    let fence = unsafe { d.create_fence(&vk::FenceCreateInfo::default(), None) };
    // Set once the submit succeeded and until its wait did: `cmd` may still be pending.
    let mut pending = false;
    let done = (|| -> Result<()> {
        let command_pool = command_pool.call("vkCreateCommandPool")?;
        ctx.name(command_pool, &format!("{name}-command-pool"));
        let fence = fence.call("vkCreateFence")?;
        ctx.name(fence, &format!("{name}-fence"));
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(command_pool)
            .command_buffer_count(1);
        // SAFETY: `command_pool` was just made and is used by this thread alone (its external
        // synchronisation); `alloc` lives until the call returns.
        let cmd =
            unsafe { d.allocate_command_buffers(&alloc) }.call("vkAllocateCommandBuffers")?[0];
        ctx.name(cmd, &format!("{name}-commands"));
        let begin = vk::CommandBufferBeginInfo::default()
            .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
        // SAFETY: `cmd` was just allocated, so it is in the initial state; `begin` outlives it.
        unsafe { d.begin_command_buffer(cmd, &begin) }.call("vkBeginCommandBuffer")?;
        if let Some(hazards) = ctx.hazards.get() {
            hazards.begun(cmd);
        }
        // SAFETY: `cmd` was just begun on this context's device, from a pool of its queue
        // family (graphics and compute), outside rendering; only `record` records into it.
        let rec = unsafe { Recording::new(ctx, cmd) };
        rec.step(name, record);
        rec.finish();
        // SAFETY: `cmd` is recording, outside any rendering (`record` ends what it begins), and
        // its labels are closed. The submit names only `cmd` and the unsignalled, unused
        // `fence`; `cmds` and `submit` live until it returns. `Context::submit` holds the
        // queue's lock against histencil's other submits, and `Context::from_raw`'s # Safety
        // keeps a lent device's other users off.
        unsafe {
            d.end_command_buffer(cmd).call("vkEndCommandBuffer")?;
            let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
            let submit = vk::SubmitInfo2::default().command_buffer_infos(&cmds);
            ctx.submit(&[submit], fence).call("vkQueueSubmit2")?;
            pending = true;
            // Creation waits for its own one-off work, as buffer creation does; frames never
            // come through here.
            ctx.step("waiting on the GPU");
            d.wait_for_fences(
                &[fence],
                true,
                crate::gpu::device::context::FENCE_TIMEOUT_NS,
            )
            .call("vkWaitForFences")?;
            if let Some(hazards) = ctx.hazards.get() {
                hazards.waited(fence);
            }
            pending = false;
            Ok(())
        }
    })();
    if pending {
        // The wait failed (a timeout, a lost device) with `cmd` submitted: wait for the whole
        // device before freeing what `cmd` and the caller's buffers may still be used by (on a
        // lost device this returns at once, and nothing runs any more).
        let _ = ctx.wait_idle();
    }
    // SAFETY: the fence and the pool (freeing `cmd` with it) were made above and are used by
    // nothing else, and the GPU is done with them: the fence wait succeeded, or nothing was
    // submitted, or the device went idle (or was lost) just above.
    unsafe {
        if let Ok(fence) = fence {
            d.destroy_fence(fence, None);
        }
        if let Ok(command_pool) = command_pool {
            d.destroy_command_pool(command_pool, None);
        }
    }
    done
}

/// Bytes for a device-local buffer.
pub(crate) struct BufferUpload<'a> {
    pub dst: vk::Buffer,
    pub bytes: &'a [u8],
}

/// Every mip level of a colour image, tightly packed RGBA8 (4 bytes a texel), level 0 first.
/// The image is in `UNDEFINED` layout before and `SHADER_READ_ONLY_OPTIMAL` after, visible to
/// fragment shaders.
pub(crate) struct ImageUpload<'a> {
    pub dst: vk::Image,
    pub levels: &'a [(vk::Extent2D, Vec<u8>)],
}

/// Copies every upload through one staging buffer named `{name}-staging`, in one submission.
/// Afterwards buffers are readable as vertices, indices, uniforms and storage by any later
/// submission, and images are sampled by fragment shaders.
pub(crate) fn upload(
    ctx: &Context,
    name: &str,
    buffers: &[BufferUpload],
    images: &[ImageUpload],
) -> Result<()> {
    // Offsets: every chunk starts 16-byte aligned (image copies need a multiple of the texel
    // size, 4; buffer copies nothing).
    let align = |x: u64| x.next_multiple_of(16);
    let chunks = buffers.iter().map(|b| b.bytes).chain(
        images
            .iter()
            .flat_map(|i| i.levels.iter().map(|(_, l)| l.as_slice())),
    );
    let mut offsets = Vec::new();
    let mut total = 0u64;
    for chunk in chunks.clone() {
        offsets.push(total);
        total = align(total + chunk.len() as u64);
    }
    if total == 0 {
        return Ok(());
    }
    let mut staging = Buffer::new(
        ctx,
        &format!("{name}-staging"),
        total,
        vk::BufferUsageFlags::TRANSFER_SRC,
        MemoryLocation::CpuToGpu,
    )?;
    // Straight into the mapped staging memory: no second copy of every byte on the heap.
    for (chunk, &offset) in chunks.zip(&offsets) {
        staging.write_at(offset as usize, chunk);
    }
    let src = staging.handle;
    let done = submit_once(ctx, name, |rec| {
        let mut offsets = offsets.iter();
        for b in buffers {
            let offset = *offsets.next().expect("one offset per chunk");
            if !b.bytes.is_empty() {
                let region = vk::BufferCopy::default()
                    .src_offset(offset)
                    .size(b.bytes.len() as u64);
                // SAFETY: `rec` is `submit_once`'s, recording outside rendering. `src` (the
                // staging buffer, TRANSFER_SRC) holds this chunk at `offset`, and `b.dst` is a
                // live buffer the caller made with TRANSFER_DST of at least `bytes.len()`, not
                // yet used (the upload comes before anything reads it).
                unsafe { rec.copy_buffer(src, b.dst, &[region]) };
            }
        }
        let levels: Vec<_> = images
            .iter()
            .map(|i| (i.dst, i.levels.len() as u32))
            .collect();
        rec.declare_upload(&levels, Upload::Copies);
        for image in images {
            let regions: Vec<_> = image
                .levels
                .iter()
                .enumerate()
                .map(|(level, (extent, _))| {
                    let offset = *offsets.next().expect("one offset per chunk");
                    vk::BufferImageCopy::default()
                        .buffer_offset(offset)
                        .image_subresource(
                            vk::ImageSubresourceLayers::default()
                                .aspect_mask(vk::ImageAspectFlags::COLOR)
                                .mip_level(level as u32)
                                .layer_count(1),
                        )
                        .image_extent(vk::Extent3D {
                            width: extent.width,
                            height: extent.height,
                            depth: 1,
                        })
                })
                .collect();
            // SAFETY: the image (the caller's, with TRANSFER_DST usage and these levels) is in
            // TRANSFER_DST_OPTIMAL (the barrier above), and the staging buffer holds each
            // level's tightly packed RGBA8 texels at its `offset`, 16-byte aligned and so a
            // multiple of the texel size.
            unsafe { rec.copy_buffer_to_image(src, image.dst, &regions) };
        }
        // Later submissions' reads of the buffers and images wait for the copies through this
        // barrier (submission order carries the execution dependency on).
        rec.declare_upload(&levels, Upload::Reads);
    });
    staging.destroy(ctx);
    done
}
