//! The talk's second technique on the GPU: translucent objects and particle systems lit through
//! per-entity lightmaps, then blended over the lit frame.
//!
//! Every frame: each entity's region of the lightmap atlas is lit by the lights that reach its
//! bounds, one additive draw per light with the deferred pass's light code (`lightmap.frag`,
//! recorded by [`AlphaLightmaps`], the part an engine uses on its own entities); then
//! histencil's alpha pass draws the entities far to near, sampling their regions
//! (`lightmap_sample.glsl`). An object's probes are baked on the CPU from its mesh's UV layout
//! ([`histencil_alpha::bake_probes`]); a particle system's follow the camera (a quad or slices
//! fitted around the system), a mote (dust), or the ribbon's control points, and
//! `lightmap.frag` computes them per texel.

mod gpu;
mod lightmap_checks;
pub(crate) mod lightmaps;

pub use gpu::AlphaEntityRecord;
pub use histencil_alpha::{mesh_bounds, AlphaEntity, AlphaEntityKind};
pub(crate) use lightmap_checks::check_lightmap_side;
pub use lightmap_checks::max_lightmap_side;
pub use lightmaps::{AlphaLightmaps, AlphaLightmapsDesc, LightmapFrame};

use crate::gpu::access::{Contents, ImageAccess};
use crate::gpu::device::context::Context;
use crate::gpu::device::descriptors::{
    binding, create_pipeline_layout, create_set_layout, write_sampled_images, BindingDesc,
    BindingKind, GRAPHICS_STAGES,
};
use crate::gpu::device::error::{Result, VkCall};
use crate::gpu::device::pipelines::{create_pipeline, Blend, PipelineDesc, VertexInput};
use crate::gpu::device::resources::{Buffer, Image};
use crate::gpu::encoder::meshes::Meshes;
use crate::gpu::encoder::recording::Recording;
use crate::gpu::encoder::timing::LightmapTimings;
use crate::gpu::frame::attachments::{begin_cleared, begin_hdr_rendering, Load, CLEAR_BLACK};
use crate::gpu::frame::state::{oriented, FULLSCREEN};
use crate::gpu::frame::targets::{Targets, HDR_FORMAT};
use crate::shader_consts::ALPHA_MODES;
use crate::shaders;
use ash::vk;
use gpu::AlphaDrawPush;
use histencil_alpha::{
    back_to_front, plan_layout, scene_alpha_entities, sprite_vertices, AlphaPlan, EntityKey,
    LightmapLayout, Parameters, ProbeMeshes, SpriteVertex,
};
use histencil_model::{CompareOp, CullMode, DepthConvention, DepthState, PassState, ViewDesc};
use histencil_scene::Scene;

/// Set 2 of the alpha pass (include/alpha_lightmap.glsl): the lightmap atlas. A set of its own
/// because the lightmap pass renders into it.
pub(crate) const ALPHA_LIGHTMAP_SET: &[BindingDesc] = &[
    binding(0, BindingKind::SampledImage, "lightmap"),
    binding(1, BindingKind::SampledImage, "direction_map"),
    binding(2, BindingKind::Sampler, "lightmap_sampler"),
];

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
    /// The talk's first improvement: lightmaps of the light arriving at each probe with a
    /// second atlas of its dominant direction, so each fragment evaluates its own BRDF with its
    /// own normal and view ([`AlphaLightmaps::record_directional`]).
    Directional,
}

impl AlphaMode {
    /// The mode's `ALPHA_MODE_*` value: the alpha pipelines' specialisation constant.
    fn code(self) -> u32 {
        let name = match self {
            AlphaMode::Lightmap => "ALPHA_MODE_LIGHTMAP",
            AlphaMode::Forward => "ALPHA_MODE_FORWARD",
            AlphaMode::Probe => "ALPHA_MODE_PROBE",
            AlphaMode::Directional => "ALPHA_MODE_DIRECTIONAL",
        };
        ALPHA_MODES
            .iter()
            .find(|(n, _)| *n == name)
            .expect("known mode")
            .1
    }
}

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

/// What histencil's alpha pass draws in one frame.
#[derive(Clone, Copy)]
pub(crate) struct AlphaInputs<'a> {
    pub scene: &'a Scene,
    pub meshes: &'a Meshes,
    /// Set 0: the frame's uniforms and lights.
    pub frame_set: vk::DescriptorSet,
    pub mode: AlphaMode,
    pub extent: vk::Extent2D,
    pub depth: DepthConvention,
}

/// A scene's alpha entities on the GPU: the lightmaps (as an engine records them), the atlas,
/// the sprites and histencil's alpha pass.
pub(crate) struct AlphaLighting<'c> {
    layout: LightmapLayout,
    /// Each entity's slices and side, and the error estimate behind them.
    parameters: Vec<Parameters>,
    probe_meshes: ProbeMeshes,
    /// Blending order.
    order: Vec<EntityKey>,
    /// Per particle system: its first sprite vertex and vertex count.
    sprite_ranges: Vec<(u32, u32)>,
    lightmap_draws: usize,
    lightmaps: AlphaLightmaps<&'c Context>,
    lightmap: Image,
    /// The direction map of directional frames, as large as the atlas.
    direction_map: Image,
    sprites: Buffer,
    lightmap_set_layout: vk::DescriptorSetLayout,
    pipeline_layout: vk::PipelineLayout,
    pool: vk::DescriptorPool,
    lightmap_set: vk::DescriptorSet,
    /// Bilinear, clamp to edge: how the alpha pass reads the atlas (lightmap_sample.glsl).
    sampler: vk::Sampler,
    /// Per [`AlphaMode`] (in `AlphaMode::code` order), the object and particle pipelines,
    /// made when a frame first uses the mode.
    pipelines: [Option<[vk::Pipeline; 2]>; 4],
}

/// The alpha pass's own Vulkan objects, created step by step so a failure part-way destroys what
/// exists.
#[derive(Default)]
struct Parts {
    images: Vec<Image>,
    buffers: Vec<Buffer>,
    set_layouts: Vec<vk::DescriptorSetLayout>,
    pipeline_layout: Option<vk::PipelineLayout>,
    pool: Option<vk::DescriptorPool>,
    sampler: Option<vk::Sampler>,
    pipelines: Vec<vk::Pipeline>,
}

impl Parts {
    fn destroy(&mut self, ctx: &Context) {
        let d = &ctx.device;
        // SAFETY: each handle was made from this device by `AlphaLighting::create` and is taken
        // out as it goes, so none is destroyed twice; the GPU is done with them: a creation that
        // failed recorded nothing, and `AlphaLighting::destroy` waits for the device first.
        unsafe {
            if let Some(s) = self.sampler.take() {
                d.destroy_sampler(s, None);
            }
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

impl<'c> AlphaLighting<'c> {
    /// Plans the lightmap layout for `scene` seen at `extent` (region sides from coverage, or
    /// `forced_side`), and creates the lightmaps, the atlas, the sprites and the pipelines.
    ///
    /// # Errors
    /// [`crate::Error::Lightmap`] when the layout cannot be planned (bad forced side, atlas
    /// full), besides Vulkan errors.
    pub fn new(
        ctx: &'c Context,
        scene: &Scene,
        extent: vk::Extent2D,
        forced_side: Option<u32>,
        frame_layout: vk::DescriptorSetLayout,
        modules: &'static crate::BrdfModules,
    ) -> Result<Self> {
        let max_side = histencil_alpha::MAX_ATLAS_SIDE.min(ctx.max_image_dimension);
        let plan = plan_layout(scene, extent.height, forced_side, max_side)?;
        let lightmaps = AlphaLightmaps::with_modules(
            ctx,
            &AlphaLightmapsDesc {
                atlas_format: LIGHTMAP_FORMAT,
                frames_in_flight: 1,
                direction_format: Some(LIGHTMAP_FORMAT),
            },
            modules,
        )?;
        let mut parts = Parts::default();
        match Self::create(ctx, scene, plan, lightmaps, frame_layout, &mut parts) {
            Ok(built) => Ok(built),
            Err(e) => {
                parts.destroy(ctx);
                Err(e)
            }
        }
    }

    fn create(
        ctx: &'c Context,
        scene: &Scene,
        AlphaPlan { layout, parameters }: AlphaPlan,
        lightmaps: AlphaLightmaps<&'c Context>,
        frame_layout: vk::DescriptorSetLayout,
        parts: &mut Parts,
    ) -> Result<Self> {
        let (w, h) = layout.atlas.size();
        let extent = vk::Extent2D {
            width: w,
            height: h,
        };
        use vk::ImageUsageFlags as U;
        for name in ["alpha-lightmap-atlas", "alpha-direction-map"] {
            parts.images.push(Image::new(
                ctx,
                name,
                LIGHTMAP_FORMAT,
                extent,
                U::COLOR_ATTACHMENT | U::SAMPLED,
            )?);
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
            &[
                frame_layout,
                lightmaps.alpha_set_layout(),
                lightmap_set_layout,
            ],
            GRAPHICS_STAGES,
            size_of::<AlphaDrawPush>() as u32,
        )?;
        parts.pipeline_layout = Some(pipeline_layout);
        let (pool, lightmap_set) = create_lightmap_set(ctx, parts, lightmap_set_layout)?;

        let sampler = create_sampler(ctx)?;
        parts.sampler = Some(sampler);
        write_lightmap_set(
            ctx,
            lightmap_set,
            [parts.images[0].view, parts.images[1].view],
            sampler,
        );

        let probe_meshes = ProbeMeshes::new(scene);
        let lightmap_draws = scene_alpha_entities(scene, &probe_meshes)
            .iter()
            .map(|e| e.lights_reaching(&scene.lights).len())
            .sum();
        let order = back_to_front(scene);
        let direction_map = parts.images.pop().expect("the direction map");
        let lightmap = parts.images.pop().expect("the atlas");
        let sprites = parts.buffers.pop().expect("the sprites");
        let built = Self {
            layout,
            parameters,
            probe_meshes,
            order,
            sprite_ranges,
            lightmap_draws,
            lightmaps,
            lightmap,
            direction_map,
            sprites,
            lightmap_set_layout,
            pipeline_layout,
            pool,
            lightmap_set,
            sampler,
            pipelines: [None; 4],
        };
        *parts = Parts::default();
        Ok(built)
    }

    /// The planned layout: atlas size and each entity's region.
    pub fn layout(&self) -> &LightmapLayout {
        &self.layout
    }

    /// Each entity's slices and side and the estimate behind them, in entity order.
    pub fn parameters(&self) -> &[Parameters] {
        &self.parameters
    }

    /// How many lightmap draws a frame makes: one per (entity, light that reaches it).
    pub fn lightmap_draws(&self) -> usize {
        self.lightmap_draws
    }

    /// Writes the frame's entity records (every mode reads them) and, in the lightmap modes,
    /// records the lightmap pass through `rec` (the body the lightmaps' entry points share, so
    /// what an engine records is what this records; `rec`'s clock times it), with per-entity
    /// timestamps if asked ([`Self::lightmap_timings`]).
    pub fn record_lightmaps(
        &mut self,
        rec: &Recording,
        scene: &Scene,
        view: &ViewDesc,
        mode: AlphaMode,
        timestamps: bool,
    ) -> Result<()> {
        let entities = scene_alpha_entities(scene, &self.probe_meshes);
        let lit = matches!(mode, AlphaMode::Lightmap | AlphaMode::Directional);
        let frame = LightmapFrame {
            slot: 0,
            view,
            lights: &scene.lights,
            entities: &entities,
            layout: &self.layout,
            // Only a recorded pass writes its queries.
            timestamps: timestamps && lit,
        };
        // SAFETY: the renderer, this lighting's one user, waits for each frame it submits
        // before it records the next, and records nothing after a wait that failed
        // (`Renderer::begin_commands`): slot 0's last frame has finished.
        unsafe { self.lightmaps.slot_finished(0)? };
        self.lightmaps
            .write_frame(rec.outside(), &frame, &self.lightmap)?;
        let direction = match mode {
            AlphaMode::Lightmap => None,
            AlphaMode::Directional => Some(&mut *self.direction_map),
            AlphaMode::Forward | AlphaMode::Probe => return Ok(()),
        };
        // SAFETY: the renderer's command buffer is recording on this device, outside rendering
        // between its passes (`Renderer::record_deferred` and the alpha pass after it), and
        // the lightmaps record through `rec`, its one recording.
        unsafe {
            let (cmd, layout) = (rec.outside(), (0, &self.layout));
            let lightmaps = &mut self.lightmaps;
            lightmaps.record_pass(cmd, layout, &mut self.lightmap, direction, Some(rec))
        };
        Ok(())
    }

    /// The lightmap pass's GPU times of the last frame, once it has finished: `None` unless
    /// it recorded lightmaps with timestamps.
    pub fn lightmap_timings(&self) -> Result<Option<LightmapTimings>> {
        self.lightmaps.timings(0)
    }

    fn push(&self, rec: &Recording, push: AlphaDrawPush) {
        // SAFETY: `record_alpha`, the one caller, pushes inside its HDR rendering with a
        // pipeline of this layout bound; the push is `AlphaDrawPush` at offset 0, the layout's
        // graphics-stage range.
        unsafe {
            rec.push(
                self.pipeline_layout,
                GRAPHICS_STAGES,
                0,
                bytemuck::bytes_of(&push),
            )
        };
    }

    /// The object and particle pipelines of `mode`, made on first use.
    fn pipelines(&mut self, ctx: &Context, mode: AlphaMode) -> Result<[vk::Pipeline; 2]> {
        let slot = mode.code() as usize;
        if let Some(made) = self.pipelines[slot] {
            return Ok(made);
        }
        // The alpha pass: blended over the lit HDR frame, tested against its depth.
        let hdr = [HDR_FORMAT];
        let specialization = [
            u32::from(mode == AlphaMode::Forward),
            u32::from(mode == AlphaMode::Probe),
            u32::from(mode == AlphaMode::Directional),
        ];
        let objects = PipelineDesc {
            name: "alpha-object-pipeline",
            vertex: ("alpha_object.vert", shaders::ALPHA_OBJECT_VERT),
            fragment: Some(("alpha_object.frag", self.lightmaps.modules().alpha_object)),
            layout: self.pipeline_layout,
            vertex_input: VertexInput::PositionNormalUv,
            color_formats: &hdr,
            color_writes: true,
            blend: Blend::PremultipliedOver,
            depth_stencil_format: ctx.depth_stencil_format,
            depth_clamp: false,
            specialization: &specialization,
        };
        let particles = PipelineDesc {
            name: "alpha-particle-pipeline",
            vertex: ("particle.vert", shaders::PARTICLE_VERT),
            fragment: Some(("particle.frag", self.lightmaps.modules().particle)),
            vertex_input: VertexInput::Sprite,
            ..objects
        };
        let object = create_pipeline(ctx, &objects)?;
        let particle = match create_pipeline(ctx, &particles) {
            Ok(p) => p,
            Err(e) => {
                // SAFETY: `object` was made just above from this device and never recorded.
                unsafe { ctx.device.destroy_pipeline(object, None) };
                return Err(e);
            }
        };
        self.pipelines[slot] = Some([object, particle]);
        Ok([object, particle])
    }

    /// Blends the entities far to near over the lit frame in `targets.hdr`, lit as
    /// `inputs.mode` says.
    ///
    /// # Errors
    /// Pipeline creation errors, the first time a mode is used; nothing is recorded then.
    pub fn record_alpha(
        &mut self,
        rec: &Recording,
        inputs: &AlphaInputs,
        targets: &mut Targets,
    ) -> Result<()> {
        let AlphaInputs {
            scene,
            meshes,
            frame_set,
            mode,
            extent,
            depth,
        } = *inputs;
        let [object_pipeline, particle_pipeline] = self.pipelines(rec.ctx(), mode)?;
        rec.pass(crate::passes::names::ALPHA, |rec| {
            // SAFETY: the sets match the layout's sets 0 to 2 (`create` made it from their
            // layouts): the renderer's frame set, the lightmaps' slot 0 alpha set (written by
            // `record_lightmaps` this frame) and the lightmap set; all live as long as `self`.
            unsafe {
                let sets = [frame_set, self.lightmaps.alpha_set(0), self.lightmap_set];
                let graphics = vk::PipelineBindPoint::GRAPHICS;
                rec.bind_sets(graphics, self.pipeline_layout, 0, &sets);
            }
            // Forward and probe frames never write the atlas, nor plain lightmap frames the
            // direction map; the transition still gives each bound (and unread) image the layout its
            // descriptor declares. An image no frame has written yet is cleared first, so no
            // read-only layout is entered from UNDEFINED.
            for image in [&mut self.lightmap, &mut self.direction_map] {
                if image.state.layout == vk::ImageLayout::UNDEFINED {
                    begin_cleared(rec, image, CLEAR_BLACK);
                    rec.end_rendering();
                }
                rec.transition(image, ImageAccess::FragmentSampled, Contents::Keep);
            }
            let attachments = (&mut *targets.hdr, &mut *targets.depth_stencil);
            begin_hdr_rendering(rec, attachments, extent, Load::Keep, Load::Keep);
            let graphics = vk::PipelineBindPoint::GRAPHICS;
            let objects = scene.alpha_objects.len();
            for &entity in &self.order {
                match entity {
                    EntityKey::Object(i) => {
                        // SAFETY: inside the HDR rendering begun above, whose attachments' formats
                        // (HDR_FORMAT, the context's depth-stencil) the pipeline was made for; it
                        // lives in `self.pipelines` until `destroy`.
                        unsafe { rec.bind_pipeline(graphics, object_pipeline) };
                        rec.apply(&oriented(ALPHA_OBJECTS, depth));
                        let push = AlphaDrawPush {
                            entity: i as u32,
                            ..Default::default()
                        };
                        self.push(rec, push);
                        meshes.shape(scene.alpha_objects[i].shape).draw(rec);
                    }
                    EntityKey::System(i) => {
                        let (first, count) = self.sprite_ranges[i];
                        // SAFETY: as for the object pipeline above; `sprites` is a live vertex
                        // buffer of this device (`VERTEX_BUFFER` usage, made by `create`).
                        unsafe {
                            rec.bind_pipeline(graphics, particle_pipeline);
                            rec.bind_vertex_buffer(self.sprites.handle);
                        }
                        rec.apply(&oriented(PARTICLES, depth));
                        let push = AlphaDrawPush {
                            entity: (objects + i) as u32,
                            ..Default::default()
                        };
                        self.push(rec, push);
                        // SAFETY: the particle pipeline, sets, sprites and dynamic state are bound
                        // and set above; `first..first + count` is this system's range of the
                        // sprite buffer (`sprite_ranges`, from `create`).
                        unsafe { rec.draw(count, first) };
                    }
                }
            }
            rec.end_rendering();
        });
        Ok(())
    }

    /// Frees the alpha pass's own objects; the lightmaps free theirs when dropped.
    /// Every slot of its lightmaps finished (the renderer's drop, after its wait).
    ///
    /// # Safety
    /// As [`AlphaLightmaps::all_finished`]'s.
    pub(crate) unsafe fn all_finished(&mut self) {
        // SAFETY: this fn's # Safety.
        unsafe { self.lightmaps.all_finished() };
    }

    pub fn destroy(&mut self, ctx: &Context) {
        let mut parts = Parts {
            images: vec![],
            buffers: vec![],
            set_layouts: vec![self.lightmap_set_layout],
            pipeline_layout: Some(self.pipeline_layout),
            pool: Some(self.pool),
            sampler: Some(self.sampler),
            pipelines: self.pipelines.iter().flatten().flatten().copied().collect(),
        };
        // The one caller is the renderer's Drop, which has just made the same wait (see there).
        let _ = ctx.wait_idle();
        parts.destroy(ctx);
        self.lightmap.destroy(ctx);
        self.direction_map.destroy(ctx);
        self.sprites.destroy(ctx);
    }
}

/// The atlas sampler: bilinear, clamp to edge, one mip level.
fn create_sampler(ctx: &Context) -> Result<vk::Sampler> {
    let info = vk::SamplerCreateInfo::default()
        .mag_filter(vk::Filter::LINEAR)
        .min_filter(vk::Filter::LINEAR)
        .mipmap_mode(vk::SamplerMipmapMode::NEAREST)
        .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
        .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
        .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE)
        .max_lod(0.0);
    // SAFETY: a plain create info (no anisotropy, no compare, no chained structs), valid for
    // the call.
    let sampler = unsafe { ctx.device.create_sampler(&info, None) }.call("vkCreateSampler")?;
    ctx.name(sampler, "alpha-lightmap-sampler");
    Ok(sampler)
}

/// A pool with the alpha pass's lightmap set (the atlas, the direction map, their sampler).
fn create_lightmap_set(
    ctx: &Context,
    parts: &mut Parts,
    layout: vk::DescriptorSetLayout,
) -> Result<(vk::DescriptorPool, vk::DescriptorSet)> {
    let sizes = crate::gpu::device::descriptors::pool_sizes(&[(ALPHA_LIGHTMAP_SET, 1)]);
    let info = vk::DescriptorPoolCreateInfo::default()
        .max_sets(1)
        .pool_sizes(&sizes);
    // SAFETY: `info` and `sizes` outlive the call; one set, and every count non-zero.
    let pool =
        unsafe { ctx.device.create_descriptor_pool(&info, None) }.call("vkCreateDescriptorPool")?;
    ctx.name(pool, "alpha-descriptor-pool");
    parts.pool = Some(pool);
    let layouts = [layout];
    let alloc = vk::DescriptorSetAllocateInfo::default()
        .descriptor_pool(pool)
        .set_layouts(&layouts);
    // SAFETY: `pool` was made just above from this device with room for this one set of
    // `layout`, the caller's live `ALPHA_LIGHTMAP_SET` layout.
    let sets =
        unsafe { ctx.device.allocate_descriptor_sets(&alloc) }.call("vkAllocateDescriptorSets")?;
    ctx.name(sets[0], "alpha-lightmap-set");
    Ok((pool, sets[0]))
}

/// The atlas and the direction map at bindings 0 and 1, the sampler at 2
/// (include/alpha_lightmap.glsl).
fn write_lightmap_set(
    ctx: &Context,
    set: vk::DescriptorSet,
    images: [vk::ImageView; 2],
    sampler: vk::Sampler,
) {
    write_sampled_images(ctx, set, &images);
    let filter = [vk::DescriptorImageInfo::default().sampler(sampler)];
    let write = vk::WriteDescriptorSet::default()
        .dst_set(set)
        .dst_binding(2)
        .descriptor_type(vk::DescriptorType::SAMPLER)
        .image_info(&filter);
    // SAFETY: `set` was just allocated (`create_lightmap_set`) and no command buffer uses it;
    // binding 2 is the layout's sampler (`ALPHA_LIGHTMAP_SET`) and `sampler` is live.
    unsafe { crate::gpu::device::descriptors::update_sets(ctx, &[write]) };
}
