//! The CPU simulator: executes a [`FramePlan`] on a software depth + stencil buffer, with the
//! hi-stencil emulation of [`TileSurface`], and records which pass shaded which pixel.
//! It is the oracle for the GPU implementation: the same plan, the same state values.

use crate::amd::{tile_values, TileHierarchy};
use crate::depth_bounds::DepthRange;
use crate::footprint::Footprint;
use crate::frame::{FramePlan, Step};
use crate::layout::StencilLayout;
use crate::plan::{Geometry, Pass, PassKind, Shader};

use crate::tiles::{TileStats, TileSurface};

/// Depth and stencil of the frame after the G-buffer pass.
#[derive(Clone, Debug, PartialEq)]
pub struct SoftTarget {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Surface depth per pixel; the far depth of the plan's convention where there is no
    /// surface.
    pub depth: Vec<f32>,
    /// Stencil per pixel as the G-buffer pass left it (BRDF ids and the engine's bits); the run
    /// leaves the final stencil here.
    pub stencil: Vec<u8>,
}

impl SoftTarget {
    /// The index of pixel (x, y) in [`SoftTarget::depth`] and [`SoftTarget::stencil`]: rows from
    /// the top.
    pub fn index(&self, x: u32, y: u32) -> usize {
        (y * self.width + x) as usize
    }
}

/// Marks a pixel of [`LightShading::brdf`] that no pass shaded.
pub const NOT_SHADED: u8 = u8::MAX;

/// Per pixel of one light's footprint rectangle: how often and how it was shaded.
#[derive(Clone, Debug, PartialEq)]
pub struct LightShading {
    /// Times a light shader ran on the pixel (should be 0 or 1).
    pub count: Vec<u8>,
    /// The BRDF slot it was shaded with (the pixel's own slot for branching), or [`NOT_SHADED`].
    pub brdf: Vec<u8>,
    /// Index into the plan's steps of the last pass that shaded it.
    pub step: Vec<u32>,
}

impl LightShading {
    fn new(footprint: &Footprint) -> Self {
        let n = (footprint.width * footprint.height) as usize;
        Self {
            count: vec![0; n],
            brdf: vec![NOT_SHADED; n],
            step: vec![u32::MAX; n],
        }
    }
}

/// What a run produced besides the final stencil (left in the target).
#[derive(Clone, Debug, PartialEq)]
pub struct SimResult {
    /// Per light of the plan, in [`FramePlan::lights`] order: which pixels it shaded, how often.
    pub lights: Vec<LightShading>,
    /// Per light: the culling bit was still set after its last pass. Only the light's footprint
    /// rectangle is checked: passes write nowhere else, so if every earlier light left the
    /// frame clean, the whole frame is clean exactly when this rectangle is.
    pub culling_bit_left: Vec<bool>,
    /// Hi-stencil tiles tested, culled and passed over the whole run.
    pub stats: TileStats,
    /// Fragments of shade passes the depth bounds test rejected
    /// ([`crate::FramePlan::with_depth_bounds`]): pixels in a light's footprint whose surface
    /// lies outside its depth range, which the pass would otherwise have tested and, where its
    /// stencil and depth tests passed, shaded.
    pub depth_bounds_rejected: u64,
}

/// Runs plans for one stencil layout and tile size.
#[derive(Clone, Copy, Debug)]
pub struct Simulator {
    /// The layout the plans were made for.
    pub layout: StencilLayout,
    /// Side of a hi-stencil tile in pixels: the granularity the emulated hierarchy culls at.
    pub tile_size: u32,
}

impl Simulator {
    /// Executes `plan` on `target`; `footprints[i]` is the coverage of light `i`.
    ///
    /// # Panics
    /// If a step names a light without a footprint, a footprint exceeds the target or follows
    /// another depth convention than the plan: caller bugs, not data errors.
    pub fn run(
        &self,
        target: &mut SoftTarget,
        plan: &FramePlan,
        footprints: &[Footprint],
    ) -> SimResult {
        self.run_on(target, plan, footprints, None)
    }

    /// [`Simulator::run`] on a GPU whose own hierarchical stencil (`hierarchy`, built here from
    /// the target's stencil) rejects the tiles of stencil-testing draws without any plan step:
    /// the AMD platforms ([`crate::amd`]), which run the native plan. Their rejections are
    /// counted in the stats as hi-stencil tests and culls; what is shaded and the stencil left
    /// are the same as without it, since a model rejects only tiles where nothing passes.
    ///
    /// # Panics
    /// As [`Simulator::run`], and for a plan with hi-stencil state, flushes or a preserved-bits
    /// save and restore (a console's plan): the hierarchy follows stencil written by draws only.
    pub fn run_with(
        &self,
        target: &mut SoftTarget,
        plan: &FramePlan,
        footprints: &[Footprint],
        hierarchy: &mut dyn TileHierarchy,
    ) -> SimResult {
        assert!(
            plan.steps.iter().all(|step| match step {
                Step::Pass { pass, .. } => pass.state.hi_stencil.is_none(),
                _ => false,
            }),
            "run_with runs plans without hi-stencil steps (the native plan)"
        );
        self.run_on(target, plan, footprints, Some(hierarchy))
    }

    fn run_on<'a>(
        &self,
        target: &'a mut SoftTarget,
        plan: &FramePlan,
        footprints: &[Footprint],
        mut hierarchy: Option<&'a mut (dyn TileHierarchy + 'a)>,
    ) -> SimResult {
        assert!(
            footprints.iter().all(|f| f.depth() == plan.depth),
            "footprints and plan follow different depth conventions"
        );
        let tiles = TileSurface::new(target.width, target.height, self.tile_size);
        if let Some(h) = hierarchy.as_deref_mut() {
            crate::amd::begin(h, &target.stencil, target.width, &tiles);
        }
        let mut run = Run {
            layout: self.layout,
            tile_stamp: vec![u32::MAX; tiles.tile_count()],
            rejected: vec![false; tiles.tile_count()],
            tiles,
            stats: TileStats::default(),
            depth_bounds_rejected: 0,
            touched: Vec::new(),
            target,
            hierarchy,
        };
        let mut lights: Vec<LightShading> = footprints.iter().map(LightShading::new).collect();
        let mut culling_bit_left = vec![false; footprints.len()];
        let mut saved = Vec::new();
        let mut current: Option<usize> = None;
        for (index, step) in plan.steps.iter().enumerate() {
            if let Step::Pass { light, .. } = step {
                if let Some(previous) = current.filter(|c| c != light) {
                    culling_bit_left[previous] = run.culling_bit_set(&footprints[previous]);
                }
                current = Some(*light);
            }
            match step {
                Step::Pass { light, pass } => {
                    let far = plan.depth.far();
                    let bounds = plan.lights[*light]
                        .depth_range
                        .filter(|_| pass.state.depth_bounds);
                    run.pass(
                        index as u32,
                        (pass, bounds),
                        far,
                        &footprints[*light],
                        &mut lights[*light],
                    )
                }
                Step::FlushHiStencil => {
                    run.tiles.flush();
                    run.stats.flushes += 1;
                }
                Step::SavePreserved { mask } => {
                    saved = run.target.stencil.iter().map(|s| s & mask).collect();
                }
                Step::RestorePreserved { mask } => {
                    for (s, kept) in run.target.stencil.iter_mut().zip(&saved) {
                        *s = (*s & !mask) | kept;
                    }
                }
            }
        }
        if let Some(previous) = current {
            culling_bit_left[previous] = run.culling_bit_set(&footprints[previous]);
        }
        SimResult {
            lights,
            culling_bit_left,
            stats: run.stats,
            depth_bounds_rejected: run.depth_bounds_rejected,
        }
    }
}

struct Run<'a> {
    layout: StencilLayout,
    target: &'a mut SoftTarget,
    tiles: TileSurface,
    stats: TileStats,
    depth_bounds_rejected: u64,
    /// The step that last touched each tile, so each draw counts a tile once.
    tile_stamp: Vec<u32>,
    touched: Vec<usize>,
    /// The GPU's own hierarchical stencil, if the platform has one ([`Simulator::run_with`]).
    hierarchy: Option<&'a mut (dyn TileHierarchy + 'a)>,
    /// Per tile, whether `hierarchy` rejected it for the current draw.
    rejected: Vec<bool>,
}

impl Run<'_> {
    fn culling_bit_set(&self, footprint: &Footprint) -> bool {
        let culling = self.layout.culling_mask();
        (footprint.y0..footprint.y0 + footprint.height).any(|y| {
            (footprint.x0..footprint.x0 + footprint.width)
                .any(|x| self.target.stencil[self.target.index(x, y)] & culling != 0)
        })
    }

    fn pass(
        &mut self,
        step: u32,
        (pass, bounds): (&Pass, Option<DepthRange>),
        far: f32,
        footprint: &Footprint,
        shading: &mut LightShading,
    ) {
        let state = &pass.state;
        let Some(front_facing) = pass.front_facing() else {
            panic!("a volume pass must cull one face set: {}", pass.label())
        };
        let face = state.stencil_for(front_facing);
        let hi_test = state.tests_hi_stencil();
        // The GPU's own hierarchy tests what `hierarchy_test` says (the GPU path asks it too).
        let auto_test =
            self.hierarchy.is_some() && !hi_test && crate::amd::hierarchy_test(pass).is_some();
        let hi_write = state.hi_stencil.filter(|h| h.write);
        self.touched.clear();
        for y in footprint.y0..footprint.y0 + footprint.height {
            for x in footprint.x0..footprint.x0 + footprint.width {
                let Some(span) = footprint.span(x, y) else {
                    continue;
                };
                let fragment_depth = match pass.geometry {
                    Geometry::FullScreen => far,
                    Geometry::Volume if front_facing => match span.front {
                        Some(front) => front,
                        None => continue,
                    },
                    Geometry::Volume => span.back,
                };
                let tile = self.tiles.tile_of(x, y);
                if self.tile_stamp[tile] != step {
                    self.tile_stamp[tile] = step;
                    self.touched.push(tile);
                    if hi_test {
                        self.stats.tiles_tested += 1;
                        self.stats.tiles_culled += u64::from(!self.tiles.passes(tile));
                    }
                    if let (true, Some(h), Some(f)) = (auto_test, self.hierarchy.as_deref(), face) {
                        self.rejected[tile] = !h.may_pass(tile, &f);
                        self.stats.tiles_tested += 1;
                        self.stats.tiles_culled += u64::from(self.rejected[tile]);
                    }
                }
                if hi_test && !self.tiles.passes(tile) {
                    continue;
                }
                if auto_test && self.rejected[tile] {
                    continue;
                }
                let i = self.target.index(x, y);
                // Vulkan's depth bounds test comes before the stencil test: a fragment it
                // rejects runs no stencil op either.
                if bounds.is_some_and(|b| !b.contains(self.target.depth[i])) {
                    self.depth_bounds_rejected += 1;
                    continue;
                }
                let stencil = self.target.stencil[i];
                let stencil_passed = face.is_none_or(|f| f.test(stencil));
                let depth_passed =
                    stencil_passed && state.depth.passes(fragment_depth, self.target.depth[i]);
                if let Some(f) = face {
                    self.target.stencil[i] = f.update(stencil, stencil_passed, depth_passed);
                }
                if depth_passed && state.color_write {
                    let local =
                        ((y - footprint.y0) * footprint.width + (x - footprint.x0)) as usize;
                    shading.count[local] = shading.count[local].saturating_add(1);
                    shading.brdf[local] = match pass.kind {
                        PassKind::Shade(Shader::Brdf(slot)) => slot as u8,
                        _ => self.layout.brdf_slot(stencil) as u8,
                    };
                    shading.step[local] = step;
                    self.stats.fragments_shaded += 1;
                }
            }
        }
        // The hierarchy sees every tile this draw may have written.
        if let Some(h) = self.hierarchy.as_deref_mut() {
            if state.writes_stencil() {
                let (width, height) = (self.target.width, self.target.height);
                for &tile in &self.touched {
                    let values =
                        tile_values(&self.target.stencil, width, height, &self.tiles, tile);
                    h.written(tile, &values);
                }
            }
        }
        if let Some(hi) = hi_write {
            self.tiles.begin_write();
            let (width, height) = (self.target.width, self.target.height);
            for &tile in &self.touched {
                let (x0, y0, x1, y1) = self.tiles.tile_pixels(tile, width, height);
                let may_pass = (y0..y1).any(|y| {
                    (x0..x1)
                        .any(|x| hi.compare_passes(self.target.stencil[(y * width + x) as usize]))
                });
                self.tiles.write(tile, may_pass);
            }
        }
    }
}
