//! Making an engine's lightmaps: set layouts, pipeline layout, pipelines, the descriptor pool and
//! every slot's buffers and sets; a failure half way leaves the rest to `Drop`.

use super::*;

impl<C: Deref<Target = Context>> AlphaLightmaps<C> {
    pub(super) fn create(&mut self) -> Result<()> {
        let ctx: &Context = &self.ctx;
        self.set_layouts[0] =
            create_set_layout(ctx, "lightmap-frame-set-layout", FRAME_SET, GRAPHICS_STAGES)?;
        self.set_layouts[1] =
            create_set_layout(ctx, "alpha-set-layout", ALPHA_SET, GRAPHICS_STAGES)?;
        self.pipeline_layout = create_pipeline_layout(
            ctx,
            "lightmap-pipeline-layout",
            &self.set_layouts,
            GRAPHICS_STAGES,
            size_of::<AlphaDrawPush>() as u32,
        )?;
        let formats = [self.desc.atlas_format];
        let plain = PipelineDesc {
            name: "alpha-lightmap-pipeline",
            vertex: ("fullscreen.vert", shaders::FULLSCREEN_VERT),
            fragment: Some(("lightmap.frag", self.modules.lightmap)),
            layout: self.pipeline_layout,
            vertex_input: VertexInput::None,
            color_formats: &formats,
            color_writes: true,
            blend: Blend::Additive,
            depth_stencil_format: vk::Format::UNDEFINED,
            depth_clamp: false,
            specialization: &[],
        };
        self.pipeline = create_pipeline(ctx, &plain)?;
        if let Some(direction_format) = self.desc.direction_format {
            let formats = [self.desc.atlas_format, direction_format];
            self.directional_pipeline = create_pipeline(
                ctx,
                &PipelineDesc {
                    name: "alpha-lightmap-directional-pipeline",
                    fragment: Some((
                        "lightmap_directional.frag",
                        self.modules.lightmap_directional,
                    )),
                    color_formats: &formats,
                    ..plain
                },
            )?;
        }

        let slots = self.desc.frames_in_flight;
        let sizes =
            crate::gpu::device::descriptors::pool_sizes(&[(FRAME_SET, slots), (ALPHA_SET, slots)]);
        let info = vk::DescriptorPoolCreateInfo::default()
            .max_sets(2 * slots)
            .pool_sizes(&sizes);
        // SAFETY: `info` and `sizes` outlive the call; `new` refused no frames in flight, so
        // `max_sets` and every size's count are non-zero.
        self.pool = unsafe { ctx.device.create_descriptor_pool(&info, None) }
            .call("vkCreateDescriptorPool")?;
        ctx.name(self.pool, "lightmap-descriptor-pool");
        let layouts: Vec<_> = (0..slots).flat_map(|_| self.set_layouts).collect();
        let alloc = vk::DescriptorSetAllocateInfo::default()
            .descriptor_pool(self.pool)
            .set_layouts(&layouts);
        // SAFETY: the pool was made above from this device with room for exactly these sets
        // (two per slot) and their descriptors; both set layouts were made above and are live.
        let sets = unsafe { ctx.device.allocate_descriptor_sets(&alloc) }
            .call("vkAllocateDescriptorSets")?;
        for (i, pair) in sets.chunks(2).enumerate() {
            let (frame_set, alpha_set) = (pair[0], pair[1]);
            ctx.name(frame_set, &format!("lightmap-frame-set-{i}"));
            ctx.name(alpha_set, &format!("alpha-set-{i}"));
            let mut made: Vec<Buffer> = Vec::new();
            let mut make = |name: String, bytes: u64, usage| -> Result<()> {
                made.push(Buffer::new(
                    ctx,
                    &name,
                    bytes,
                    usage,
                    MemoryLocation::CpuToGpu,
                )?);
                Ok(())
            };
            let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
            let result = make(
                format!("lightmap-uniforms-{i}"),
                size_of::<FrameUniforms>() as u64,
                vk::BufferUsageFlags::UNIFORM_BUFFER,
            )
            .and_then(|()| make(format!("lightmap-lights-{i}"), 256, storage))
            .and_then(|()| {
                STORAGE_NAMES
                    .iter()
                    .try_for_each(|name| make(format!("{name}-{i}"), 256, storage))
            });
            if let Err(e) = result {
                for mut b in made {
                    b.destroy(ctx);
                }
                return Err(e);
            }
            let mut made = made.into_iter();
            let mut next = move || made.next().expect("six buffers");
            let slot = Slot {
                uniforms: next(),
                lights: next(),
                storage: [next(), next(), next(), next()],
                frame_set,
                alpha_set,
                entity_lights: Vec::new(),
                timer: SlotTimer::default(),
            };
            write_frame_set(ctx, frame_set, slot.uniforms.handle, slot.lights.handle);
            write_storage_buffers(ctx, alpha_set, &slot.storage.each_ref().map(|b| b.handle));
            self.slots.push(slot);
        }
        Ok(())
    }
}
