//! The renderer: owns a scene's GPU resources and records / submits whole frames. This file
//! holds what it owns and what it is built with (`RendererDesc`); `create.rs` how it is made
//! and freed, `plan.rs` how a frame is planned, `frame.rs` the order of a frame's passes,
//! `simulator.rs` what the CPU simulator is given.

pub(crate) mod capture;
mod create;
mod frame;
pub(crate) mod materials;
mod plan;
pub(crate) mod platform;
mod simulator;
pub(crate) mod technique;

use crate::alpha::AlphaLighting;
use crate::gpu::device::context::Context;
use crate::gpu::device::descriptors::Descriptors;
use crate::gpu::device::error::Result;
use crate::gpu::device::resources::Buffer;
use crate::gpu::encoder::meshes::Meshes;
use crate::gpu::encoder::timing::{FrameTimings, Timestamps};
use crate::gpu::frame::readback::{FrameImages, ReadbackBuffers};
use crate::gpu::frame::targets::Targets;
use crate::lighting::lut::LutTables;
use crate::lighting::DeferredLighting;
use crate::passes::geometry::MeshPasses;
use crate::passes::tonemap::Tonemap;
use crate::renderer::materials::GpuMaterials;
use crate::renderer::technique::Backend;
use ash::vk;
use histencil_brdf::{Brdf, BrdfId};
use histencil_model::{CostModel, StencilBits, StencilLayout, TalkFigures, TileStats};
use histencil_scene::Scene;

/// The LUT technique's table resolution unless [`RendererDesc::lut_resolution`] says otherwise:
/// the `brdf-report` tables put the broad lobes within about 1e-3 of their formula at 32
/// points per axis (the sharp ones need more, see the README), at 384 KiB per 3D table.
pub const DEFAULT_LUT_RESOLUTION: u32 = 32;

/// The talk gives no fixed cost per draw; the default cost model assumes this one.
const ASSUMED_DRAW_OVERHEAD_MS: f64 = 0.005;

/// The most materials the G-buffer can index: integers are exact in its f16 alpha up to here.
const MAX_MATERIALS: usize = 2048;

/// A rendered frame: its GPU timings, the images asked for, and the hi-stencil statistics when
/// [`crate::FrameDesc::tile_stats`] asks for them (deferred techniques only).
pub struct Frame {
    /// GPU time per pass, read from the frame's timestamps.
    pub timings: FrameTimings,
    /// The images [`crate::FrameDesc::readback`] asked for; the others are `None`.
    pub images: FrameImages,
    /// Tiles tested and culled, fragments shaded, flushes; `None` unless asked for.
    pub tile_stats: Option<TileStats>,
}

/// What a [`Renderer`] is built with: its resolution, where its stencil bits sit, and what it
/// bakes (LUT tables, lightmap sizes) or chooses with (the adaptive technique's costs).
///
/// These are fixed for a renderer's life, as an engine's pipelines and tables are: a frame
/// never depends on a setting some earlier caller left behind, and a comparison of two
/// settings is two renderers (making one costs the scene's uploads). What changes per frame is
/// in [`crate::FrameDesc`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RendererDesc {
    /// The targets' width in pixels.
    pub width: u32,
    /// The targets' height in pixels.
    pub height: u32,
    /// The culling bit and the BRDF field where an engine wants them; `None`: the talk's
    /// layout (culling bit 0, BRDF bits above it).
    pub stencil_bits: Option<StencilBits>,
    /// The LUT technique's table resolution (grid points per axis,
    /// `2..=`[`histencil_brdf::lut::Lut::MAX_RESOLUTION`]).
    pub lut_resolution: u32,
    /// Every alpha entity's lightmap side in texels (a ribbon's texels along it; dust keeps
    /// one texel per mote), `2..=`[`histencil_alpha::MAX_FORCED_SIDE`]; `None`: each sized
    /// from its screen coverage (`histencil_alpha::side_for_coverage`).
    pub lightmap_side: Option<u32>,
    /// The costs [`crate::Technique::Adaptive`] chooses with, e.g. calibrated on this device.
    /// `None`: the talk's measurements fitted by [`CostModel::from_talk`] (360 figures for the
    /// 360-like backend, PS3 figures otherwise) with an assumed 5 us per extra draw.
    pub cost_model: Option<CostModel>,
    /// Each BRDF's shading cost relative to the others, as `histencil calibrate` measured them
    /// (its costs file's `brdf_weights`): the adaptive technique weights branching's tax by the
    /// BRDFs each light touches. `None`: every BRDF costs the same.
    pub brdf_weights: Option<histencil_brdf::BrdfWeights>,
    /// The BRDFs it shades with and their shaders: histencil's own
    /// ([`crate::BrdfModules::builtin`]), or an engine's set ([`crate::compile_brdf_set`]).
    /// Every object's and entity's BRDF must be one of the set's.
    pub brdfs: &'static crate::BrdfModules,
}

impl RendererDesc {
    /// `width` x `height` with the talk's stencil layout, [`DEFAULT_LUT_RESOLUTION`], lightmaps
    /// sized from coverage and the talk's costs.
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            stencil_bits: None,
            lut_resolution: DEFAULT_LUT_RESOLUTION,
            lightmap_side: None,
            cost_model: None,
            brdf_weights: None,
            brdfs: crate::BrdfModules::builtin(),
        }
    }
}

/// A scene ready to render at one resolution.
pub struct Renderer<'c> {
    ctx: &'c Context,
    scene: Scene,
    stencil_layout: StencilLayout,
    /// The BRDFs in use; a BRDF's index here is its stencil slot.
    brdfs: Vec<BrdfId>,
    /// Each object's BRDF slot.
    object_slots: Vec<u32>,
    /// The distinct BRDF materials (one LUT table each) and each object's index among them.
    materials: Vec<Brdf>,
    object_materials: Vec<u32>,
    /// What it was built with: the LUT resolution, lightmap side and costs are read from here.
    desc: RendererDesc,
    /// Baked when the LUT technique first renders.
    lut_tables: Option<LutTables<&'c Context>>,
    /// Created at the first frame of a scene with alpha entities.
    alpha: Option<AlphaLighting<'c>>,
    /// The lighting passes, as an engine records them, into this renderer's targets.
    lighting: DeferredLighting<&'c Context>,
    extent: vk::Extent2D,
    targets: Targets,
    meshes: Meshes,
    /// The objects' texture maps (set 1 of the mesh passes).
    maps: GpuMaterials,
    frame_uniforms: Buffer,
    lights: Buffer,
    /// The frame set (set 0 of the mesh, alpha and tonemap passes).
    descriptors: Descriptors,
    mesh_passes: MeshPasses,
    tonemap: Tonemap,
    command_pool: vk::CommandPool,
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
    /// A frame was submitted and its fence wait failed (a timeout, a lost device), with what
    /// it returned: the command buffer may still be pending, so the renderer records nothing
    /// more and says so with that result.
    unfinished: std::cell::Cell<Option<vk::Result>>,
    timestamps: Timestamps,
    readback: ReadbackBuffers,
}

impl<'c> Renderer<'c> {
    /// The device it renders on.
    pub fn context(&self) -> &'c Context {
        self.ctx
    }

    /// The scene being rendered.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// What it was made with: a second renderer of a variant of its scene (without its alpha
    /// entities, say) takes the same BRDF set, costs and sizes from here.
    pub fn desc(&self) -> &RendererDesc {
        &self.desc
    }

    /// Where the culling bit, the BRDF field and the preserved bits sit in its stencil.
    pub fn stencil_layout(&self) -> &StencilLayout {
        &self.stencil_layout
    }

    /// The BRDFs in use, in stencil slot order.
    pub fn brdfs(&self) -> &[BrdfId] {
        &self.brdfs
    }

    /// The stencil value each object's G-buffer draw writes with `preserved_pattern` in the
    /// preserved bits ([`crate::FrameDesc::preserved_pattern`]).
    pub fn object_stencil_values(&self, preserved_pattern: u8) -> Vec<u8> {
        self.object_slots
            .iter()
            .map(|s| {
                crate::passes::geometry::gbuffer_stencil(
                    &self.stencil_layout,
                    *s,
                    preserved_pattern,
                )
                .map_or(0, |f| f.reference)
            })
            .collect()
    }

    /// The costs the adaptive technique uses with `backend`, its BRDFs' weights
    /// ([`RendererDesc::brdf_weights`]) put in their stencil slots.
    pub fn cost_model(&self, backend: Backend) -> CostModel {
        let mut costs = self.desc.cost_model.unwrap_or_else(|| {
            let figures = match backend {
                Backend::X360 { .. } => TalkFigures::X360,
                Backend::Ps3
                | Backend::Native
                | Backend::AmdPretest
                | Backend::AmdAndOr
                | Backend::AmdAndOrUnmasked => TalkFigures::PS3,
            };
            CostModel::from_talk(&figures, ASSUMED_DRAW_OVERHEAD_MS)
        });
        if let Some(weights) = self.desc.brdf_weights {
            let mut slots = histencil_model::SlotWeights::UNIFORM;
            for (slot, id) in slots.0.iter_mut().zip(&self.brdfs) {
                *slot = weights.get(*id);
            }
            costs.slot_weights = Some(slots);
        }
        costs
    }

    /// The LUT technique's table resolution ([`RendererDesc::lut_resolution`]).
    pub fn lut_resolution(&self) -> u32 {
        self.desc.lut_resolution
    }

    /// The LUT technique's tables at the current resolution, baked and uploaded on first use
    /// (by table index: the scene's distinct BRDF materials in first-use order).
    ///
    /// # Errors
    /// [`crate::Error::LutTexturedParameters`] when an object's metallic-roughness map changes
    /// its BRDF's parameters per texel ([`histencil_scene::Material::parameters_vary`]),
    /// [`crate::Error::LutUntabulable`] when a table cannot hold an object's BRDF
    /// ([`crate::lut_refusal`]: an engine BRDF whose function takes the tint, that reads the
    /// tangent, or that lights where `N.L <= 0`),
    /// [`crate::Error::TooManyMaterials`] beyond what the G-buffer indexes, and those of
    /// [`LutTables::new`].
    pub fn lut_tables(&mut self) -> Result<&LutTables<&'c Context>> {
        if self.lut_tables.is_none() {
            if let Some(o) = self
                .scene
                .objects
                .iter()
                .find(|o| o.material.parameters_vary())
            {
                return Err(crate::Error::LutTexturedParameters {
                    object: o.name.clone(),
                    brdf: o.material.brdf.id().name(),
                });
            }
            let modules = self.desc.brdfs;
            let mut refused = None;
            for o in &self.scene.objects {
                if let Some(why) = crate::lut_refusal(self.ctx, modules, &o.material.brdf)? {
                    refused = Some((o, why));
                    break;
                }
            }
            if let Some((o, why)) = refused {
                return Err(crate::Error::LutUntabulable {
                    object: o.name.clone(),
                    brdf: o.material.brdf.id().name(),
                    why,
                });
            }
            if self.materials.len() > MAX_MATERIALS {
                return Err(crate::Error::TooManyMaterials {
                    count: self.materials.len(),
                    max: MAX_MATERIALS,
                });
            }
            let tables = LutTables::with_modules(
                self.ctx,
                self.desc.brdfs,
                &self.materials,
                self.desc.lut_resolution,
            )?;
            // SAFETY: `tables` moves into `self.lut_tables` below and is freed only by the
            // renderer's Drop, after its device wait; they are the first tables (baked once),
            // so no command buffer reads earlier ones.
            unsafe { self.lighting.set_lut_tables(&tables) };
            self.lut_tables = Some(tables);
        }
        Ok(self.lut_tables.as_ref().expect("baked above"))
    }

    /// The alpha entities' lightmap layout (atlas size, each entity's region), planned on first
    /// use; `None` for a scene without alpha entities.
    ///
    /// # Errors
    /// [`crate::Error::Lightmap`] when the entities do not fit the atlas.
    pub fn lightmap_layout(&mut self) -> Result<Option<&histencil_alpha::LightmapLayout>> {
        Ok(self.alpha_lighting()?.map(|a| a.layout()))
    }

    /// Each alpha entity's lightmap parameters (slices, side) and the error estimate behind
    /// them, in `histencil_alpha::entities` order; empty for a scene without alpha entities.
    ///
    /// # Errors
    /// [`crate::Error::Lightmap`] when the entities do not fit the atlas.
    pub fn lightmap_parameters(&mut self) -> Result<Vec<histencil_alpha::Parameters>> {
        Ok(self
            .alpha_lighting()?
            .map_or_else(Vec::new, |a| a.parameters().to_vec()))
    }

    /// Lightmap draws per frame: one per (entity, light that reaches its bounds).
    pub fn lightmap_draws(&mut self) -> Result<usize> {
        Ok(self.alpha_lighting()?.map_or(0, |a| a.lightmap_draws()))
    }

    fn alpha_lighting(&mut self) -> Result<Option<&mut AlphaLighting<'c>>> {
        if self.scene.alpha_entity_count() == 0 {
            return Ok(None);
        }
        if self.alpha.is_none() {
            self.alpha = Some(AlphaLighting::new(
                self.ctx,
                &self.scene,
                self.extent,
                self.desc.lightmap_side,
                self.descriptors.frame_layout,
                self.desc.brdfs,
            )?);
        }
        Ok(self.alpha.as_mut())
    }

    /// Light pipelines created so far.
    pub fn light_pipeline_count(&self) -> usize {
        self.lighting.pipeline_count()
    }
}
