//! The renderer: owns a scene's GPU resources and records / submits whole frames. This file
//! holds what it owns and how it is configured; `create.rs` how it is made and freed,
//! `plan.rs` how a frame is planned, `frame.rs` the order of a frame's passes, `simulator.rs`
//! what the CPU simulator is given.

mod create;
mod frame;
mod plan;
mod simulator;

use crate::alpha::AlphaLighting;
use crate::context::Context;
use crate::deferred_lighting::DeferredLighting;
use crate::descriptors::Descriptors;
use crate::error::Result;
use crate::lut::LutTables;
use crate::materials::GpuMaterials;
use crate::meshes::Meshes;
use crate::passes::geometry::MeshPasses;
use crate::passes::tonemap::Tonemap;
use crate::readback::{FrameImages, ReadbackBuffers};
use crate::resources::Buffer;
use crate::targets::Targets;
use crate::technique::Backend;
use crate::timing::{FrameTimings, Timestamps};
use ash::vk;
use histencil_brdf::lut::Lut;
use histencil_brdf::{Brdf, BrdfId};
use histencil_model::{CostModel, StencilLayout, TalkFigures, TileStats};
use histencil_scene::Scene;

/// The LUT technique's table resolution until [`Renderer::set_lut_resolution`] says otherwise:
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
    pub timings: FrameTimings,
    pub images: FrameImages,
    pub tile_stats: Option<TileStats>,
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
    lut_resolution: u32,
    /// Baked when the LUT technique first renders at `lut_resolution`.
    lut_tables: Option<LutTables>,
    /// Lightmap region side for every entity; `None`: from screen coverage.
    lightmap_side: Option<u32>,
    /// Created at the first frame of a scene with alpha entities (and again when the lightmap
    /// resolution changes).
    alpha: Option<AlphaLighting<'c>>,
    /// The lighting passes, as an engine records them, into this renderer's targets.
    lighting: DeferredLighting<'c>,
    /// The adaptive technique's costs; `None`: fitted to the talk's figures for the backend.
    cost_model: Option<CostModel>,
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
    timestamps: Timestamps,
    readback: ReadbackBuffers,
}

impl<'c> Renderer<'c> {
    /// The scene being rendered.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

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

    /// The costs [`crate::Technique::Adaptive`] chooses with, e.g. calibrated on this device. Without
    /// them it uses the talk's measurements fitted by [`CostModel::from_talk`] (360 figures for
    /// the 360-like backend, PS3 figures otherwise) with an assumed 5 us per extra draw.
    pub fn set_cost_model(&mut self, costs: Option<CostModel>) {
        self.cost_model = costs;
    }

    /// The costs the adaptive technique uses with `backend`.
    pub fn cost_model(&self, backend: Backend) -> CostModel {
        self.cost_model.unwrap_or_else(|| {
            let figures = match backend {
                Backend::X360 { .. } => TalkFigures::X360,
                Backend::Ps3 | Backend::Native => TalkFigures::PS3,
            };
            CostModel::from_talk(&figures, ASSUMED_DRAW_OVERHEAD_MS)
        })
    }

    /// Sets the LUT technique's table resolution (grid points per axis); the tables are baked
    /// again on the next LUT frame.
    ///
    /// # Errors
    /// [`crate::Error::Lut`] outside `2..=`[`Lut::MAX_RESOLUTION`].
    pub fn set_lut_resolution(&mut self, resolution: u32) -> Result<()> {
        Lut::check_resolution(resolution)?;
        if resolution != self.lut_resolution {
            if let Some(mut old) = self.lut_tables.take() {
                old.destroy(self.ctx);
            }
            self.lut_resolution = resolution;
        }
        Ok(())
    }

    pub fn lut_resolution(&self) -> u32 {
        self.lut_resolution
    }

    /// The LUT technique's tables at the current resolution, baked and uploaded on first use
    /// (by table index: the scene's distinct BRDF materials in first-use order).
    ///
    /// # Errors
    /// [`crate::Error::LutTexturedParameters`] when an object's metallic-roughness map changes
    /// its BRDF's parameters per texel ([`histencil_scene::Material::parameters_vary`]),
    /// [`crate::Error::TooManyMaterials`] beyond what the G-buffer indexes, and those of
    /// [`LutTables::new`].
    pub fn lut_tables(&mut self) -> Result<&LutTables> {
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
            if self.materials.len() > MAX_MATERIALS {
                return Err(crate::Error::TooManyMaterials {
                    count: self.materials.len(),
                    max: MAX_MATERIALS,
                });
            }
            let tables = LutTables::new(self.ctx, &self.materials, self.lut_resolution)?;
            // SAFETY: the renderer keeps the tables until it drops them or bakes new ones, and
            // it waits for every frame it submits.
            unsafe { self.lighting.set_lut_tables(&tables) };
            self.lut_tables = Some(tables);
        }
        Ok(self.lut_tables.as_ref().expect("baked above"))
    }

    /// Gives every alpha entity's lightmap `side` texels a side (a ribbon `side` texels along
    /// it; dust keeps one texel per mote); `None` sizes them from screen coverage
    /// (`histencil_alpha::side_for_coverage`). The atlas is laid out again on the next frame.
    ///
    /// # Errors
    /// [`crate::Error::Lightmap`] for a side outside 2..=[`histencil_alpha::MAX_FORCED_SIDE`]
    /// (the renderer keeps its setting).
    pub fn set_lightmap_resolution(&mut self, side: Option<u32>) -> Result<()> {
        if let Some(s) = side {
            histencil_alpha::check_forced_side(s)?;
        }
        if side != self.lightmap_side {
            if let Some(mut old) = self.alpha.take() {
                old.destroy(self.ctx);
            }
            self.lightmap_side = side;
        }
        Ok(())
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
                self.lightmap_side,
                self.descriptors.frame_layout,
            )?);
        }
        Ok(self.alpha.as_mut())
    }

    /// Light pipelines created so far.
    pub fn light_pipeline_count(&self) -> usize {
        self.lighting.pipeline_count()
    }
}
