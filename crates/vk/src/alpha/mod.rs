//! The talk's second technique on the GPU: translucent objects and particle systems lit through
//! per-entity lightmaps, then blended over the lit frame.
//!
//! Once (at the first frame): each alpha mesh is drawn in its UV layout into its region of the
//! position atlas, leaving one object-space probe (position and normal) per texel. Every frame:
//! each entity's region of the lightmap atlas is lit by the lights that reach its bounds, one
//! additive draw per light with the deferred pass's light code (`lightmap.frag`); then the alpha
//! pass draws the entities far to near, sampling their regions. The probes of particle systems
//! are not baked: they follow the camera (a quad or slices fitted around the system), a mote
//! (dust), or the ribbon's control points, and `lightmap.frag` computes them per texel.

mod gpu;

use crate::access::{transition, Contents, ImageAccess};
use crate::context::Context;
use crate::descriptors::{
    create_pipeline_layout, create_set_layout, write_storage_buffers, ALPHA_LIGHTMAP_SET,
    ALPHA_SET, GRAPHICS_STAGES,
};
use crate::error::{Result, VkCall};
use crate::meshes::Meshes;
use crate::passes::{begin_hdr_rendering, begin_rendering, color_attachment, Load, CLEAR_BLACK};
use crate::pipelines::{create_pipeline, Blend, PipelineDesc, VertexInput};
use crate::resources::{Buffer, Image};
use crate::shader_consts::ALPHA_MODES;
use crate::shaders;
use crate::state::{apply, oriented, FULLSCREEN};
use crate::targets::{Targets, HDR_FORMAT};
use ash::vk;
use gpu::{entity_lights, entity_records, AlphaDrawPush};
use histencil_alpha::{
    back_to_front, plan_layout, sprite_vertices, EntityKey, LightmapLayout, SpriteVertex,
};
use histencil_model::{CompareOp, CullMode, DepthConvention, DepthState, PassState};
use histencil_scene::Scene;

/// How the alpha pass lights translucent objects and particles.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum AlphaMode {
    /// The talk's technique: per-entity lightmaps lit on the GPU every frame.
    #[default]
    Lightmap,
    /// Ground truth: every light evaluated per pixel, as the forward reference does.
    Forward,
    /// The classic alternative: every light evaluated at one point per entity (what a CPU light
    /// probe stores), applied with the fragment's normal and view direction.
    Probe,
}

impl AlphaMode {
    fn code(self) -> u32 {
        let name = match self {
            AlphaMode::Lightmap => "ALPHA_MODE_LIGHTMAP",
            AlphaMode::Forward => "ALPHA_MODE_FORWARD",
            AlphaMode::Probe => "ALPHA_MODE_PROBE",
        };
        ALPHA_MODES
            .iter()
            .find(|(n, _)| *n == name)
            .expect("known mode")
            .1
    }
}

/// Position and normal atlases: f32, the probes' positions are the lighting's inputs.
const PROBE_FORMAT: vk::Format = vk::Format::R32G32B32A32_SFLOAT;
/// The lightmap atlas: HDR radiance, as the lighting target.
const LIGHTMAP_FORMAT: vk::Format = HDR_FORMAT;

/// Translucent surfaces: depth-tested against the opaque scene, not written (they do not hide
/// each other; they are sorted instead).
const ALPHA_OBJECTS: PassState = PassState {
    cull: CullMode::Back,
    depth: DepthState {
        compare: Some(CompareOp::LessOrEqual),
        write: false,
    },
    ..FULLSCREEN
};
const PARTICLES: PassState = PassState {
    cull: CullMode::None,
    ..ALPHA_OBJECTS
};

/// A scene's alpha entities on the GPU: atlases, records, sprites and pipelines.
pub(crate) struct AlphaLighting {
    layout: LightmapLayout,
    /// Blending order.
    order: Vec<EntityKey>,
    /// Per particle system: its first sprite vertex and vertex count.
    sprite_ranges: Vec<(u32, u32)>,
    /// Per entity (record order): the lights that reach it.
    entity_lights: Vec<Vec<u32>>,
    baked: bool,
    positions: Image,
    normals: Image,
    lightmap: Image,
    entities: Buffer,
    points: Buffer,
    light_list: Buffer,
    sprites: Buffer,
    alpha_set_layout: vk::DescriptorSetLayout,
    lightmap_set_layout: vk::DescriptorSetLayout,
    pipeline_layout: vk::PipelineLayout,
    pool: vk::DescriptorPool,
    alpha_set: vk::DescriptorSet,
    lightmap_set: vk::DescriptorSet,
    bake_pipeline: vk::Pipeline,
    lightmap_pipeline: vk::Pipeline,
    object_pipeline: vk::Pipeline,
    particle_pipeline: vk::Pipeline,
}

/// Every Vulkan object an [`AlphaLighting`] owns, created step by step so a failure part-way
/// destroys what exists.
#[derive(Default)]
struct Parts {
    images: Vec<Image>,
    buffers: Vec<Buffer>,
    set_layouts: Vec<vk::DescriptorSetLayout>,
    pipeline_layout: Option<vk::PipelineLayout>,
    pool: Option<vk::DescriptorPool>,
    pipelines: Vec<vk::Pipeline>,
}

impl Parts {
    fn destroy(&mut self, ctx: &Context) {
        let d = &ctx.device;
        unsafe {
            for p in self.pipelines.drain(..) {
                d.destroy_pipeline(p, None);
            }
            if let Some(pool) = self.pool.take() {
                d.destroy_descriptor_pool(pool, None);
            }
            if let Some(l) = self.pipeline_layout.take() {
                d.destroy_pipeline_layout(l, None);
            }
            for l in self.set_layouts.drain(..) {
                d.destroy_descriptor_set_layout(l, None);
            }
        }
        for mut i in self.images.drain(..) {
            i.destroy(ctx);
        }
        for mut b in self.buffers.drain(..) {
            b.destroy(ctx);
        }
    }
}

impl AlphaLighting {
    /// Plans the lightmap layout for `scene` seen at `extent` (region sides from coverage, or
    /// `forced_side`), and creates the atlases, buffers and pipelines.
    ///
    /// # Errors
    /// [`crate::Error::Lightmap`] when the layout cannot be planned (bad forced side, atlas
    /// full), besides Vulkan errors.
    pub fn new(
        ctx: &Context,
        scene: &Scene,
        extent: vk::Extent2D,
        forced_side: Option<u32>,
        frame_layout: vk::DescriptorSetLayout,
    ) -> Result<Self> {
        let max_side = histencil_alpha::MAX_ATLAS_SIDE.min(ctx.max_image_dimension);
        let layout = plan_layout(scene, extent.height, forced_side, max_side)?;
        let mut parts = Parts::default();
        match Self::create(ctx, scene, layout, frame_layout, &mut parts) {
            Ok(built) => Ok(built),
            Err(e) => {
                parts.destroy(ctx);
                Err(e)
            }
        }
    }

    fn create(
        ctx: &Context,
        scene: &Scene,
        layout: LightmapLayout,
        frame_layout: vk::DescriptorSetLayout,
        parts: &mut Parts,
    ) -> Result<Self> {
        let (w, h) = layout.atlas.size();
        let extent = vk::Extent2D {
            width: w,
            height: h,
        };
        use vk::ImageUsageFlags as U;
        let usage = U::COLOR_ATTACHMENT | U::SAMPLED;
        for (name, format) in [
            ("alpha-position-atlas", PROBE_FORMAT),
            ("alpha-normal-atlas", PROBE_FORMAT),
            ("alpha-lightmap-atlas", LIGHTMAP_FORMAT),
        ] {
            parts
                .images
                .push(Image::new(ctx, name, format, extent, usage)?);
        }

        let entity_lights = entity_lights(scene, &layout.regions);
        let (records, mut points, mut light_list) =
            entity_records(scene, &layout.regions, &entity_lights);
        // A storage buffer binding needs a non-empty range.
        if points.is_empty() {
            points.push([0.0; 4]);
        }
        if light_list.is_empty() {
            light_list.push(0);
        }
        for (name, bytes) in [
            ("alpha-entities", bytemuck::cast_slice::<_, u8>(&records)),
            ("alpha-points", bytemuck::cast_slice(&points)),
            ("alpha-entity-lights", bytemuck::cast_slice(&light_list)),
        ] {
            let usage = vk::BufferUsageFlags::STORAGE_BUFFER;
            parts
                .buffers
                .push(Buffer::with_data(ctx, name, usage, bytes)?);
        }
        let mut sprites: Vec<SpriteVertex> = Vec::new();
        let mut sprite_ranges = Vec::new();
        let objects = scene.alpha_objects.len() as u32;
        for (i, system) in scene.particle_systems.iter().enumerate() {
            let first = sprites.len() as u32;
            sprites.extend(sprite_vertices(&scene.camera, system, objects + i as u32));
            sprite_ranges.push((first, sprites.len() as u32 - first));
        }
        if sprites.is_empty() {
            sprites.push(bytemuck::Zeroable::zeroed());
        }
        parts.buffers.push(Buffer::with_data(
            ctx,
            "alpha-sprites",
            vk::BufferUsageFlags::VERTEX_BUFFER,
            bytemuck::cast_slice(&sprites),
        )?);

        let alpha_set_layout =
            create_set_layout(ctx, "alpha-set-layout", ALPHA_SET, GRAPHICS_STAGES)?;
        parts.set_layouts.push(alpha_set_layout);
        let lightmap_set_layout = create_set_layout(
            ctx,
            "alpha-lightmap-set-layout",
            ALPHA_LIGHTMAP_SET,
            GRAPHICS_STAGES,
        )?;
        parts.set_layouts.push(lightmap_set_layout);
        let pipeline_layout = create_pipeline_layout(
            ctx,
            "alpha-pipeline-layout",
            &[frame_layout, alpha_set_layout, lightmap_set_layout],
            GRAPHICS_STAGES,
            size_of::<AlphaDrawPush>() as u32,
        )?;
        parts.pipeline_layout = Some(pipeline_layout);
        let (pool, alpha_set, lightmap_set) =
            create_sets(ctx, parts, [alpha_set_layout, lightmap_set_layout])?;

        let probe_formats = [PROBE_FORMAT, PROBE_FORMAT];
        let lightmap_formats = [LIGHTMAP_FORMAT];
        let hdr = [HDR_FORMAT];
        let base = PipelineDesc {
            name: "alpha-bake-pipeline",
            vertex: ("alpha_bake.vert", shaders::ALPHA_BAKE_VERT),
            fragment: Some(("alpha_bake.frag", shaders::ALPHA_BAKE_FRAG)),
            layout: pipeline_layout,
            vertex_input: VertexInput::PositionNormalUv,
            color_formats: &probe_formats,
            color_writes: true,
            blend: Blend::Off,
            depth_stencil_format: vk::Format::UNDEFINED,
            depth_clamp: false,
            specialization: &[],
        };
        // The alpha pass: blended over the lit HDR frame, tested against its depth.
        let over_the_frame = PipelineDesc {
            color_formats: &hdr,
            blend: Blend::PremultipliedOver,
            depth_stencil_format: ctx.depth_stencil_format,
            ..base
        };
        let descs = [
            PipelineDesc { ..base },
            PipelineDesc {
                name: "alpha-lightmap-pipeline",
                vertex: ("fullscreen.vert", shaders::FULLSCREEN_VERT),
                fragment: Some(("lightmap.frag", shaders::LIGHTMAP_FRAG)),
                vertex_input: VertexInput::None,
                color_formats: &lightmap_formats,
                blend: Blend::Additive,
                ..base
            },
            PipelineDesc {
                name: "alpha-object-pipeline",
                vertex: ("alpha_object.vert", shaders::ALPHA_OBJECT_VERT),
                fragment: Some(("alpha_object.frag", shaders::ALPHA_OBJECT_FRAG)),
                ..over_the_frame
            },
            PipelineDesc {
                name: "alpha-particle-pipeline",
                vertex: ("particle.vert", shaders::PARTICLE_VERT),
                fragment: Some(("particle.frag", shaders::PARTICLE_FRAG)),
                vertex_input: VertexInput::Sprite,
                ..over_the_frame
            },
        ];
        for desc in &descs {
            parts.pipelines.push(create_pipeline(ctx, desc)?);
        }

        let images = &parts.images;
        let storage: Vec<vk::Buffer> = parts.buffers[..3].iter().map(|b| b.handle).collect();
        write_storage_buffers(ctx, alpha_set, &storage);
        write_sampled_image(ctx, alpha_set, 3, images[0].view);
        write_sampled_image(ctx, alpha_set, 4, images[1].view);
        write_sampled_image(ctx, lightmap_set, 0, images[2].view);

        let order = back_to_front(scene);
        let mut images = std::mem::take(&mut parts.images).into_iter();
        let mut buffers = std::mem::take(&mut parts.buffers).into_iter();
        let mut pipelines = std::mem::take(&mut parts.pipelines).into_iter();
        let mut next = move || images.next().expect("three atlases");
        let built = Self {
            layout,
            order,
            sprite_ranges,
            entity_lights,
            baked: false,
            positions: next(),
            normals: next(),
            lightmap: next(),
            entities: buffers.next().expect("entities"),
            points: buffers.next().expect("points"),
            light_list: buffers.next().expect("light list"),
            sprites: buffers.next().expect("sprites"),
            alpha_set_layout,
            lightmap_set_layout,
            pipeline_layout,
            pool,
            alpha_set,
            lightmap_set,
            bake_pipeline: pipelines.next().expect("bake"),
            lightmap_pipeline: pipelines.next().expect("lightmap"),
            object_pipeline: pipelines.next().expect("objects"),
            particle_pipeline: pipelines.next().expect("particles"),
        };
        *parts = Parts::default();
        Ok(built)
    }

    /// The planned layout: atlas size and each entity's region.
    pub fn layout(&self) -> &LightmapLayout {
        &self.layout
    }

    /// How many lightmap draws a frame makes: one per (entity, light that reaches it).
    pub fn lightmap_draws(&self) -> usize {
        self.entity_lights.iter().map(Vec::len).sum()
    }

    /// Records the probe bake (first frame only) and, in lightmap mode, the lightmap pass into
    /// `cmd`.
    pub fn record_lightmaps(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scene: &Scene,
        meshes: &Meshes,
        frame_set: vk::DescriptorSet,
        mode: AlphaMode,
    ) {
        self.bind_sets(ctx, cmd, frame_set);
        if !self.baked {
            self.record_bake(ctx, cmd, scene, meshes);
            self.baked = true;
        }
        if mode == AlphaMode::Lightmap {
            self.record_lighting(ctx, cmd);
        }
    }

    fn bind_sets(&self, ctx: &Context, cmd: vk::CommandBuffer, frame_set: vk::DescriptorSet) {
        unsafe {
            ctx.device.cmd_bind_descriptor_sets(
                cmd,
                vk::PipelineBindPoint::GRAPHICS,
                self.pipeline_layout,
                0,
                &[frame_set, self.alpha_set, self.lightmap_set],
                &[],
            );
        }
    }

    fn push(&self, ctx: &Context, cmd: vk::CommandBuffer, push: AlphaDrawPush) {
        unsafe {
            ctx.device.cmd_push_constants(
                cmd,
                self.pipeline_layout,
                GRAPHICS_STAGES,
                0,
                bytemuck::bytes_of(&push),
            );
        }
    }

    /// Draws each alpha mesh in its UV layout into its region of the position and normal
    /// atlases (cleared to w = 0: no probe).
    fn record_bake(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scene: &Scene,
        meshes: &Meshes,
    ) {
        ctx.begin_label(cmd, "alpha-probe-bake");
        for image in [&mut self.positions, &mut self.normals] {
            transition(
                ctx,
                cmd,
                image,
                ImageAccess::ColorAttachment,
                Contents::Discard,
            );
        }
        let colors = [
            color_attachment(&self.positions, Load::Clear(CLEAR_BLACK)),
            color_attachment(&self.normals, Load::Clear(CLEAR_BLACK)),
        ];
        begin_rendering(ctx, cmd, self.positions.extent, &colors, None);
        unsafe {
            ctx.device
                .cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.bake_pipeline);
        }
        apply(ctx, cmd, &FULLSCREEN);
        for (index, r) in self.layout.regions.iter().enumerate() {
            let EntityKey::Object(i) = r.entity else {
                continue;
            };
            set_region(ctx, cmd, r.region);
            self.push(
                ctx,
                cmd,
                AlphaDrawPush {
                    entity: index as u32,
                    ..Default::default()
                },
            );
            meshes
                .bake_shape(scene.alpha_objects[i].shape)
                .draw(ctx, cmd);
        }
        unsafe { ctx.device.cmd_end_rendering(cmd) };
        ctx.end_label(cmd);
    }

    /// Lights every entity's region: one additive draw per light that reaches it.
    fn record_lighting(&mut self, ctx: &Context, cmd: vk::CommandBuffer) {
        ctx.begin_label(cmd, "alpha-lightmaps");
        for image in [&mut self.positions, &mut self.normals] {
            transition(
                ctx,
                cmd,
                image,
                ImageAccess::FragmentSampled,
                Contents::Keep,
            );
        }
        transition(
            ctx,
            cmd,
            &mut self.lightmap,
            ImageAccess::ColorAttachment,
            Contents::Discard,
        );
        let colors = [color_attachment(&self.lightmap, Load::Clear(CLEAR_BLACK))];
        begin_rendering(ctx, cmd, self.lightmap.extent, &colors, None);
        unsafe {
            ctx.device.cmd_bind_pipeline(
                cmd,
                vk::PipelineBindPoint::GRAPHICS,
                self.lightmap_pipeline,
            );
        }
        apply(ctx, cmd, &FULLSCREEN);
        for (index, (r, lights)) in self
            .layout
            .regions
            .iter()
            .zip(&self.entity_lights)
            .enumerate()
        {
            if lights.is_empty() {
                continue;
            }
            let mut region = r.region;
            region.width = r.shape.tiles * r.shape.tile_width;
            set_region(ctx, cmd, region);
            for &light in lights {
                let push = AlphaDrawPush {
                    entity: index as u32,
                    light,
                    ..Default::default()
                };
                self.push(ctx, cmd, push);
                unsafe { ctx.device.cmd_draw(cmd, 3, 1, 0, 0) };
            }
        }
        unsafe { ctx.device.cmd_end_rendering(cmd) };
        ctx.end_label(cmd);
    }

    /// Blends the entities far to near over the lit frame in `targets.hdr`, lit as `mode` says.
    #[allow(clippy::too_many_arguments)]
    pub fn record_alpha(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scene: &Scene,
        meshes: &Meshes,
        targets: &mut Targets,
        frame_set: vk::DescriptorSet,
        (mode, extent, depth): (AlphaMode, vk::Extent2D, DepthConvention),
    ) {
        ctx.begin_label(cmd, "alpha");
        self.bind_sets(ctx, cmd, frame_set);
        // Forward and probe frames never write the lightmap; the transition still gives the
        // bound (and unread) image the layout its descriptor declares. An atlas no frame has
        // written yet is cleared first, so no read-only layout is entered from UNDEFINED.
        for image in [&mut self.positions, &mut self.normals, &mut self.lightmap] {
            if image.state.layout == vk::ImageLayout::UNDEFINED {
                transition(
                    ctx,
                    cmd,
                    image,
                    ImageAccess::ColorAttachment,
                    Contents::Discard,
                );
                let colors = [color_attachment(image, Load::Clear(CLEAR_BLACK))];
                begin_rendering(ctx, cmd, image.extent, &colors, None);
                unsafe { ctx.device.cmd_end_rendering(cmd) };
            }
            transition(
                ctx,
                cmd,
                image,
                ImageAccess::FragmentSampled,
                Contents::Keep,
            );
        }
        let attachments = (&mut *targets.hdr, &mut *targets.depth_stencil);
        begin_hdr_rendering(ctx, cmd, attachments, extent, Load::Keep, Load::Keep);
        let d = &ctx.device;
        let objects = scene.alpha_objects.len();
        for &entity in &self.order {
            match entity {
                EntityKey::Object(i) => {
                    unsafe {
                        d.cmd_bind_pipeline(
                            cmd,
                            vk::PipelineBindPoint::GRAPHICS,
                            self.object_pipeline,
                        );
                    }
                    apply(ctx, cmd, &oriented(ALPHA_OBJECTS, depth));
                    let push = AlphaDrawPush {
                        entity: i as u32,
                        mode: mode.code(),
                        ..Default::default()
                    };
                    self.push(ctx, cmd, push);
                    meshes.shape(scene.alpha_objects[i].shape).draw(ctx, cmd);
                }
                EntityKey::System(i) => {
                    let (first, count) = self.sprite_ranges[i];
                    unsafe {
                        d.cmd_bind_pipeline(
                            cmd,
                            vk::PipelineBindPoint::GRAPHICS,
                            self.particle_pipeline,
                        );
                        d.cmd_bind_vertex_buffers(cmd, 0, &[self.sprites.handle], &[0]);
                    }
                    apply(ctx, cmd, &oriented(PARTICLES, depth));
                    let push = AlphaDrawPush {
                        entity: (objects + i) as u32,
                        mode: mode.code(),
                        ..Default::default()
                    };
                    self.push(ctx, cmd, push);
                    unsafe { d.cmd_draw(cmd, count, 1, first, 0) };
                }
            }
        }
        unsafe { d.cmd_end_rendering(cmd) };
        ctx.end_label(cmd);
    }

    pub fn destroy(&mut self, ctx: &Context) {
        let mut parts = Parts {
            images: vec![],
            buffers: vec![],
            set_layouts: vec![self.alpha_set_layout, self.lightmap_set_layout],
            pipeline_layout: Some(self.pipeline_layout),
            pool: Some(self.pool),
            pipelines: vec![
                self.bake_pipeline,
                self.lightmap_pipeline,
                self.object_pipeline,
                self.particle_pipeline,
            ],
        };
        parts.destroy(ctx);
        for image in [&mut self.positions, &mut self.normals, &mut self.lightmap] {
            image.destroy(ctx);
        }
        for buffer in [
            &mut self.entities,
            &mut self.points,
            &mut self.light_list,
            &mut self.sprites,
        ] {
            buffer.destroy(ctx);
        }
    }
}

/// Viewport and scissor over one atlas region.
fn set_region(ctx: &Context, cmd: vk::CommandBuffer, r: histencil_alpha::Region) {
    let viewport = vk::Viewport {
        x: r.x as f32,
        y: r.y as f32,
        width: r.width as f32,
        height: r.height as f32,
        min_depth: 0.0,
        max_depth: 1.0,
    };
    let scissor = vk::Rect2D {
        offset: vk::Offset2D {
            x: r.x as i32,
            y: r.y as i32,
        },
        extent: vk::Extent2D {
            width: r.width,
            height: r.height,
        },
    };
    unsafe {
        ctx.device.cmd_set_viewport(cmd, 0, &[viewport]);
        ctx.device.cmd_set_scissor(cmd, 0, &[scissor]);
    }
}

/// A pool with one alpha set (three storage buffers, two sampled images) and one lightmap set.
fn create_sets(
    ctx: &Context,
    parts: &mut Parts,
    layouts: [vk::DescriptorSetLayout; 2],
) -> Result<(vk::DescriptorPool, vk::DescriptorSet, vk::DescriptorSet)> {
    let sizes = [
        vk::DescriptorPoolSize::default()
            .ty(vk::DescriptorType::STORAGE_BUFFER)
            .descriptor_count(3),
        vk::DescriptorPoolSize::default()
            .ty(vk::DescriptorType::SAMPLED_IMAGE)
            .descriptor_count(3),
    ];
    let info = vk::DescriptorPoolCreateInfo::default()
        .max_sets(2)
        .pool_sizes(&sizes);
    let pool =
        unsafe { ctx.device.create_descriptor_pool(&info, None) }.call("vkCreateDescriptorPool")?;
    ctx.name(pool, "alpha-descriptor-pool");
    parts.pool = Some(pool);
    let alloc = vk::DescriptorSetAllocateInfo::default()
        .descriptor_pool(pool)
        .set_layouts(&layouts);
    let sets =
        unsafe { ctx.device.allocate_descriptor_sets(&alloc) }.call("vkAllocateDescriptorSets")?;
    ctx.name(sets[0], "alpha-set");
    ctx.name(sets[1], "alpha-lightmap-set");
    Ok((pool, sets[0], sets[1]))
}

fn write_sampled_image(ctx: &Context, set: vk::DescriptorSet, binding: u32, view: vk::ImageView) {
    let info = [vk::DescriptorImageInfo::default()
        .image_view(view)
        .image_layout(vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL)];
    let write = vk::WriteDescriptorSet::default()
        .dst_set(set)
        .dst_binding(binding)
        .descriptor_type(vk::DescriptorType::SAMPLED_IMAGE)
        .image_info(&info);
    unsafe { ctx.device.update_descriptor_sets(&[write], &[]) };
}
