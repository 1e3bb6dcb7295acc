//! The pipelines of the lighting pass, created the first time a plan needs them: a scene pays
//! only for the BRDFs it uses, and a technique only for its own shaders.

use crate::gpu::device::context::Context;
use crate::gpu::device::error::Result;
use crate::gpu::device::pipelines::{create_pipeline, Blend, PipelineDesc, VertexInput};
use crate::hi_stencil::{plan_touches, TouchedTiles, TOUCH_FORMAT};
use crate::passes::light_modules::LightModules;
use crate::shaders;
use ash::vk;
use histencil_brdf::BrdfId;
use histencil_model::{FramePlan, Geometry, Pass, PassKind, Shader, Step};
use std::collections::HashMap;

/// The fragment stage of a light pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LightShader {
    /// No fragment shader: stencil and depth only.
    StencilOnly,
    /// No fragment shader, into the hi-stencil emulation's depth-only touch image: where a
    /// write's volume rasterises (`crate::hi_stencil`).
    TouchTiles,
    /// Counts tiles a hi-stencil test covers and rejects (`hi_stencil_count.frag`).
    CountTiles,
    /// Writes one saved preserved stencil bit back (`restore_preserved.frag`).
    RestoreBit,
    /// The light shader of one BRDF.
    Brdf {
        /// The BRDF it is specialised for.
        id: BrdfId,
        /// The hi-stencil work it carries.
        tiles: TileWork,
    },
    /// The uber light shader branching on the G-buffer's BRDF id.
    Branching {
        /// The hi-stencil work it carries.
        tiles: TileWork,
    },
    /// The LUT technique's light shader: every BRDF from its material's table.
    Lut {
        /// The hi-stencil work it carries.
        tiles: TileWork,
    },
}

/// Where shade passes get a BRDF's value from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BrdfSource {
    /// The BRDF's formula (`include/brdf`): the stencil, branching and adaptive techniques.
    Formula,
    /// The material's look-up table (`include/lut.glsl`): the LUT technique, whatever pass the
    /// plan shades with.
    Table,
}

/// Which of the hi-stencil emulation's work a light shader carries: rejecting failing tiles, and
/// counting shaded fragments for the statistics. What a pass does not need is specialised away,
/// so timed passes carry no shader memory writes: llvmpipe pays for an atomic compiled in even
/// where it never runs (about 5 of the 14 % a testing pass cost over native's; README).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TileWork {
    /// Neither: a pass without an emulated hi-stencil test.
    None,
    /// The emulated hi-stencil test, read-only.
    Test,
    /// The test and the statistics' fragment count.
    TestAndCount,
}

/// A light pipeline: what it rasterises and its fragment stage.
pub type LightPipelineKey = (Geometry, LightShader);

/// `SHADED_BRDF` of `deferred_light.frag` for the branching shader.
const BRANCH_ON_GBUFFER: u32 = u32::MAX;

/// The lighting's pipelines, one per [`LightPipelineKey`] a plan has needed so far, made from
/// one set of [`LightModules`] and kept until the lighting is destroyed.
pub struct LightPipelines {
    layout: vk::PipelineLayout,
    /// The light shaders: histencil's, or compiled with an engine's hooks.
    modules: LightModules,
    hdr_format: vk::Format,
    depth_stencil_format: vk::Format,
    pipelines: HashMap<LightPipelineKey, vk::Pipeline>,
}

impl LightPipelines {
    /// None made yet: pipelines for `layout` (the lighting's, which it keeps owning), rendering
    /// to `hdr_format` and `depth_stencil_format`, from `modules`.
    pub fn new(
        layout: vk::PipelineLayout,
        modules: LightModules,
        hdr_format: vk::Format,
        depth_stencil_format: vk::Format,
    ) -> Self {
        Self {
            layout,
            modules,
            hdr_format,
            depth_stencil_format,
            pipelines: HashMap::new(),
        }
    }

    /// Creates the pipeline for `key` unless it exists.
    pub fn prepare(&mut self, ctx: &Context, key: LightPipelineKey) -> Result<()> {
        if self.pipelines.contains_key(&key) {
            return Ok(());
        }
        let (geometry, shader) = key;
        let (vertex, vertex_input) = match geometry {
            Geometry::Volume => (
                ("light_volume.vert", shaders::LIGHT_VOLUME_VERT),
                VertexInput::Position,
            ),
            Geometry::FullScreen => (
                ("fullscreen.vert", shaders::FULLSCREEN_VERT),
                VertexInput::None,
            ),
        };
        let light = ("deferred_light.frag", self.modules.deferred_light);
        let (fragment, specialization, shader_name) = match shader {
            LightShader::StencilOnly => (None, None, "stencil".to_owned()),
            LightShader::TouchTiles => (None, None, "touch-tiles".to_owned()),
            LightShader::CountTiles => (
                Some(("hi_stencil_count.frag", shaders::HI_STENCIL_COUNT_FRAG)),
                None,
                "count-tiles".to_owned(),
            ),
            LightShader::RestoreBit => (
                Some(("restore_preserved.frag", shaders::RESTORE_PRESERVED_FRAG)),
                None,
                "restore-bit".to_owned(),
            ),
            LightShader::Brdf { id, tiles } => (
                Some(light),
                Some([id.index(), tiles.tests(), tiles.counts()]),
                format!("{}{}", id.name(), tiles.suffix()),
            ),
            LightShader::Branching { tiles } => (
                Some(light),
                Some([BRANCH_ON_GBUFFER, tiles.tests(), tiles.counts()]),
                format!("branching{}", tiles.suffix()),
            ),
            // Constant 0 is unused by the LUT shader; all three are given so every light shader
            // specialises the same way.
            LightShader::Lut { tiles } => (
                Some(("lut_light.frag", self.modules.lut_light)),
                Some([BRANCH_ON_GBUFFER, tiles.tests(), tiles.counts()]),
                format!("lut{}", tiles.suffix()),
            ),
        };
        let shades = specialization.is_some();
        let geometry_name = match geometry {
            Geometry::Volume => "volume",
            Geometry::FullScreen => "fullscreen",
        };
        let hdr = [self.hdr_format];
        let touch = shader == LightShader::TouchTiles;
        let (color_formats, depth_stencil_format): (&[vk::Format], _) = if touch {
            (&[], TOUCH_FORMAT)
        } else {
            (&hdr, self.depth_stencil_format)
        };
        let pipeline = create_pipeline(
            ctx,
            &PipelineDesc {
                name: &format!("light-{geometry_name}-{shader_name}-pipeline"),
                vertex,
                fragment,
                layout: self.layout,
                vertex_input,
                color_formats,
                color_writes: shades,
                blend: if shades { Blend::Additive } else { Blend::Off },
                depth_stencil_format,
                // Back faces beyond the far plane clamp to depth 1, behind every surface.
                depth_clamp: geometry == Geometry::Volume,
                specialization: specialization.as_ref().map_or(&[], |c| c.as_slice()),
            },
        )?;
        self.pipelines.insert(key, pipeline);
        Ok(())
    }

    pub(crate) fn get(&self, key: LightPipelineKey) -> vk::Pipeline {
        self.pipelines[&key]
    }

    /// How many pipelines exist: what the scene and the techniques used so far cost.
    pub fn count(&self) -> usize {
        self.pipelines.len()
    }

    /// Frees the pipelines made so far (not the layout); a second call does nothing.
    pub fn destroy(&mut self, ctx: &Context) {
        for (_, p) in self.pipelines.drain() {
            // SAFETY: `p` was made by `prepare` from this device and is drained from the map, so
            // destroyed once; the lighting's Drop, the one caller, has its slots finished or
            // the device idle first.
            unsafe { ctx.device.destroy_pipeline(p, None) };
        }
    }
}

impl TileWork {
    fn suffix(self) -> &'static str {
        match self {
            TileWork::None => "",
            TileWork::Test => "-tiles",
            TileWork::TestAndCount => "-tiles-counted",
        }
    }

    /// `TILE_TEST` of `include/light_tiles.glsl`.
    fn tests(self) -> u32 {
        u32::from(self != TileWork::None)
    }

    /// `TILE_COUNT` of `include/light_tiles.glsl`.
    fn counts(self) -> u32 {
        u32::from(self == TileWork::TestAndCount)
    }
}

/// The pipeline of a planned pass. `brdfs` maps stencil slots to BRDFs; with `count_stats`
/// every light shader counts its fragments. A hi-stencil write draws as native does: the
/// emulator's touch draw that follows it is its own ([`LightShader::TouchTiles`]).
///
/// `hierarchy`: the GPU keeps its own hierarchical stencil (the AMD platforms), which may test
/// any pass, so every light shader can reject tiles.
pub fn pipeline_key(
    pass: &Pass,
    brdfs: &[BrdfId],
    count_stats: bool,
    source: BrdfSource,
    hierarchy: bool,
) -> LightPipelineKey {
    let tiles = if count_stats {
        TileWork::TestAndCount
    } else if pass.state.tests_hi_stencil() || hierarchy {
        TileWork::Test
    } else {
        TileWork::None
    };
    let shader = match pass.kind {
        PassKind::Shade(_) if source == BrdfSource::Table => LightShader::Lut { tiles },
        PassKind::Shade(Shader::Brdf(slot)) => LightShader::Brdf {
            id: brdfs[slot as usize],
            tiles,
        },
        PassKind::Shade(Shader::Branching) => LightShader::Branching { tiles },
        _ => LightShader::StencilOnly,
    };
    (pass.geometry, shader)
}

/// Every pipeline a plan uses, each once, in first-use order; `count_tiles` adds the statistics
/// draws of hi-stencil tests; `hierarchy` as for [`pipeline_key`] (with `count_tiles`, every
/// pass may take a statistics draw).
pub fn plan_pipelines(
    plan: &FramePlan,
    brdfs: &[BrdfId],
    count_tiles: bool,
    source: BrdfSource,
    hierarchy: bool,
) -> Vec<LightPipelineKey> {
    let mut keys = Vec::new();
    let mut add = |key| {
        if !keys.contains(&key) {
            keys.push(key);
        }
    };
    let touches = plan_touches(plan);
    for (step, touch) in plan.steps.iter().zip(touches) {
        match step {
            Step::Pass { pass, .. } => {
                add(pipeline_key(pass, brdfs, count_tiles, source, hierarchy));
                if touch == Some(TouchedTiles::Drawn) {
                    add((Geometry::Volume, LightShader::TouchTiles));
                }
                if count_tiles && (pass.state.tests_hi_stencil() || hierarchy) {
                    add((pass.geometry, LightShader::CountTiles));
                }
            }
            Step::RestorePreserved { .. } => {
                add((Geometry::FullScreen, LightShader::StencilOnly));
                add((Geometry::FullScreen, LightShader::RestoreBit));
            }
            Step::FlushHiStencil | Step::SavePreserved { .. } => {}
        }
    }
    keys
}

/// Creates every pipeline `plan` uses.
pub fn prepare_pipelines(
    ctx: &Context,
    pipelines: &mut LightPipelines,
    plan: &FramePlan,
    brdfs: &[BrdfId],
    count_tiles: bool,
    source: BrdfSource,
    hierarchy: bool,
) -> Result<()> {
    for key in plan_pipelines(plan, brdfs, count_tiles, source, hierarchy) {
        pipelines.prepare(ctx, key)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use histencil_model::{
        FlushPolicy, LightCase, LightRequest, LightTechnique, StencilLayout, X360Like,
    };

    #[test]
    fn passes_map_to_the_shaders_of_their_brdfs() {
        let brdfs = [BrdfId::Lambert, BrdfId::Ggx];
        let layout = StencilLayout::new(2, 0).unwrap();
        let request = LightRequest {
            case: LightCase::Outside,
            affected: vec![0, 1],
            technique: LightTechnique::Stencil,
        };
        let plan = FramePlan::from_requests(
            &layout,
            &X360Like::default(),
            std::slice::from_ref(&request),
            FlushPolicy::Auto,
        )
        .unwrap();
        let keys = plan_pipelines(&plan, &brdfs, false, BrdfSource::Formula, false);
        let shaders: Vec<LightShader> = keys.iter().map(|k| k.1).collect();
        let tiles = TileWork::Test;
        for expected in [
            LightShader::StencilOnly,
            LightShader::TouchTiles,
            LightShader::Brdf {
                id: BrdfId::Lambert,
                tiles,
            },
            LightShader::Brdf {
                id: BrdfId::Ggx,
                tiles,
            },
        ] {
            assert!(shaders.contains(&expected), "{expected:?} in {shaders:?}");
        }
        assert!(!shaders.contains(&LightShader::CountTiles));
        // Timed frames carry no atomic: no light shader of theirs counts.
        assert!(!keys.iter().any(|k| matches!(
            k.1,
            LightShader::Brdf {
                tiles: TileWork::TestAndCount,
                ..
            } | LightShader::Branching {
                tiles: TileWork::TestAndCount
            } | LightShader::Lut {
                tiles: TileWork::TestAndCount
            }
        )));
        // Only the statistics runs compile the fragment count in.
        let counted = plan_pipelines(&plan, &brdfs, true, BrdfSource::Formula, false);
        assert!(counted.iter().any(|k| k.1 == LightShader::CountTiles));
        assert!(counted.iter().all(|k| !matches!(
            k.1,
            LightShader::Brdf {
                tiles: TileWork::Test | TileWork::None,
                ..
            }
        )));
        // A viewer inside the light: its hi-stencil writes are full-screen, which touch every
        // tile, and need no touch draw.
        let inside = LightRequest {
            case: LightCase::ViewerInside,
            ..request
        };
        let plan =
            FramePlan::from_requests(&layout, &X360Like::default(), &[inside], FlushPolicy::Auto)
                .unwrap();
        assert!(plan.steps.iter().any(|s| matches!(
            s,
            histencil_model::Step::Pass { pass, .. } if pass.state.writes_hi_stencil()
        )));
        let keys = plan_pipelines(&plan, &brdfs, false, BrdfSource::Formula, false);
        assert!(!keys.iter().any(|k| k.1 == LightShader::TouchTiles));
        let table = plan_pipelines(&plan, &brdfs, false, BrdfSource::Table, false);
        assert!(table.iter().any(|k| matches!(k.1, LightShader::Lut { .. })));
        assert!(!table.iter().any(|k| matches!(
            k.1,
            LightShader::Brdf { .. } | LightShader::Branching { .. }
        )));
    }
}
