//! Compute pipelines over one set of storage buffers ([`ComputePipeline`]: the hi-stencil tile
//! update, the evaluators), and kernels run once and waited for ([`CaseKernel`]: the test-facing
//! evaluators of GLSL BRDFs and table lookups that hold the shader code to its Rust reference,
//! case by case).

use crate::gpu::access::BufferAccess;
use crate::gpu::device::context::Context;
use crate::gpu::device::descriptors::{
    create_pipeline_layout, create_set_layout, create_storage_buffer_set, BindingDesc,
};
use crate::gpu::device::error::Result;
use crate::gpu::device::pipelines::create_compute_pipeline;
use crate::gpu::device::resources::Buffer;
use crate::gpu::encoder::recording::Recording;
use crate::gpu::encoder::upload::submit_once;
use ash::vk;
use gpu_allocator::MemoryLocation;

/// Invocations per workgroup of every case kernel (`local_size_x` in the shaders).
const WORKGROUP: u32 = 64;

/// A compute pipeline whose only set (set 0) is a [`BindingDesc`] table of storage buffers, with
/// `push_bytes` of push constants; named `{name}-set-layout`, `{name}-pipeline-layout` and
/// `{name}-pipeline`.
pub(crate) struct ComputePipeline {
    pub set_layout: vk::DescriptorSetLayout,
    layout: vk::PipelineLayout,
    pipeline: vk::Pipeline,
}

impl ComputePipeline {
    /// Creates the three objects; on failure, destroys those already made.
    pub fn new(
        ctx: &Context,
        name: &str,
        set: &[BindingDesc],
        module: (&str, &[u8]),
        push_bytes: u32,
    ) -> Result<Self> {
        let compute = vk::ShaderStageFlags::COMPUTE;
        let set_layout = create_set_layout(ctx, &format!("{name}-set-layout"), set, compute)?;
        let mut made = Self {
            set_layout,
            layout: vk::PipelineLayout::null(),
            pipeline: vk::Pipeline::null(),
        };
        let layout_name = format!("{name}-pipeline-layout");
        let result = create_pipeline_layout(ctx, &layout_name, &[set_layout], compute, push_bytes)
            .and_then(|layout| {
                made.layout = layout;
                create_compute_pipeline(ctx, &format!("{name}-pipeline"), module, layout, &[])
            });
        match result {
            Ok(pipeline) => {
                made.pipeline = pipeline;
                Ok(made)
            }
            Err(e) => {
                made.destroy(ctx);
                Err(e)
            }
        }
    }

    /// Binds the pipeline and `set` as set 0, and pushes `push` at offset 0.
    pub fn bind(&self, rec: &Recording, set: vk::DescriptorSet, push: &[u8]) {
        // SAFETY: the recording's command buffer is recording on this device (`submit_once`'s, or a
        // lighting's under `record`'s # Safety). The pipeline and layout are live (`self`), and
        // `set` is a live set of `set_layout`. Both callers push exactly the layout's
        // `push_bytes` (4 for a case count, `size_of::<UpdatePush>()` for the tile update).
        unsafe {
            rec.bind(
                vk::PipelineBindPoint::COMPUTE,
                self.pipeline,
                self.layout,
                &[set],
            );
            rec.push(self.layout, vk::ShaderStageFlags::COMPUTE, 0, push);
        }
    }

    /// Destroys what exists (null handles are ignored by Vulkan).
    pub fn destroy(&mut self, ctx: &Context) {
        // SAFETY: the objects are this value's own, from `ctx.device`; null ones (a creation
        // that failed half way) are no-ops. Owners destroy them once no pending work uses the
        // pipeline (a case kernel's runs wait for their fence; the tile update's owner after
        // its lighting waited, teardown.rs), the pipeline before the layouts it was made with.
        unsafe {
            ctx.device.destroy_pipeline(self.pipeline, None);
            ctx.device.destroy_pipeline_layout(self.layout, None);
            ctx.device
                .destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}

/// A [`ComputePipeline`] with the case count as its only push constant: binding 0 holds the
/// cases, binding 1 receives one `vec4` per case, and any further bindings are the caller's
/// read-only data.
pub(crate) struct CaseKernel {
    name: &'static str,
    compute: ComputePipeline,
}

impl CaseKernel {
    pub fn new(
        ctx: &Context,
        name: &'static str,
        set: &[BindingDesc],
        module: (&str, &[u8]),
    ) -> Result<Self> {
        let compute = ComputePipeline::new(ctx, name, set, module, 4)?;
        Ok(Self { name, compute })
    }

    /// Runs the kernel over `count` cases laid out in `cases` (std430), with `extra` as
    /// bindings 2, 3, ..., and returns the first three components of each result.
    pub fn run(
        &self,
        ctx: &Context,
        cases: &[u8],
        count: u32,
        extra: &[vk::Buffer],
    ) -> Result<Vec<[f32; 4]>> {
        if count == 0 {
            return Ok(Vec::new());
        }
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let mut input = Buffer::with_data(ctx, &format!("{}-cases", self.name), storage, cases)?;
        let mut output = match Buffer::new(
            ctx,
            &format!("{}-results", self.name),
            u64::from(count) * 16,
            storage,
            MemoryLocation::GpuToCpu,
        ) {
            Ok(b) => b,
            Err(e) => {
                input.destroy(ctx);
                return Err(e);
            }
        };
        let mut buffers = vec![input.handle, output.handle];
        buffers.extend_from_slice(extra);
        let values = self.dispatch(ctx, &buffers, count).map(|()| {
            bytemuck::cast_slice::<u8, f32>(output.read())
                .chunks_exact(4)
                .map(|c| [c[0], c[1], c[2], c[3]])
                .collect()
        });
        input.destroy(ctx);
        output.destroy(ctx);
        values
    }

    fn dispatch(&self, ctx: &Context, buffers: &[vk::Buffer], count: u32) -> Result<()> {
        let (pool, set) =
            create_storage_buffer_set(ctx, self.name, self.compute.set_layout, buffers)?;
        let recorded = submit_once(ctx, self.name, |rec| {
            // Host writes to the inputs are visible at submit; only the results need a
            // barrier, towards the host read after the fence. The kernel writes binding 1.
            rec.declare_buffers(&[(buffers[1], BufferAccess::ComputeWrite)]);
            self.compute.bind(rec, set, &count.to_le_bytes());
            // SAFETY: `rec` is `submit_once`'s, recording outside rendering, with the pipeline
            // and its set bound just above. The group count stays within the spec's minimum
            // `maxComputeWorkGroupCount[0]` (65535) up to 65535 * 64 cases; nothing checks a
            // longer list (the evaluators' callers pass test-sized ones).
            unsafe { rec.dispatch([count.div_ceil(WORKGROUP), 1, 1]) };
            rec.host_readable(vk::PipelineStageFlags2::COMPUTE_SHADER);
        });
        // SAFETY: the pool (and its set) was made above for this dispatch alone. When
        // `submit_once` succeeded its fence wait left the GPU done with it; when it failed
        // before the submit nothing used it. After a failed fence wait the dispatch may still
        // be pending, and freeing the pool then is unsound (as in `submit_once`).
        unsafe { ctx.device.destroy_descriptor_pool(pool, None) };
        recorded
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.compute.destroy(ctx);
    }
}

/// A direction padded to a std430 `vec4`.
pub(crate) fn pad(d: [f32; 3]) -> [f32; 4] {
    [d[0], d[1], d[2], 0.0]
}
