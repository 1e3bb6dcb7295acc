//! The barriers a step's declared accesses derive, recorded: images ([`Recording::declare`]),
//! buffers ([`Recording::declare_buffers`], against each buffer's last declared uses, which the
//! context keeps across command buffers), an upload's levelled images, the host's reads after a
//! fence, and the broad memory barrier the light passes' split keeps for an engine's hooks. The
//! derivations themselves are pure and live in [`crate::gpu::access`]; no barrier is written
//! anywhere else.

use crate::gpu::access::{
    hand_over, image_barrier, subresource_range, BufferAccess, Contents, ImageAccess, ImageRef,
    ImageState, LeaveOut, Upload, Use,
};
use crate::gpu::encoder::recording::Recording;
use ash::vk;

impl Recording<'_> {
    /// Declares how a step uses `uses`' images next and records the one barrier command that
    /// takes each from its current state there: a pass declares its accesses, then draws.
    pub(crate) fn declare(&self, uses: &mut [Use<'_>]) {
        if uses.is_empty() {
            return;
        }
        debug_assert!(
            (1..uses.len()).all(|i| uses[..i].iter().all(|u| u.0.image != uses[i].0.image)),
            "an image declared twice in one step's accesses"
        );
        let barriers: Vec<_> = uses
            .iter()
            .map(|(image, next, contents)| image_barrier(image, *next, *contents))
            .collect();
        let dependency = vk::DependencyInfo::default().image_memory_barriers(&barriers);
        // SAFETY: the recording is outside rendering (`outside` checks it in debug builds;
        // accesses are declared between passes: the renderer's frame, `submit_once`'s, or an
        // engine's under `record`'s # Safety). Each image is live with every aspect of its format
        // named; its `state` is true when the commands run (histencil's bookkeeping, or the
        // engine's promise for its `ImageRef`s), so each old layout is right; an image declared
        // twice in one call would take its second barrier from a state the first replaced, which
        // no caller does. `dependency` lives until the call returns.
        unsafe { self.barrier(&dependency) };
        for (image, next, _) in uses.iter_mut() {
            image.state = ImageState::after(*next);
        }
    }

    /// [`Self::declare`] for one image.
    pub(crate) fn transition(&self, image: &mut ImageRef, next: ImageAccess, contents: Contents) {
        self.declare(&mut [(image, next, contents)]);
    }

    /// A global memory barrier: every write recorded before is visible to every access after.
    ///
    /// The depth-id and tiled passes hand buffers and attachments between fragment shaders,
    /// attachments and compute; one broad barrier between those phases is simpler to get right
    /// than a precise one per hand-over (and the light passes' split uses it where an engine's
    /// hooks bind resources histencil cannot see). The hi-stencil emulation's bookkeeping
    /// (reset, flush, save) and the light passes' own split use
    /// [`Recording::declare_buffers`] instead: their hand-overs are few and known, and a full
    /// wait there would count against the console.
    ///
    /// The stages are the ones histencil records (named rather than `ALL_COMMANDS`, which the
    /// best-practices layer flags); synchronisation validation in every test run would report a
    /// hazard through a stage missing here.
    pub(crate) fn memory_barrier(&self) {
        let stages = recorded_stages();
        let write = vk::AccessFlags2::MEMORY_WRITE;
        let read_write = vk::AccessFlags2::MEMORY_READ | vk::AccessFlags2::MEMORY_WRITE;
        self.memory_dependency((stages, write), (stages, read_write));
    }

    /// A global memory barrier from `src`'s writes to `dst`'s accesses, each a (stages,
    /// accesses) pair of the graphics, compute and transfer stages (which the recording's queue
    /// family supports: `Recording::new`'s # Safety), each access one its stages perform.
    pub(crate) fn memory_dependency(
        &self,
        src: (vk::PipelineStageFlags2, vk::AccessFlags2),
        dst: (vk::PipelineStageFlags2, vk::AccessFlags2),
    ) {
        let supported = recorded_stages();
        debug_assert!(
            supported.contains(src.0) && supported.contains(dst.0),
            "a memory dependency on stages histencil does not record in"
        );
        let barrier = [vk::MemoryBarrier2::default()
            .src_stage_mask(src.0)
            .src_access_mask(src.1)
            .dst_stage_mask(dst.0)
            .dst_access_mask(dst.1)];
        let dependency = vk::DependencyInfo::default().memory_barriers(&barrier);
        // SAFETY: outside rendering (`outside` checks it in debug builds; the callers barrier
        // between their compute, transfer and render phases); the stages are ones the queue
        // family supports, as said above, and `dependency` lives until the call returns.
        unsafe { self.barrier(&dependency) };
    }
}

impl Recording<'_> {
    /// Makes the writes of `stage` so far (copies, or shader storage writes) visible to host reads
    /// after the fence.
    pub(crate) fn host_readable(&self, stage: vk::PipelineStageFlags2) {
        let writes = if stage == vk::PipelineStageFlags2::COPY {
            vk::AccessFlags2::TRANSFER_WRITE
        } else {
            vk::AccessFlags2::SHADER_STORAGE_WRITE
        };
        let barrier = [vk::MemoryBarrier2::default()
            .src_stage_mask(stage)
            .src_access_mask(writes)
            .dst_stage_mask(vk::PipelineStageFlags2::HOST)
            .dst_access_mask(vk::AccessFlags2::HOST_READ)];
        // SAFETY: the recording's command buffer is recording outside rendering; `barrier`
        // lives until the call returns and names only stages and accesses the queue family
        // supports.
        unsafe { self.barrier(&vk::DependencyInfo::default().memory_barriers(&barrier)) };
    }
}

impl Recording<'_> {
    /// The barrier of an upload's phase `next` for `images`, colour images with their mip level
    /// counts (uploads have levels, which [`ImageRef`] does not), in one command. The reads
    /// after it come in later submissions (creation waits for its upload), which submission
    /// order orders after it.
    pub(crate) fn declare_upload(&self, images: &[(vk::Image, u32)], next: Upload) {
        use vk::{AccessFlags2 as A, ImageLayout as L, PipelineStageFlags2 as S};
        let ((src_stage, src_access, old), (dst_stage, dst_access, new)) = match next {
            Upload::Copies => (
                (S::NONE, A::NONE, L::UNDEFINED),
                (S::COPY, A::TRANSFER_WRITE, L::TRANSFER_DST_OPTIMAL),
            ),
            Upload::Reads => (
                (S::COPY, A::TRANSFER_WRITE, L::TRANSFER_DST_OPTIMAL),
                (
                    S::FRAGMENT_SHADER,
                    A::SHADER_SAMPLED_READ,
                    L::SHADER_READ_ONLY_OPTIMAL,
                ),
            ),
        };
        let barriers: Vec<_> = images
            .iter()
            .map(|&(image, levels)| {
                vk::ImageMemoryBarrier2::default()
                    .src_stage_mask(src_stage)
                    .src_access_mask(src_access)
                    .dst_stage_mask(dst_stage)
                    .dst_access_mask(dst_access)
                    .old_layout(old)
                    .new_layout(new)
                    .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                    .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                    .image(image)
                    .subresource_range(
                        subresource_range(vk::ImageAspectFlags::COLOR).level_count(levels),
                    )
            })
            .collect();
        // After the copies, the buffers they wrote too.
        let buffer_reads: &[_] = match next {
            Upload::Copies => &[],
            Upload::Reads => &[vk::MemoryBarrier2::default()
                .src_stage_mask(S::COPY)
                .src_access_mask(A::TRANSFER_WRITE)
                .dst_stage_mask(
                    S::VERTEX_INPUT | S::VERTEX_SHADER | S::FRAGMENT_SHADER | S::COMPUTE_SHADER,
                )
                .dst_access_mask(
                    A::VERTEX_ATTRIBUTE_READ
                        | A::INDEX_READ
                        | A::UNIFORM_READ
                        | A::SHADER_STORAGE_READ,
                )],
        };
        if barriers.is_empty() && buffer_reads.is_empty() {
            return;
        }
        let dependency = vk::DependencyInfo::default()
            .image_memory_barriers(&barriers)
            .memory_barriers(buffer_reads);
        // SAFETY: outside rendering (`submit_once`'s recording, checked by `outside` in debug
        // builds); each image is a live colour image of the caller's with `levels` levels, in
        // the layout `old` names (nothing recorded into it but this upload's own commands);
        // the stages are a graphics and compute queue's; `dependency` lives until the call
        // returns.
        unsafe { self.barrier(&dependency) };
    }
}

/// The stages histencil records work in (named rather than `ALL_COMMANDS`, which the
/// best-practices layer flags), all supported by the graphics and compute queue family it
/// records on: what a full barrier waits for, and what a memory dependency may name.
fn recorded_stages() -> vk::PipelineStageFlags2 {
    use vk::PipelineStageFlags2 as S;
    S::DRAW_INDIRECT
        | S::VERTEX_INPUT
        | S::VERTEX_SHADER
        | S::EARLY_FRAGMENT_TESTS
        | S::FRAGMENT_SHADER
        | S::LATE_FRAGMENT_TESTS
        | S::COLOR_ATTACHMENT_OUTPUT
        | S::COMPUTE_SHADER
        | S::ALL_TRANSFER
}

impl Recording<'_> {
    /// Declares how the step being recorded uses `uses`' buffers next, and records the one
    /// barrier command that hands each over from its last declared uses (in recording order,
    /// across command buffers: `access::BufferUse`); nothing where none is needed (a read after a
    /// read, or a read the last write was already made visible to). Outside rendering.
    ///
    /// The hazard check holds the declarations to the shaders: until the innermost open label
    /// closes, its draws and dispatches may write the buffers declared with a write access,
    /// and any other buffer a shader writes is an error (`HISTENCIL-UNDECLARED-WRITE`, naming
    /// the pass, set and binding), for no barrier could be derived for it.
    pub(crate) fn declare_buffers(&self, uses: &[(vk::Buffer, BufferAccess)]) {
        self.declare_buffers_leaving_out(uses, None);
    }

    /// [`Self::declare_buffers`] less one of its parts, for a hazard test to prove the check
    /// finds it missing (`crate::gpu::device::hazards::HandOver`): the barrier (the uses still
    /// recorded as the buffers' last), or the declaration the check holds shaders to (the
    /// barrier still recorded). `None` leaves out nothing.
    pub(crate) fn declare_buffers_leaving_out(
        &self,
        uses: &[(vk::Buffer, BufferAccess)],
        leave_out: Option<LeaveOut>,
    ) {
        if let (Some(h), false) = (self.hazards(), leave_out == Some(LeaveOut::Declaration)) {
            let writes: Vec<vk::Buffer> = uses
                .iter()
                .filter(|(_, a)| a.writes())
                .map(|(b, _)| *b)
                .collect();
            h.declare_writes(self.any(), &writes);
        }
        let barriers: Vec<vk::BufferMemoryBarrier2> = {
            let mut last = self
                .ctx()
                .buffer_uses
                .lock()
                .unwrap_or_else(|e| e.into_inner());
            uses.iter()
                .filter_map(|&(buffer, access)| {
                    let state = last.entry(buffer).or_default();
                    let (barrier, next) = hand_over(*state, access);
                    *state = next;
                    barrier.map(|(src, dst)| {
                        vk::BufferMemoryBarrier2::default()
                            .src_stage_mask(src.0)
                            .src_access_mask(src.1)
                            .dst_stage_mask(dst.0)
                            .dst_access_mask(dst.1)
                            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                            .buffer(buffer)
                            .offset(0)
                            .size(vk::WHOLE_SIZE)
                    })
                })
                .collect()
        };
        if barriers.is_empty() || leave_out == Some(LeaveOut::Barrier) {
            return;
        }
        let dependency = vk::DependencyInfo::default().buffer_memory_barriers(&barriers);
        // SAFETY: outside rendering (`barrier` checks it in debug builds); the buffers are live
        // (the callers' own), and each barrier names only stages and accesses of the buffer
        // access table, which the recording's queue family supports.
        unsafe { self.barrier(&dependency) };
    }
}
