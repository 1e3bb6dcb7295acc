//! The commands a pass records between its barriers, as the encoder's methods: binds, pushes,
//! draws, dispatches, fills and copies. Each one asks for the command buffer where Vulkan
//! allows it (`inside` rendering for a draw, `outside` for a dispatch, a fill or a copy, `any`
//! for binds and pushes), so a debug build catches a draw recorded outside rendering or a
//! dispatch inside it at the call, not as a validation message about a later command; and a
//! pass writes `rec.draw(3)` instead of fetching the device and the buffer for ash.
//!
//! They are `unsafe` for what the recording cannot know: that the handles are live objects of
//! its device, and that what a draw or dispatch reads (the bound pipeline, sets, pushes, dynamic
//! state, buffers) was bound and set. Each caller's `SAFETY` says how it knows.

use crate::gpu::encoder::recording::Recording;
use ash::vk;

impl Recording<'_> {
    /// Binds `pipeline` at `point`, and `sets` from set `first` of `layout` (none when empty).
    ///
    /// # Safety
    /// `pipeline` and `layout` are live objects of this recording's device, `pipeline` is a
    /// `point` pipeline, and each set is a live set of `layout`'s set layout at its index.
    pub unsafe fn bind(
        &self,
        point: vk::PipelineBindPoint,
        pipeline: vk::Pipeline,
        layout: vk::PipelineLayout,
        sets: &[vk::DescriptorSet],
    ) {
        // SAFETY: this fn's # Safety; binding is allowed inside and outside rendering.
        unsafe {
            self.bind_pipeline(point, pipeline);
            self.bind_sets(point, layout, 0, sets);
        }
    }

    /// Binds the graphics `pipeline` and `sets` from set 0 of `layout`: how a pass starts
    /// drawing.
    ///
    /// # Safety
    /// As [`Self::bind`], for a graphics pipeline.
    pub unsafe fn bind_graphics(
        &self,
        pipeline: vk::Pipeline,
        layout: vk::PipelineLayout,
        sets: &[vk::DescriptorSet],
    ) {
        // SAFETY: this fn's # Safety.
        unsafe { self.bind(vk::PipelineBindPoint::GRAPHICS, pipeline, layout, sets) }
    }

    /// Binds `pipeline` at `point` alone, keeping the sets bound (a pipeline of the same layout).
    ///
    /// # Safety
    /// `pipeline` is a live `point` pipeline of this recording's device.
    pub unsafe fn bind_pipeline(&self, point: vk::PipelineBindPoint, pipeline: vk::Pipeline) {
        if let Some(h) = self.hazards() {
            h.bind_pipeline(self.any(), point, pipeline);
        }
        // SAFETY: this fn's # Safety; allowed inside and outside rendering.
        unsafe { self.device().cmd_bind_pipeline(self.any(), point, pipeline) }
    }

    /// Binds `sets` from set `first` of `layout`; nothing when `sets` is empty.
    ///
    /// # Safety
    /// `layout` is live, and each set is a live set of its set layout at `first` plus its index.
    pub unsafe fn bind_sets(
        &self,
        point: vk::PipelineBindPoint,
        layout: vk::PipelineLayout,
        first: u32,
        sets: &[vk::DescriptorSet],
    ) {
        if sets.is_empty() {
            return;
        }
        if let Some(h) = self.hazards() {
            h.bind_sets(self.any(), point, first, sets);
        }
        // SAFETY: this fn's # Safety; allowed inside and outside rendering.
        unsafe {
            self.device()
                .cmd_bind_descriptor_sets(self.any(), point, layout, first, sets, &[])
        }
    }

    /// Pushes `bytes` at `offset` for `stages` of `layout`.
    ///
    /// # Safety
    /// `layout` is live and has a push constant range for `stages` covering `offset` to
    /// `offset + bytes.len()`, a multiple of 4 at a multiple of 4.
    pub unsafe fn push(
        &self,
        layout: vk::PipelineLayout,
        stages: vk::ShaderStageFlags,
        offset: u32,
        bytes: &[u8],
    ) {
        debug_assert!(!bytes.is_empty() && (bytes.len() | offset as usize) & 3 == 0);
        // SAFETY: this fn's # Safety; allowed inside and outside rendering.
        unsafe {
            self.device()
                .cmd_push_constants(self.any(), layout, stages, offset, bytes)
        }
    }

    /// Draws `vertices` vertices from `first`, one instance, inside rendering.
    ///
    /// # Safety
    /// A graphics pipeline is bound with everything it reads bound and set: its sets, push
    /// constants, dynamic state, and the vertex buffers its input names, holding `first` to
    /// `first + vertices`; rendering was begun through this recording with attachments the
    /// pipeline's formats.
    pub unsafe fn draw(&self, vertices: u32, first: u32) {
        self.journal_shading(vk::PipelineBindPoint::GRAPHICS, &[]);
        // SAFETY: inside rendering (checked in debug builds); the rest is this fn's # Safety.
        unsafe { self.device().cmd_draw(self.inside(), vertices, 1, first, 0) }
    }

    /// Binds the vertex buffer (binding 0) and the u32 index buffer of a mesh and draws `count`
    /// indices, inside rendering.
    ///
    /// # Safety
    /// As [`Self::draw`]; `vertices` and `indices` are live buffers of this device made with
    /// `VERTEX_BUFFER` and `INDEX_BUFFER` usage and filled before the draw runs, and each of the
    /// first `count` u32 indices of `indices` names a vertex of `vertices`.
    pub unsafe fn draw_mesh(&self, vertices: vk::Buffer, indices: vk::Buffer, count: u32) {
        use vk::{AccessFlags2 as A, PipelineStageFlags2 as S};
        let inputs = [
            (vertices, S::VERTEX_INPUT, A::VERTEX_ATTRIBUTE_READ),
            (indices, S::VERTEX_INPUT, A::INDEX_READ),
        ];
        self.journal_shading(vk::PipelineBindPoint::GRAPHICS, &inputs);
        let (d, cmd) = (self.device(), self.inside());
        // SAFETY: inside rendering (checked in debug builds); the rest is this fn's # Safety.
        unsafe {
            d.cmd_bind_vertex_buffers(cmd, 0, &[vertices], &[0]);
            d.cmd_bind_index_buffer(cmd, indices, 0, vk::IndexType::UINT32);
            d.cmd_draw_indexed(cmd, count, 1, 0, 0, 0);
        }
    }

    /// Binds `buffer` as vertex binding 0.
    ///
    /// # Safety
    /// `buffer` is a live buffer of this device made with `VERTEX_BUFFER` usage.
    pub unsafe fn bind_vertex_buffer(&self, buffer: vk::Buffer) {
        // Journaled as read here, by the draws that follow.
        if let Some(h) = self.hazards() {
            let read = (
                vk::PipelineStageFlags2::VERTEX_INPUT,
                vk::AccessFlags2::VERTEX_ATTRIBUTE_READ,
            );
            h.read(self.any(), buffer, read);
        }
        // SAFETY: this fn's # Safety; allowed inside and outside rendering.
        unsafe {
            self.device()
                .cmd_bind_vertex_buffers(self.any(), 0, &[buffer], &[0])
        }
    }

    /// Dispatches `groups` workgroups, outside rendering.
    ///
    /// # Safety
    /// A compute pipeline is bound with its sets and push constants, and each count is within
    /// the device's `maxComputeWorkGroupCount`.
    pub unsafe fn dispatch(&self, groups: [u32; 3]) {
        let [x, y, z] = groups;
        self.journal_shading(vk::PipelineBindPoint::COMPUTE, &[]);
        // SAFETY: outside rendering (checked in debug builds); the rest is this fn's # Safety.
        unsafe { self.device().cmd_dispatch(self.outside(), x, y, z) }
    }

    /// Dispatches the workgroup counts `buffer` holds at `offset`, outside rendering.
    ///
    /// # Safety
    /// As [`Self::dispatch`]; `buffer` is live, made with `INDIRECT_BUFFER` usage, holds three
    /// u32 counts at `offset` (a multiple of 4) written and made visible to the indirect read
    /// before the dispatch runs.
    pub unsafe fn dispatch_indirect(&self, buffer: vk::Buffer, offset: u64) {
        let arguments = (
            buffer,
            vk::PipelineStageFlags2::DRAW_INDIRECT,
            vk::AccessFlags2::INDIRECT_COMMAND_READ,
        );
        self.journal_shading(vk::PipelineBindPoint::COMPUTE, &[arguments]);
        // SAFETY: outside rendering (checked in debug builds); the rest is this fn's # Safety.
        unsafe {
            self.device()
                .cmd_dispatch_indirect(self.outside(), buffer, offset)
        }
    }

    /// Fills the whole of `buffer` with the u32 `value`, outside rendering.
    ///
    /// # Safety
    /// `buffer` is live, made with `TRANSFER_DST` usage, and its earlier uses were made
    /// available to a transfer write (a barrier before this call, or none since the last wait).
    pub unsafe fn fill(&self, buffer: vk::Buffer, value: u32) {
        self.journal_transfer("fill", &[], &[buffer]);
        // SAFETY: outside rendering (checked in debug builds); the rest is this fn's # Safety.
        unsafe {
            self.device()
                .cmd_fill_buffer(self.outside(), buffer, 0, vk::WHOLE_SIZE, value)
        }
    }

    /// Writes `bytes` into `buffer` from offset 0, outside rendering.
    ///
    /// # Safety
    /// As [`Self::fill`]; `bytes` is 4 to 65536 bytes, a multiple of 4, and fits the buffer.
    pub unsafe fn update(&self, buffer: vk::Buffer, bytes: &[u8]) {
        debug_assert!(!bytes.is_empty() && bytes.len() <= 65536 && bytes.len() & 3 == 0);
        self.journal_transfer("update", &[], &[buffer]);
        // SAFETY: outside rendering (checked in debug builds); the rest is this fn's # Safety.
        unsafe {
            self.device()
                .cmd_update_buffer(self.outside(), buffer, 0, bytes)
        }
    }

    /// Copies `regions` of `src` into the colour image `dst`, in `TRANSFER_DST_OPTIMAL`,
    /// outside rendering.
    ///
    /// # Safety
    /// `src` is live with `TRANSFER_SRC` usage and holds each region's tightly packed texels at
    /// its offset (a multiple of the texel size); `dst` is a live image with `TRANSFER_DST`
    /// usage, in `TRANSFER_DST_OPTIMAL` for the regions' levels, each region inside its level.
    pub unsafe fn copy_buffer_to_image(
        &self,
        src: vk::Buffer,
        dst: vk::Image,
        regions: &[vk::BufferImageCopy],
    ) {
        let layout = vk::ImageLayout::TRANSFER_DST_OPTIMAL;
        self.journal_transfer("copy to image", &[src], &[]);
        // SAFETY: outside rendering (checked in debug builds); the rest is this fn's # Safety.
        unsafe {
            self.device()
                .cmd_copy_buffer_to_image(self.outside(), src, dst, layout, regions)
        }
    }

    /// Records `dependency` as it is: for images histencil does not track as `ImageRef`s
    /// (an upload's, before and after its copies). Tracked images go through `declare`.
    ///
    /// # Safety
    /// Every image and buffer `dependency` names is live on this device; each image barrier's
    /// old layout is the image's layout (or `UNDEFINED`, discarding it); the stages are ones
    /// the recording's queue family supports, each access one its stages perform.
    pub unsafe fn barrier(&self, dependency: &vk::DependencyInfo) {
        if let Some(h) = self.hazards() {
            h.barrier(self.any(), dependency);
        }
        // SAFETY: outside rendering (checked in debug builds); the rest is this fn's # Safety.
        unsafe {
            self.device()
                .cmd_pipeline_barrier2(self.outside(), dependency)
        }
    }

    /// Copies `regions` of `src` into `dst`, outside rendering.
    ///
    /// # Safety
    /// Both buffers are live, `src` made with `TRANSFER_SRC` and `dst` with `TRANSFER_DST`
    /// usage, the regions lie inside both and do not overlap in `dst`, and earlier writes of
    /// `src` and uses of `dst` were made available to the transfer.
    pub unsafe fn copy_buffer(&self, src: vk::Buffer, dst: vk::Buffer, regions: &[vk::BufferCopy]) {
        self.journal_transfer("copy", &[src], &[dst]);
        // SAFETY: outside rendering (checked in debug builds); the rest is this fn's # Safety.
        unsafe {
            self.device()
                .cmd_copy_buffer(self.outside(), src, dst, regions)
        }
    }

    /// Journals a draw's or dispatch's buffers for the hazard check, when it is on.
    fn journal_shading(
        &self,
        point: vk::PipelineBindPoint,
        extra: &[(vk::Buffer, vk::PipelineStageFlags2, vk::AccessFlags2)],
    ) {
        if let Some(h) = self.hazards() {
            h.shade(self.any(), point, extra);
        }
    }

    /// Journals a transfer's buffers for the hazard check, when it is on.
    pub(crate) fn journal_transfer(&self, what: &str, reads: &[vk::Buffer], writes: &[vk::Buffer]) {
        if let Some(h) = self.hazards() {
            h.transfer(self.any(), what, reads, writes);
        }
    }
}
