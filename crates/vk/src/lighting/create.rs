//! Making a lighting: its set layouts, pipeline layout, per-slot buffers and sets, the
//! hi-stencil surface and the light volumes; a failure half way leaves the rest to `Drop`.

use super::{DeferredLighting, Slot};
use crate::gpu::device::context::Context;
use crate::gpu::device::descriptors::{
    create_pipeline_layout, create_set_layout, write_frame_set, write_storage_buffers, FRAME_SET,
    GBUFFER_SET, GRAPHICS_STAGES,
};
use crate::gpu::device::error::{Result, VkCall};
use crate::gpu::device::resources::Buffer;
use crate::gpu::encoder::timing::SlotTimer;
use crate::gpu::frame::gpu_types::{FrameUniforms, GpuLight, PUSH_CONSTANT_BYTES};
use crate::hi_stencil::HiStencilSurface;
use crate::hi_stencil::HI_STENCIL_SET;
use crate::lighting::hooks::LightHooks;
use crate::lighting::lut::LUT_SET;
use crate::passes::light_pipelines::LightPipelines;
use crate::passes::light_volumes::LightVolumes;
use ash::vk;
use gpu_allocator::MemoryLocation;
use std::ops::Deref;

impl<C: Deref<Target = Context>> DeferredLighting<C> {
    pub(super) fn create(&mut self) -> Result<()> {
        let ctx: &Context = &self.ctx;
        let named = [
            ("frame-set-layout", FRAME_SET),
            ("gbuffer-set-layout", GBUFFER_SET),
            ("hi-stencil-set-layout", HI_STENCIL_SET),
            ("lut-set-layout", LUT_SET),
        ];
        let hooks = &self.desc.hooks;
        let builtin = hooks.is_builtin_decode();
        for (i, (name, set)) in named.into_iter().enumerate() {
            if i == 1 && !builtin {
                continue;
            }
            // The tiled technique's compute kernels bind the frame, G-buffer and filler sets.
            let stages = match i {
                2 => GRAPHICS_STAGES,
                _ => GRAPHICS_STAGES | vk::ShaderStageFlags::COMPUTE,
            };
            self.set_layouts[i] = create_set_layout(ctx, name, set, stages)?;
        }
        let mut layouts = self.set_layouts.to_vec();
        if let LightHooks::Engine(engine) = hooks {
            engine.register_layouts(ctx);
            layouts[1] = engine.decode_layout;
            layouts.extend(engine.visibility_layout);
        }
        self.pipeline_layout = create_pipeline_layout(
            ctx,
            "lighting-pipeline-layout",
            &layouts,
            GRAPHICS_STAGES,
            PUSH_CONSTANT_BYTES,
        )?;
        self.pipelines = LightPipelines::new(
            self.pipeline_layout,
            hooks.modules(),
            self.desc.hdr_format,
            self.desc.depth_stencil_format,
        );
        self.volumes = Some(LightVolumes::new(ctx)?);
        // Without the emulation the light pipelines still bind its set: a one-tile surface.
        let surface = if self.desc.hi_stencil {
            self.desc.extent
        } else {
            vk::Extent2D {
                width: 1,
                height: 1,
            }
        };
        let slots = self.desc.frames_in_flight;
        self.hi_stencil = Some(HiStencilSurface::new(ctx, surface, slots)?);

        // Per slot its frame set, and with the built-in decode its G-buffer set; the hi-stencil
        // and LUT sets once.
        let decode_sets = if builtin { slots } else { 0 };
        let sizes = crate::gpu::device::descriptors::pool_sizes(&[
            (FRAME_SET, slots),
            (GBUFFER_SET, decode_sets),
            (HI_STENCIL_SET, 1),
            (LUT_SET, 1),
        ]);
        let sets_per_slot = if builtin { 2 } else { 1 };
        let info = vk::DescriptorPoolCreateInfo::default()
            .max_sets(sets_per_slot * slots + 2)
            .pool_sizes(&sizes);
        // SAFETY: `info` and the `sizes` it points at outlive the call; `check_desc` refused no
        // frames in flight, so `max_sets` and every size's count are non-zero.
        self.pool = unsafe { ctx.device.create_descriptor_pool(&info, None) }
            .call("vkCreateDescriptorPool")?;
        ctx.name(self.pool, "lighting-descriptor-pool");
        let [frame_layout, gbuffer_layout, hi_stencil_layout, lut_layout] = self.set_layouts;
        let mut layouts = vec![hi_stencil_layout, lut_layout];
        for _ in 0..slots {
            layouts.push(frame_layout);
            if builtin {
                layouts.push(gbuffer_layout);
            }
        }
        let alloc = vk::DescriptorSetAllocateInfo::default()
            .descriptor_pool(self.pool)
            .set_layouts(&layouts);
        // SAFETY: the pool was made above from this device for exactly these sets (`max_sets`
        // counts them, its sizes their descriptors), and the layouts are live, made above.
        let sets = unsafe { ctx.device.allocate_descriptor_sets(&alloc) }
            .call("vkAllocateDescriptorSets")?;
        self.hi_stencil_set = sets[0];
        ctx.name(sets[0], "hi-stencil-set");
        ctx.name(sets[1], "lut-set");
        let hi = self.hi_stencil.as_ref().expect("made above");
        write_storage_buffers(ctx, self.hi_stencil_set, &hi.light_set_buffers());
        self.lut_set = sets[1];

        let light_bytes = u64::from(self.desc.max_lights.max(1)) * size_of::<GpuLight>() as u64;
        for (i, pair) in sets[2..].chunks(sets_per_slot as usize).enumerate() {
            let frame_set = pair[0];
            let gbuffer_set = pair.get(1).copied().unwrap_or_default();
            ctx.name(frame_set, &format!("lighting-frame-set-{i}"));
            if builtin {
                ctx.name(gbuffer_set, &format!("lighting-gbuffer-set-{i}"));
            }
            let uniforms = Buffer::new(
                ctx,
                &format!("lighting-uniforms-{i}"),
                size_of::<FrameUniforms>() as u64,
                vk::BufferUsageFlags::UNIFORM_BUFFER,
                MemoryLocation::CpuToGpu,
            )?;
            let lights = Buffer::new(
                ctx,
                &format!("lighting-lights-{i}"),
                light_bytes,
                vk::BufferUsageFlags::STORAGE_BUFFER,
                MemoryLocation::CpuToGpu,
            );
            let lights = match lights {
                Ok(l) => l,
                Err(e) => {
                    let mut uniforms = uniforms;
                    uniforms.destroy(ctx);
                    return Err(e);
                }
            };
            write_frame_set(ctx, frame_set, uniforms.handle, lights.handle);
            self.slots.push(Slot {
                uniforms,
                lights,
                frame_set,
                gbuffer_set,
                timer: SlotTimer::default(),
                emulation: SlotTimer::default(),
            });
        }
        Ok(())
    }
}
