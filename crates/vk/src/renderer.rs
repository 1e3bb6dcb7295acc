//! The renderer: owns a scene's GPU resources and records / submits whole frames.

use crate::context::Context;
use crate::descriptors::{DescriptorTargets, Descriptors};
use crate::error::{Result, VkCall};
use crate::gpu_types::{FrameUniforms, GpuLight};
use crate::meshes::Meshes;
use crate::passes::geometry::GeometryPass;
use crate::passes::lighting::LightingPass;
use crate::passes::tonemap::TonemapPass;
use crate::pipelines::{PipelineLayouts, Pipelines, TargetFormats};
use crate::readback::{FrameImages, Readback, ReadbackBuffers};
use crate::resources::Buffer;
use crate::targets::{check_extent, Targets, GBUFFER_FORMATS, HDR_FORMAT, LDR_FORMAT};
use crate::timing::{FrameTimings, Timestamps};
use ash::vk;
use histencil_brdf::BrdfId;
use histencil_model::StencilLayout;
use histencil_scene::Scene;

/// How the frame is lit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Technique {
    /// G-buffer, then light volumes with stencil depth culling; the light shader branches on the
    /// G-buffer's BRDF id.
    Deferred,
    /// The forward reference: every object lit by every light per pixel.
    Forward,
}

impl std::str::FromStr for Technique {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "deferred" => Ok(Technique::Deferred),
            "forward" => Ok(Technique::Forward),
            _ => Err(format!(
                "unknown technique `{s}` (known: deferred, forward)"
            )),
        }
    }
}

/// A rendered frame: its GPU timings and the images asked for.
pub struct Frame {
    pub timings: FrameTimings,
    pub images: FrameImages,
}

/// A scene ready to render at one resolution.
pub struct Renderer<'c> {
    ctx: &'c Context,
    scene: Scene,
    stencil_layout: StencilLayout,
    /// Each object's BRDF slot (index among the BRDFs in use).
    object_slots: Vec<u32>,
    extent: vk::Extent2D,
    targets: Targets,
    meshes: Meshes,
    frame_uniforms: Buffer,
    lights: Buffer,
    descriptors: Descriptors,
    pipelines: Pipelines,
    command_pool: vk::CommandPool,
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
    timestamps: Timestamps,
    readback: ReadbackBuffers,
}

impl<'c> Renderer<'c> {
    /// Validates the scene and the resolution, then builds everything a frame needs.
    pub fn new(ctx: &'c Context, scene: Scene, width: u32, height: u32) -> Result<Self> {
        scene.validate()?;
        let extent = check_extent(ctx, width, height)?;
        let brdfs: Vec<BrdfId> = scene.brdfs_in_use();
        let stencil_layout = StencilLayout::new(brdfs.len().max(1) as u32, 0)?;
        let object_slots = scene
            .objects
            .iter()
            .map(|o| brdfs.iter().position(|b| *b == o.material.brdf).unwrap() as u32)
            .collect();

        let targets = Targets::new(ctx, extent)?;
        let meshes = Meshes::new(ctx)?;
        let uniforms = FrameUniforms::new(&scene.camera, width, height, scene.lights.len() as u32);
        let frame_uniforms = Buffer::with_data(
            ctx,
            "frame-uniforms",
            vk::BufferUsageFlags::UNIFORM_BUFFER,
            bytemuck::bytes_of(&uniforms),
        )?;
        let gpu_lights: Vec<GpuLight> = scene.lights.iter().map(GpuLight::new).collect();
        let lights = Buffer::with_data(
            ctx,
            "scene-lights",
            vk::BufferUsageFlags::STORAGE_BUFFER,
            bytemuck::cast_slice(&gpu_lights),
        )?;
        let descriptors = Descriptors::new(
            ctx,
            &DescriptorTargets {
                frame_uniforms: frame_uniforms.handle,
                lights: lights.handle,
                gbuffer_views: [
                    targets.gbuffer[0].view,
                    targets.gbuffer[1].view,
                    targets.gbuffer[2].view,
                ],
                hdr_view: targets.hdr.view,
            },
        )?;
        let pipelines = Pipelines::new(
            ctx,
            &PipelineLayouts {
                mesh: descriptors.mesh_pipeline_layout,
                lighting: descriptors.lighting_pipeline_layout,
                tonemap: descriptors.tonemap_pipeline_layout,
            },
            &TargetFormats {
                gbuffer: GBUFFER_FORMATS,
                hdr: HDR_FORMAT,
                ldr: LDR_FORMAT,
                depth_stencil: ctx.depth_stencil_format,
            },
        )?;
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(ctx.queue_family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        let command_pool = unsafe { ctx.device.create_command_pool(&pool_info, None) }
            .call("vkCreateCommandPool")?;
        ctx.name(command_pool, "frame-command-pool");
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(command_pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        let cmd = unsafe { ctx.device.allocate_command_buffers(&alloc) }
            .call("vkAllocateCommandBuffers")?[0];
        ctx.name(cmd, "frame-commands");
        let fence = unsafe {
            ctx.device
                .create_fence(&vk::FenceCreateInfo::default(), None)
        }
        .call("vkCreateFence")?;
        ctx.name(fence, "frame-fence");
        let timestamps = Timestamps::new(ctx)?;
        let readback = ReadbackBuffers::new(ctx, extent)?;
        Ok(Self {
            ctx,
            scene,
            stencil_layout,
            object_slots,
            extent,
            targets,
            meshes,
            frame_uniforms,
            lights,
            descriptors,
            pipelines,
            command_pool,
            cmd,
            fence,
            timestamps,
            readback,
        })
    }

    pub fn stencil_layout(&self) -> &StencilLayout {
        &self.stencil_layout
    }

    /// The stencil value each object's G-buffer draw writes (before any engine bits).
    pub fn object_stencil_values(&self) -> Vec<u8> {
        let l = &self.stencil_layout;
        self.object_slots
            .iter()
            .map(|s| {
                if l.has_brdf_bits() {
                    l.brdf_reference(*s)
                } else {
                    0
                }
            })
            .collect()
    }

    /// Renders one frame and waits for it. `readback` says which images to copy back.
    pub fn render(&mut self, technique: Technique, readback: Readback) -> Result<Frame> {
        // Only the deferred path has a G-buffer to read BRDF ids from.
        let readback = Readback {
            brdf_ids: readback.brdf_ids && technique == Technique::Deferred,
            ..readback
        };
        let ctx = self.ctx;
        let cmd = self.cmd;
        unsafe {
            ctx.device
                .reset_command_buffer(cmd, vk::CommandBufferResetFlags::empty())
                .call("vkResetCommandBuffer")?;
            let begin = vk::CommandBufferBeginInfo::default()
                .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            ctx.device
                .begin_command_buffer(cmd, &begin)
                .call("vkBeginCommandBuffer")?;
        }
        self.timestamps.begin_frame(ctx, cmd);
        let geometry = GeometryPass {
            ctx,
            cmd,
            scene: &self.scene,
            meshes: &self.meshes,
            pipeline: match technique {
                Technique::Deferred => self.pipelines.gbuffer,
                Technique::Forward => self.pipelines.forward,
            },
            pipeline_layout: self.descriptors.mesh_pipeline_layout,
            frame_set: self.descriptors.frame_set,
            extent: self.extent,
        };
        match technique {
            Technique::Deferred => {
                geometry.record_gbuffer(
                    &mut self.targets,
                    &self.stencil_layout,
                    &self.object_slots,
                );
                self.timestamps.mark(ctx, cmd, "gbuffer");
                LightingPass {
                    ctx,
                    cmd,
                    lights: &self.scene.lights,
                    camera: &self.scene.camera,
                    meshes: &self.meshes,
                    pipelines: &self.pipelines,
                    pipeline_layout: self.descriptors.lighting_pipeline_layout,
                    sets: [self.descriptors.frame_set, self.descriptors.gbuffer_set],
                    layout: &self.stencil_layout,
                    extent: self.extent,
                }
                .record(&mut self.targets);
                self.timestamps.mark(ctx, cmd, "lighting");
            }
            Technique::Forward => {
                geometry.record_forward(&mut self.targets);
                self.timestamps.mark(ctx, cmd, "forward");
            }
        }
        TonemapPass {
            ctx,
            cmd,
            pipeline: self.pipelines.tonemap,
            pipeline_layout: self.descriptors.tonemap_pipeline_layout,
            sets: [self.descriptors.frame_set, self.descriptors.tonemap_set],
            extent: self.extent,
        }
        .record(&mut self.targets);
        self.timestamps.mark(ctx, cmd, "tonemap");
        self.readback.record(ctx, cmd, &mut self.targets, readback);
        unsafe {
            ctx.device
                .end_command_buffer(cmd)
                .call("vkEndCommandBuffer")?;
            let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
            let submit = vk::SubmitInfo2::default().command_buffer_infos(&cmds);
            ctx.device
                .queue_submit2(ctx.queue, &[submit], self.fence)
                .call("vkQueueSubmit2")?;
            ctx.device
                .wait_for_fences(&[self.fence], true, u64::MAX)
                .call("vkWaitForFences")?;
            ctx.device
                .reset_fences(&[self.fence])
                .call("vkResetFences")?;
        }
        let timings = self.timestamps.read(ctx)?;
        let images = self.readback.read(readback)?;
        Ok(Frame { timings, images })
    }

    /// Renders `frames` frames without readback and returns the median of each timing.
    pub fn measure(&mut self, technique: Technique, frames: usize) -> Result<FrameTimings> {
        let mut all = Vec::new();
        for _ in 0..frames.max(1) {
            all.push(self.render(technique, Readback::NONE)?.timings);
        }
        Ok(FrameTimings::median(&all))
    }
}

impl Drop for Renderer<'_> {
    fn drop(&mut self) {
        let ctx = self.ctx;
        unsafe {
            let _ = ctx.device.device_wait_idle();
            ctx.device.destroy_fence(self.fence, None);
            ctx.device.destroy_command_pool(self.command_pool, None);
        }
        self.timestamps.destroy(ctx);
        self.readback.destroy(ctx);
        self.pipelines.destroy(ctx);
        self.descriptors.destroy(ctx);
        self.lights.destroy(ctx);
        self.frame_uniforms.destroy(ctx);
        self.meshes.destroy(ctx);
        self.targets.destroy(ctx);
    }
}
