//! How a renderer is made and unmade: the scene validated, the layout and materials derived,
//! every resource created (a failure half way frees what was made), and all of it freed in
//! order at drop.

use super::{Renderer, RendererDesc};
use crate::gpu::device::context::Context;
use crate::gpu::device::descriptors::Descriptors;
use crate::gpu::device::error::{Result, VkCall};
use crate::gpu::device::resources::Buffer;
use crate::gpu::device::teardown::{build, Destroy, Owned};
use crate::gpu::encoder::meshes::Meshes;
use crate::gpu::encoder::timing::Timestamps;
use crate::gpu::frame::gpu_types::{FrameUniforms, GpuLight};
use crate::gpu::frame::readback::ReadbackBuffers;
use crate::gpu::frame::targets::{check_extent, Targets, GBUFFER_FORMATS, HDR_FORMAT, LDR_FORMAT};
use crate::lighting::hooks::LightHooks;
use crate::lighting::{DeferredLighting, LightingDesc};
use crate::passes::geometry::{MeshFormats, MeshPasses};
use crate::passes::tonemap::Tonemap;
use crate::renderer::materials::GpuMaterials;
use ash::vk;
use histencil_brdf::lut::Lut;
use histencil_brdf::{Brdf, BrdfId};
use histencil_model::StencilLayout;
use histencil_scene::Scene;

/// The distinct BRDF materials of `scene` in first-use order (the LUT technique's tables) and
/// each object's index among them.
fn distinct_materials(scene: &Scene) -> (Vec<Brdf>, Vec<u32>) {
    let mut materials: Vec<Brdf> = Vec::new();
    let indices = scene
        .objects
        .iter()
        .map(|o| {
            let brdf = o.material.brdf;
            let index = materials
                .iter()
                .position(|m| *m == brdf)
                .unwrap_or_else(|| {
                    materials.push(brdf);
                    materials.len() - 1
                });
            index as u32
        })
        .collect();
    (materials, indices)
}

/// Every object's and entity's BRDF is one of `set`'s, with its parameters in their ranges: a
/// BRDF the shaders were not compiled with would shade black in silence.
fn check_brdfs(scene: &Scene, set: &histencil_brdf::BrdfSet) -> Result<()> {
    let objects = scene.objects.iter().map(|o| (&o.name, &o.material.brdf));
    let alpha = scene
        .alpha_objects
        .iter()
        .map(|o| (&o.name, &o.material.brdf));
    let particles = scene
        .particle_systems
        .iter()
        .map(|p| (&p.name, &p.material.brdf));
    for (name, brdf) in objects.chain(alpha).chain(particles) {
        set.check(brdf)
            .map_err(|e| crate::Error::BrdfSet(format!("{name}: {e}")))?;
    }
    Ok(())
}

/// The stencil slot of BRDF `id`: its index among the BRDFs in use (as
/// [`crate::LightingDesc::slot_of`] numbers them).
fn slot_of(brdfs: &[BrdfId], id: BrdfId) -> u32 {
    brdfs
        .iter()
        .position(|b| *b == id)
        .expect("brdfs_in_use lists every object's BRDF") as u32
}

impl<'c> Renderer<'c> {
    /// Validates the scene and the resolution, then builds everything a frame needs, with the
    /// defaults of [`RendererDesc::new`].
    pub fn new(ctx: &'c Context, scene: Scene, width: u32, height: u32) -> Result<Self> {
        Self::with_desc(ctx, scene, &RendererDesc::new(width, height))
    }

    /// Validates `desc` and the scene, then builds everything a frame needs.
    ///
    /// # Errors
    /// Before anything is made: [`crate::Error::BadResolution`] for a size the device cannot
    /// render, [`crate::Error::Lut`] for a table resolution outside
    /// `2..=`[`Lut::MAX_RESOLUTION`], [`crate::Error::Lightmap`] for a lightmap side outside
    /// `2..=`[`histencil_alpha::MAX_FORCED_SIDE`], [`crate::Error::DeviceLimit`] for one past
    /// [`crate::max_lightmap_side`] (the device's storage-buffer range), the scene's own errors, and
    /// [`crate::Error::Layout`] when its BRDFs do not fit the stencil bits. Then any error of
    /// making the resources, after freeing what was made.
    pub fn with_desc(ctx: &'c Context, mut scene: Scene, desc: &RendererDesc) -> Result<Self> {
        let (width, height) = (desc.width, desc.height);
        // The resolution first: a scene built for a zero-sized view (a lab wall) would otherwise
        // take the blame for it.
        let extent = check_extent(ctx, width, height)?;
        Lut::check_resolution(desc.lut_resolution)?;
        if let Some(side) = desc.lightmap_side {
            histencil_alpha::check_forced_side(side)?;
            crate::alpha::check_lightmap_side(ctx, side)?;
        }
        scene.validate()?;
        check_brdfs(&scene, &desc.brdfs.set)?;
        crate::brdf_modules::probe_finite(ctx, desc.brdfs)?;
        let materials: Vec<_> = (scene.objects.iter().map(|o| &o.material))
            .chain(scene.alpha_objects.iter().map(|o| &o.material))
            .map(|m| (m.brdf, m.tint.to_array()))
            .collect();
        crate::brdf_modules::probe_materials(ctx, desc.brdfs, &materials)?;
        crate::renderer::materials::check_images(ctx, &scene)?;
        scene.normalise_lights();
        let brdfs: Vec<BrdfId> = scene.brdfs_in_use();
        let brdf_count = brdfs.len().max(1) as u32;
        let stencil_layout = match desc.stencil_bits {
            None => StencilLayout::new(brdf_count, 0)?,
            Some(bits) => StencilLayout::with_positions(brdf_count, bits)?,
        };
        let object_slots = scene
            .objects
            .iter()
            .map(|o| slot_of(&brdfs, o.material.brdf.id()))
            .collect();
        let (materials, object_materials) = distinct_materials(&scene);

        let lighting = DeferredLighting::new(
            ctx,
            &LightingDesc {
                layout: stencil_layout,
                brdfs: brdfs.clone(),
                extent,
                depth_stencil_format: ctx.depth_stencil_format,
                hdr_format: HDR_FORMAT,
                frames_in_flight: 1,
                max_lights: scene.lights.len() as u32,
                hi_stencil: true,
                hooks: if desc.brdfs.is_builtin() {
                    LightHooks::Builtin
                } else {
                    LightHooks::BuiltinWithBrdfs(desc.brdfs.light)
                },
            },
        )?;
        // Each part is destroyed if a later one fails; `keep` hands it to the renderer.
        let targets = Owned::new(ctx, Targets::new(ctx, extent)?);
        let meshes = Owned::new(ctx, Meshes::new(ctx, &scene.meshes)?);
        let uniforms = FrameUniforms::new(&scene.camera, width, height, scene.lights.len() as u32);
        let frame_uniforms = Owned::new(
            ctx,
            Buffer::with_data(
                ctx,
                "frame-uniforms",
                vk::BufferUsageFlags::UNIFORM_BUFFER,
                bytemuck::bytes_of(&uniforms),
            )?,
        );
        let gpu_lights: Vec<GpuLight> = scene.lights.iter().map(GpuLight::new).collect();
        let lights = Owned::new(
            ctx,
            Buffer::with_data(
                ctx,
                "scene-lights",
                vk::BufferUsageFlags::STORAGE_BUFFER,
                bytemuck::cast_slice(&gpu_lights),
            )?,
        );
        let descriptors = Owned::new(
            ctx,
            Descriptors::new(ctx, frame_uniforms.handle, lights.handle)?,
        );
        let frame_layout = descriptors.frame_layout;
        let formats = MeshFormats {
            gbuffer: GBUFFER_FORMATS,
            hdr: HDR_FORMAT,
            depth_stencil: ctx.depth_stencil_format,
        };
        let mesh_passes = Owned::new(
            ctx,
            MeshPasses::new(ctx, frame_layout, &formats, desc.brdfs.forward)?,
        );
        let maps = Owned::new(
            ctx,
            GpuMaterials::new(ctx, &scene, mesh_passes.material_layout)?,
        );
        let tonemap = Owned::new(
            ctx,
            Tonemap::new(ctx, frame_layout, LDR_FORMAT, targets.hdr.view)?,
        );
        let submission = Owned::new(ctx, FrameSubmission::new(ctx)?);
        let timestamps = Owned::new(ctx, Timestamps::new(ctx)?);
        let readback = ReadbackBuffers::new(ctx, extent)?;
        let FrameSubmission {
            command_pool,
            cmd,
            fence,
        } = submission.keep();
        Ok(Self {
            ctx,
            scene,
            stencil_layout,
            brdfs,
            object_slots,
            materials,
            object_materials,
            desc: *desc,
            lut_tables: None,
            alpha: None,
            lighting,
            extent,
            targets: targets.keep(),
            meshes: meshes.keep(),
            maps: maps.keep(),
            frame_uniforms: frame_uniforms.keep(),
            lights: lights.keep(),
            descriptors: descriptors.keep(),
            mesh_passes: mesh_passes.keep(),
            tonemap: tonemap.keep(),
            command_pool,
            cmd,
            fence,
            unfinished: std::cell::Cell::new(None),
            timestamps: timestamps.keep(),
            readback,
        })
    }
}

/// The renderer's own submission: one command buffer, re-recorded each frame, and its fence.
#[derive(Default)]
struct FrameSubmission {
    command_pool: vk::CommandPool,
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
}

impl FrameSubmission {
    fn new(ctx: &Context) -> Result<Self> {
        build(ctx, |s: &mut Self| {
            let pool_info =
                vk::CommandPoolCreateInfo::default().queue_family_index(ctx.queue_family);
            // SAFETY: `pool_info` is valid for the call and names the context's queue family,
            // one of this device's.
            s.command_pool = unsafe { ctx.device.create_command_pool(&pool_info, None) }
                .call("vkCreateCommandPool")?;
            ctx.name(s.command_pool, "frame-command-pool");
            let alloc = vk::CommandBufferAllocateInfo::default()
                .command_pool(s.command_pool)
                .level(vk::CommandBufferLevel::PRIMARY)
                .command_buffer_count(1);
            // SAFETY: the pool was made just above from this device and is used by nothing else
            // yet (it is not shared with another thread).
            s.cmd = unsafe { ctx.device.allocate_command_buffers(&alloc) }
                .call("vkAllocateCommandBuffers")?[0];
            ctx.name(s.cmd, "frame-commands");
            // SAFETY: a default (unsignalled) fence create info, valid for the call.
            s.fence = unsafe {
                ctx.device
                    .create_fence(&vk::FenceCreateInfo::default(), None)
            }
            .call("vkCreateFence")?;
            ctx.name(s.fence, "frame-fence");
            Ok(())
        })
    }
}

impl Destroy for FrameSubmission {
    fn destroy(&mut self, ctx: &Context) {
        // SAFETY: the handles are null or were made by `new` from this device; only a failed
        // `new` (`build`) or `Renderer::with_desc` (`Owned`) destroys through here, before the
        // command buffer was ever submitted, so no queue uses the fence or the pool.
        unsafe {
            ctx.device.destroy_fence(self.fence, None);
            ctx.device.destroy_command_pool(self.command_pool, None);
        }
        *self = Self::default();
    }
}

impl Drop for Renderer<'_> {
    fn drop(&mut self) {
        let ctx = self.ctx;
        // The wait needs every queue of the device unused meanwhile: this renderer submits
        // nothing now, other renderers and lightings on the context wait for the queue's lock
        // (`Context::wait_idle`), and a lent device's other users are kept off by
        // `Context::from_raw`'s # Safety.
        let _ = ctx.wait_idle();
        // SAFETY: the fence and the pool were made from this device by `FrameSubmission::new`
        // and are destroyed only here; the wait above left the GPU done with them (a lost
        // device, whose error is ignored, runs nothing more).
        unsafe {
            ctx.device.destroy_fence(self.fence, None);
            ctx.device.destroy_command_pool(self.command_pool, None);
        }
        // SAFETY: the wait above left the GPU done with every frame the renderer recorded,
        // also one whose submission failed part way (a memory budget reached): the lighting
        // frees its objects now instead of leaving them to the context.
        unsafe { self.lighting.all_finished() };
        if let Some(a) = self.alpha.as_mut() {
            // SAFETY: as above.
            unsafe { a.all_finished() };
        }
        self.timestamps.destroy(ctx);
        self.readback.destroy(ctx);
        self.tonemap.destroy(ctx);
        if let Some(t) = self.lut_tables.take() {
            // SAFETY: `LutTables::destroy`'s # Safety holds: the device was waited idle above,
            // so every frame recorded with the tables has finished.
            unsafe { t.destroy() };
        }
        if let Some(a) = self.alpha.as_mut() {
            a.destroy(ctx);
        }
        self.maps.destroy(ctx);
        self.mesh_passes.destroy(ctx);
        self.descriptors.destroy(ctx);
        self.lights.destroy(ctx);
        self.frame_uniforms.destroy(ctx);
        self.meshes.destroy(ctx);
        self.targets.destroy(ctx);
    }
}
