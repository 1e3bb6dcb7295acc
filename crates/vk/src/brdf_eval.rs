//! Evaluates BRDF cases on the GPU with the GLSL spelling (`shaders/brdf_eval.comp`), so the
//! shipping shader code can be held to the f64 reference. One dispatch per call.

use crate::context::Context;
use crate::descriptors::{
    create_pipeline_layout, create_set_layout, create_storage_buffer_set, BRDF_EVAL_SET,
};
use crate::error::{Result, VkCall};
use crate::pipelines::create_compute_pipeline;
use crate::readback::host_readable;
use crate::resources::Buffer;
use crate::shaders;
use ash::vk;
use gpu_allocator::MemoryLocation;
use histencil_brdf::{Brdf, V3};

/// std430 mirror of `BrdfCase` in `shaders/brdf_eval.comp`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct GpuBrdfCase {
    model: [u32; 4],
    params: [f32; 4],
    n: [f32; 4],
    t: [f32; 4],
    v: [f32; 4],
    l: [f32; 4],
}

const WORKGROUP: u32 = 64;

fn pad(d: V3<f32>) -> [f32; 4] {
    [d[0], d[1], d[2], 0.0]
}

/// The compute pipeline and its layouts; buffers are made per call.
pub struct BrdfEvaluator {
    set_layout: vk::DescriptorSetLayout,
    pipeline_layout: vk::PipelineLayout,
    pipeline: vk::Pipeline,
}

impl BrdfEvaluator {
    pub fn new(ctx: &Context) -> Result<Self> {
        let compute = vk::ShaderStageFlags::COMPUTE;
        let set_layout = create_set_layout(ctx, "brdf-eval-set-layout", BRDF_EVAL_SET, compute)?;
        // Push constants: the case count.
        let pipeline_layout =
            create_pipeline_layout(ctx, "brdf-eval-pipeline-layout", &[set_layout], compute, 4)?;
        let pipeline = create_compute_pipeline(
            ctx,
            "brdf-eval-pipeline",
            ("brdf-eval-comp", shaders::BRDF_EVAL_COMP),
            pipeline_layout,
        )?;
        Ok(Self {
            set_layout,
            pipeline_layout,
            pipeline,
        })
    }

    /// `f_r * cos(theta_L)` of each case, RGB (scalar models repeat their value).
    pub fn evaluate(&self, ctx: &Context, cases: &[(Brdf, [V3<f32>; 4])]) -> Result<Vec<[f32; 3]>> {
        if cases.is_empty() {
            return Ok(Vec::new());
        }
        let gpu: Vec<GpuBrdfCase> = cases
            .iter()
            .map(|(brdf, [n, t, v, l])| GpuBrdfCase {
                model: [brdf.model_index(), 0, 0, 0],
                params: brdf.packed_params().map(|p| p as f32),
                n: pad(*n),
                t: pad(*t),
                v: pad(*v),
                l: pad(*l),
            })
            .collect();
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let mut input =
            Buffer::with_data(ctx, "brdf-eval-cases", storage, bytemuck::cast_slice(&gpu))?;
        let mut output = match Buffer::new(
            ctx,
            "brdf-eval-results",
            (cases.len() * 16) as u64,
            storage,
            MemoryLocation::GpuToCpu,
        ) {
            Ok(b) => b,
            Err(e) => {
                input.destroy(ctx);
                return Err(e);
            }
        };
        let result = self.dispatch(ctx, &input, &output, cases.len() as u32);
        let values = result.map(|()| {
            bytemuck::cast_slice::<u8, f32>(output.read())
                .chunks_exact(4)
                .map(|c| [c[0], c[1], c[2]])
                .collect()
        });
        input.destroy(ctx);
        output.destroy(ctx);
        values
    }

    fn dispatch(&self, ctx: &Context, input: &Buffer, output: &Buffer, count: u32) -> Result<()> {
        let d = &ctx.device;
        let (pool, set) = create_storage_buffer_set(
            ctx,
            "brdf-eval",
            self.set_layout,
            &[input.handle, output.handle],
        )?;
        let command_pool = unsafe {
            d.create_command_pool(
                &vk::CommandPoolCreateInfo::default().queue_family_index(ctx.queue_family),
                None,
            )
        };
        let fence = unsafe { d.create_fence(&vk::FenceCreateInfo::default(), None) };
        let recorded = (|| -> Result<()> {
            let command_pool = command_pool.call("vkCreateCommandPool")?;
            ctx.name(command_pool, "brdf-eval-command-pool");
            let fence = fence.call("vkCreateFence")?;
            ctx.name(fence, "brdf-eval-fence");
            let cmd = unsafe {
                d.allocate_command_buffers(
                    &vk::CommandBufferAllocateInfo::default()
                        .command_pool(command_pool)
                        .command_buffer_count(1),
                )
            }
            .call("vkAllocateCommandBuffers")?[0];
            ctx.name(cmd, "brdf-eval-commands");
            unsafe {
                d.begin_command_buffer(
                    cmd,
                    &vk::CommandBufferBeginInfo::default()
                        .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
                )
                .call("vkBeginCommandBuffer")?;
                ctx.begin_label(cmd, "brdf-eval");
                // Host writes to the case buffer are visible at submit; only the result needs
                // a barrier, towards the host read after the fence.
                d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.pipeline);
                d.cmd_bind_descriptor_sets(
                    cmd,
                    vk::PipelineBindPoint::COMPUTE,
                    self.pipeline_layout,
                    0,
                    &[set],
                    &[],
                );
                d.cmd_push_constants(
                    cmd,
                    self.pipeline_layout,
                    vk::ShaderStageFlags::COMPUTE,
                    0,
                    &count.to_le_bytes(),
                );
                d.cmd_dispatch(cmd, count.div_ceil(WORKGROUP), 1, 1);
                host_readable(ctx, cmd, vk::PipelineStageFlags2::COMPUTE_SHADER);
                ctx.end_label(cmd);
                d.end_command_buffer(cmd).call("vkEndCommandBuffer")?;
                let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
                let submit = vk::SubmitInfo2::default().command_buffer_infos(&cmds);
                d.queue_submit2(ctx.queue, &[submit], fence)
                    .call("vkQueueSubmit2")?;
                d.wait_for_fences(&[fence], true, u64::MAX)
                    .call("vkWaitForFences")?;
            }
            Ok(())
        })();
        unsafe {
            if let Ok(fence) = fence {
                d.destroy_fence(fence, None);
            }
            if let Ok(command_pool) = command_pool {
                d.destroy_command_pool(command_pool, None);
            }
            d.destroy_descriptor_pool(pool, None);
        }
        recorded
    }

    pub fn destroy(&mut self, ctx: &Context) {
        unsafe {
            ctx.device.destroy_pipeline(self.pipeline, None);
            ctx.device
                .destroy_pipeline_layout(self.pipeline_layout, None);
            ctx.device
                .destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}
