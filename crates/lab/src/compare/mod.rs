//! `histencil compare`: the talk's lighting-time table on this device, with every figure's error
//! against the forward reference rendered in the same run.

mod measure;
pub mod merge;
pub mod pair;
mod report;

pub use measure::MAX_ROUNDS;
use measure::{breakdown, lut_refusal, measure_sizes, measure_table, renderer_for};

use crate::image_error::{image_error, ImageError};
use crate::measure::{frame, lighting_ms, Timing};
use crate::stats::{
    median_interval, ratio_interval, sample_deciding, Interval, Sampled, Sampling, Verdict,
};
use crate::steady::{ClockSettings, Stability, SteadyClock};
use crate::variants::{brdf_palette, light_size_scene, with_brdf_count, with_one_brdf};
use crate::Result;
use histencil_brdf::BrdfId;
use histencil_scene::Scene;
use histencil_vk::{
    Backend, Context, CostModel, FlushPolicy, FrameDesc, MixedTiles, Readback, Renderer,
    RendererDesc, Shading, Technique, TileSide, TileStats,
};

/// What a comparison run measures.
#[derive(Clone, Debug)]
pub struct CompareSettings {
    pub scene: Scene,
    pub width: u32,
    pub height: u32,
    /// Timed frames per cell, after `measure::WARM_UP_FRAMES` warm-up frames: the rounds every
    /// measurement takes at least.
    pub frames: usize,
    /// Keep sampling until every overhead's interval is at most this wide (relative
    /// half-width, `0.03`: +-3 %), or `budget` runs out; `None`: `frames` rounds exactly.
    pub target_ci: Option<f64>,
    /// Wall-clock time each measurement set (the table; each light size) may sample for.
    pub budget: std::time::Duration,
    /// The adaptive technique's costs; `None`: fitted to the talk's figures.
    pub costs: Option<CostModel>,
    /// The BRDFs' weights of the same costs file ([`crate::read_brdf_weights`]); `None`: every
    /// BRDF costs the same.
    pub brdf_weights: Option<histencil_brdf::BrdfWeights>,
    /// The BRDFs it shades with: histencil's, or an engine's set (`compare --brdfs`), whose own
    /// BRDFs the scene should then name (`histencil_scene::retarget_brdfs`): the columns fold
    /// onto the scene's models first.
    pub brdfs: &'static histencil_vk::BrdfModules,
    /// BRDF counts of the table's columns (the talk's 1, 2, 3).
    pub brdf_counts: Vec<usize>,
    /// Screen coverages of the light-size sweep, 0..=1.
    pub light_sizes: Vec<f64>,
    /// Busy threads run beside the measurement (`compare --beside-load`): the same run under
    /// contention, for the quiet-against-loaded test of the verdicts (`compare merge`).
    pub beside_load: usize,
    /// Sample until the talk's cells ([`TALK_ROWS`] at 2 BRDFs and up; each light size's
    /// stencil-against-branching) are decided, instead of `frames` rounds or `target_ci`.
    pub until_decided: bool,
    /// Let a pilot of [`crate::stats::MIN_VERDICT_ROUNDS`] rounds predict the budget
    /// ([`crate::stats::Prediction`]); `budget` is then its cap.
    pub predict_budget: bool,
    /// Measure the talk's own branching row too ([`FIRST_ROW`]): per column, the uber shader
    /// compiled with that column's BRDFs only (with `glslc`, at run time) and every pixel
    /// taking the first. histencil's `branching` row compiles every BRDF of its set in at
    /// every column and shades the column's BRDFs, so it measures another thing.
    pub first_row: bool,
    /// The steady clock under every set ([`crate::steady`]): a canary warmed up until it
    /// settles and timed at every round's edges, straying rounds retaken; `None`: rounds kept
    /// as taken.
    pub clock: Option<ClockSettings>,
    /// Start the `beside_load` threads as the table's round of this index begins, instead of
    /// before the run: conditions that change part way, which the steady clock must see
    /// (`compare --beside-load-from-round`).
    pub load_from_round: Option<usize>,
}

/// The talk's branching measurement: "three different BRDFs, only one used (branch always
/// yields the first one)", the tax of branches compiled in and never taken.
pub const FIRST_ROW: &str = "branching, first";

/// The rows whose cost of an extra BRDF is the talk's question: branching against stencil on
/// the consoles and on today's GPUs.
pub const TALK_ROWS: [&str; 4] = ["branching", "stencil x360", "stencil ps3", "stencil native"];

impl CompareSettings {
    /// The talk's set-up: `huge-lights`, 1 to 3 BRDFs, lights from 0.1 % to 100 % of the screen.
    pub fn talk(width: u32, height: u32, frames: usize) -> Self {
        Self {
            scene: histencil_scene::embedded("huge-lights").expect("embedded"),
            width,
            height,
            frames,
            target_ci: None,
            budget: std::time::Duration::from_secs(60),
            costs: None,
            brdf_weights: None,
            brdfs: histencil_vk::BrdfModules::builtin(),
            brdf_counts: vec![1, 2, 3],
            light_sizes: vec![0.001, 0.003, 0.01, 0.03, 0.1, 0.3, 1.0],
            beside_load: 0,
            until_decided: false,
            predict_budget: false,
            first_row: false,
            clock: Some(ClockSettings::default()),
            load_from_round: None,
        }
    }
}

/// Per column (BRDF count), the modules of a set holding only that column's BRDFs (the
/// palette's first `count`), for [`FIRST_ROW`]; or why the row is left out: an engine's set
/// (its BRDFs' ids are their places in the set, which a subset would change), or a set
/// `glslc` could not compile.
fn first_row_modules(
    settings: &CompareSettings,
    palette: &[BrdfId],
) -> std::result::Result<Vec<&'static histencil_vk::BrdfModules>, String> {
    if !settings.brdfs.set.is_builtin_only() {
        return Err(
            "an engine's BRDF set cannot be cut to a column's BRDFs (its own BRDFs' \
                    ids are their places in the set)"
                .into(),
        );
    }
    settings
        .brdf_counts
        .iter()
        .map(|&count| {
            let ids = &palette[..count.min(palette.len())];
            let set = histencil_brdf::BrdfSet::new(ids, Vec::new()).map_err(|e| e.to_string())?;
            histencil_vk::compile_brdf_set(&set)
                .map_err(|e| format!("its shaders did not compile: {e}"))
        })
        .collect()
}

/// The table's rows: the technique and platform backend of each.
pub fn table_rows() -> Vec<(&'static str, Technique)> {
    let flush = FlushPolicy::Auto;
    let x360 = histencil_vk::Platform::X360.backend();
    vec![
        (
            "branching",
            Technique::Branching {
                backend: Backend::Native,
                flush,
            },
        ),
        (
            "stencil x360",
            Technique::Stencil {
                backend: x360,
                flush,
            },
        ),
        (
            "stencil ps3",
            Technique::Stencil {
                backend: Backend::Ps3,
                flush,
            },
        ),
        (
            "stencil native",
            Technique::Stencil {
                backend: Backend::Native,
                flush,
            },
        ),
        // AMD's hierarchies, modelled from AMD's driver sources and emulated: the native plan
        // with the tiles a GFX9-11 (pretests) or GFX12 (AND/OR) GPU would reject rejected.
        (
            "stencil amd-pretest",
            Technique::Stencil {
                backend: Backend::AmdPretest,
                flush,
            },
        ),
        (
            "stencil amd-andor",
            Technique::Stencil {
                backend: Backend::AmdAndOr,
                flush,
            },
        ),
        (
            "lut",
            Technique::Lut {
                backend: Backend::Native,
                flush,
            },
        ),
        (
            "adaptive",
            Technique::Adaptive {
                backend: Backend::Native,
                flush,
            },
        ),
        (
            "tiled",
            Technique::Tiled {
                mixed: MixedTiles::PerBrdf,
                side: TileSide::Sixteen,
            },
        ),
        (
            "tiled, mixed branching",
            Technique::Tiled {
                mixed: MixedTiles::Branching,
                side: TileSide::Sixteen,
            },
        ),
        (
            "tiled 8x8",
            Technique::Tiled {
                mixed: MixedTiles::PerBrdf,
                side: TileSide::Eight,
            },
        ),
        (
            "depth-id",
            Technique::DepthId {
                side: TileSide::Sixteen,
            },
        ),
    ]
}

/// One technique at one BRDF count.
#[derive(Clone, Debug)]
pub struct Cell {
    pub brdfs: usize,
    /// The lighting time of every round, in round order (rounds interleave every technique at
    /// every BRDF count, so sample `i` of two cells was measured under the same load): the
    /// platform's technique only, without the hi-stencil emulator's bookkeeping.
    pub samples: Vec<f64>,
    /// On the emulated backends, the emulator's bookkeeping in the same rounds (resets, splits,
    /// touch draws, tile updates, flush copies: `FrameTimings::bookkeeping_ms`); empty
    /// elsewhere. The whole lighting pass of round `i` is `samples[i] + bookkeeping[i]`.
    pub bookkeeping: Vec<f64>,
    /// With several BRDFs, what the same rounds would have taken if each BRDF cost what it costs
    /// alone: per round, the row's time on the scene with every object in one of this cell's
    /// BRDFs, weighted by that BRDF's share of the cell's surface pixels, summed (exact where
    /// every light covers the screen, as in `huge-lights`). Empty at one BRDF. The cell's time
    /// over this is what the technique adds per extra BRDF beyond the BRDFs' own arithmetic.
    pub single_brdf: Vec<f64>,
    pub error: ImageError,
}

impl Cell {
    /// The median lighting time and the spread of the rounds.
    pub fn lighting(&self) -> Timing {
        Timing::from_samples(self.samples.clone())
    }

    /// The median lighting time with its 95 % interval.
    pub fn interval(&self) -> Interval {
        median_interval(&self.samples)
    }

    /// The whole lighting pass of every round, the emulator's bookkeeping included.
    pub fn with_bookkeeping(&self) -> Vec<f64> {
        if self.bookkeeping.is_empty() {
            return self.samples.clone();
        }
        let rounds = self.samples.iter().zip(&self.bookkeeping);
        rounds.map(|(t, b)| t + b).collect()
    }
}

/// One technique across the BRDF counts.
#[derive(Clone, Debug)]
pub struct Row {
    pub name: &'static str,
    pub cells: Vec<Cell>,
}

impl Row {
    /// `(ms, %)` of the cell at `index` over this row's first (1-BRDF) cell.
    pub fn overhead(&self, index: usize) -> (f64, f64) {
        let base = self.cells[0].lighting().median_ms;
        let extra = self.cells[index].lighting().median_ms - base;
        (
            extra,
            if base > 0.0 {
                100.0 * extra / base
            } else {
                0.0
            },
        )
    }

    /// The time of the cell at `index` over this row's 1-BRDF time, paired by round: the median
    /// ratio with its 95 % interval, and what it lets one say.
    pub fn overhead_ratio(&self, index: usize) -> (Interval, Verdict) {
        let ratio = ratio_interval(&self.cells[index].samples, &self.cells[0].samples);
        (ratio, Verdict::of(&ratio))
    }

    /// The time of the cell at `index` over its BRDFs' own cost ([`Cell::single_brdf`]), paired
    /// by round, with its verdict; `None` at one BRDF.
    pub fn over_single_brdf(&self, index: usize) -> Option<(Interval, Verdict)> {
        let cell = &self.cells[index];
        if cell.single_brdf.is_empty() {
            return None;
        }
        let ratio = ratio_interval(&cell.samples, &cell.single_brdf);
        Some((ratio, Verdict::of(&ratio)))
    }

    /// The largest error over the row's cells, per measure.
    pub fn worst_error(&self) -> ImageError {
        self.cells
            .iter()
            .fold(ImageError::default(), |w, c| w.worst(c.error))
    }
}

/// One of the talk's verdicts: a stencil row (one platform) against branching at one BRDF
/// count, as the ratio of their lighting times in the same rounds (below 1: stencil faster).
#[derive(Clone, Debug)]
pub struct TalkVerdict {
    /// The stencil row (`stencil ps3`, ...).
    pub technique: &'static str,
    pub brdfs: usize,
    /// The row it is measured against: always `branching`.
    pub against: &'static str,
    /// Stencil's time over branching's, paired by round: the median with its 95 % interval.
    pub ratio: Interval,
    pub verdict: Verdict,
}

impl TalkVerdict {
    /// Which is faster where the data can tell: `stencil faster`, `branching faster`,
    /// `within ±5 %` or `undecided`.
    pub fn words(&self) -> &'static str {
        match self.verdict {
            Verdict::Faster => "stencil faster",
            Verdict::Slower => "branching faster",
            other => other.word(),
        }
    }
}

/// The talk's question asked of `rows`: each stencil row against the branching row at every
/// BRDF count above one, paired by round (the rounds interleave every row, so round `i` of two
/// rows ran under the same load). Stencil's own time: the emulated platforms' bookkeeping is
/// the emulator's, not the console's. Empty without a branching row.
pub fn talk_verdicts(rows: &[Row]) -> Vec<TalkVerdict> {
    let Some(branching) = rows.iter().find(|r| r.name == "branching") else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for row in rows.iter().filter(|r| r.name.starts_with("stencil")) {
        for (cell, base) in row.cells.iter().zip(&branching.cells).skip(1) {
            let ratio = ratio_interval(&cell.samples, &base.samples);
            out.push(TalkVerdict {
                technique: row.name,
                brdfs: cell.brdfs,
                against: branching.name,
                ratio,
                verdict: Verdict::of(&ratio),
            });
        }
    }
    out
}

/// The lighting pass of one technique split into the talk's groups, in total milliseconds.
#[derive(Clone, Debug)]
pub struct Breakdown {
    pub name: &'static str,
    pub brdfs: usize,
    pub lights: usize,
    pub setup_ms: f64,
    pub mask_ms: f64,
    pub render_ms: f64,
    pub cleanup_ms: f64,
    /// Zeroing preserved bits, flushes, restores: `(group, ms)`.
    pub other: Vec<(String, f64)>,
}

impl Breakdown {
    /// Per light and BRDF, as the talk gives it: setup and cleanup once per light, mask and render
    /// once per light and BRDF (every light touches every BRDF in the huge-light scene).
    pub fn per_pass(&self) -> [f64; 4] {
        let lights = self.lights.max(1) as f64;
        let passes = lights * self.brdfs.max(1) as f64;
        [
            self.setup_ms / lights,
            self.mask_ms / passes,
            self.render_ms / passes,
            self.cleanup_ms / lights,
        ]
    }
}

/// One light size of the sweep.
#[derive(Clone, Debug)]
pub struct SizePoint {
    pub coverage: f64,
    pub lights: usize,
    pub branching: Timing,
    pub stencil: Timing,
    pub adaptive: Timing,
    /// The tiled technique (mixed tiles per BRDF, the device's tile side).
    pub tiled: Timing,
    /// The depth-id technique, with the tiled technique's light lists of the same tile side.
    pub depth_id: Timing,
    /// Their tile side in pixels ([`TileSide::for_context`]).
    pub tile_side: u32,
    /// The worst of the five techniques' errors against forward.
    pub error: ImageError,
    /// Every round's lighting time of branching, stencil, adaptive, tiled and depth-id,
    /// interleaved.
    pub samples: [Vec<f64>; 5],
    pub sampled: Sampled,
}

impl SizePoint {
    /// Stencil's time over branching's, paired by round: below 1 stencil is faster.
    pub fn stencil_over_branching(&self) -> (Interval, Verdict) {
        let r = ratio_interval(&self.samples[1], &self.samples[0]);
        (r, Verdict::of(&r))
    }

    /// Which is faster where the data can tell: `"stencil"`, `"branching"`, `"within ±5 %"`
    /// or `"undecided"` ([`Verdict`]).
    pub fn faster(&self) -> &'static str {
        match self.stencil_over_branching().1 {
            Verdict::Faster => "stencil",
            Verdict::Slower => "branching",
            other => other.word(),
        }
    }

    /// Adaptive's time over the better (by median) of branching and stencil, paired by round,
    /// with its interval.
    pub fn adaptive_over_best_interval(&self) -> Interval {
        let best = if self.branching.median_ms <= self.stencil.median_ms {
            &self.samples[0]
        } else {
            &self.samples[1]
        };
        ratio_interval(&self.samples[2], best)
    }

    /// Tiled's time over the better (by median) of branching and stencil, paired by round, and
    /// its verdict ([`Verdict`]).
    pub fn tiled_over_best(&self) -> (Interval, Verdict) {
        self.over_best(3)
    }

    /// Depth-id's time over the better of branching and stencil, as [`SizePoint::tiled_over_best`].
    pub fn depth_id_over_best(&self) -> (Interval, Verdict) {
        self.over_best(4)
    }

    /// Depth-id's time over tiled's, paired by round: what finding a BRDF's pixels by a depth
    /// test costs against tile lists, on this device.
    pub fn depth_id_over_tiled(&self) -> (Interval, Verdict) {
        let r = ratio_interval(&self.samples[4], &self.samples[3]);
        (r, Verdict::of(&r))
    }

    fn over_best(&self, technique: usize) -> (Interval, Verdict) {
        let best = if self.branching.median_ms <= self.stencil.median_ms {
            &self.samples[0]
        } else {
            &self.samples[1]
        };
        let r = ratio_interval(&self.samples[technique], best);
        (r, Verdict::of(&r))
    }

    /// Adaptive's time over the better of branching and stencil (1: it chose the better one;
    /// below 1 where it chose better still, per light or tiled).
    pub fn adaptive_over_best(&self) -> f64 {
        let best = self.branching.median_ms.min(self.stencil.median_ms);
        if best > 0.0 {
            self.adaptive.median_ms / best
        } else {
            1.0
        }
    }
}

/// Everything a comparison run measured.
#[derive(Clone, Debug)]
pub struct CompareReport {
    pub device: String,
    /// The driver as Vulkan names it (name, build, conformance) and the validation layer: two
    /// builds of one driver share a device name.
    pub driver: String,
    pub scene: String,
    pub scene_lights: usize,
    /// The models the columns fold the scene onto, in order: the 1-BRDF column's first, each
    /// wider column adding the next (`brdf_palette`); an engine's own BRDFs by their names.
    pub models: Vec<String>,
    /// The engine BRDF set the run shaded with (`compare --brdfs`), as its BRDFs' names; empty
    /// for histencil's own.
    pub engine_brdfs: Vec<String>,
    /// Why the table has no LUT row (a model no table can hold), if it has none.
    pub lut_left_out: Option<String>,
    /// Why [`FIRST_ROW`] was asked for and left out, if it was.
    pub first_left_out: Option<String>,
    pub width: u32,
    pub height: u32,
    pub frames: usize,
    pub rows: Vec<Row>,
    pub breakdowns: Vec<Breakdown>,
    pub sizes: Vec<SizePoint>,
    /// How the table's rounds ended.
    pub sampled: Sampled,
    /// The interval width asked for, if any.
    pub target_ci: Option<f64>,
    /// `LP_NUM_THREADS` when the run started: llvmpipe's rasteriser threads, which decide how
    /// noisy its timings are (README, "Measured").
    pub lp_num_threads: Option<String>,
    /// Busy threads that ran beside the measurement ([`CompareSettings::beside_load`]).
    pub beside_load: usize,
    /// The device's depth bounds test confined the lights' shade passes
    /// (`Context::depth_bounds`): a condition of the run, as the load is.
    pub depth_bounds: bool,
    /// The costs the adaptive rows used.
    pub costs: CostModel,
    pub costs_calibrated: bool,
    /// Per BRDF count, what a GPU's hierarchical depth would make of the depth-id row's ids
    /// (`histencil_model::depth_id`, on the id image the GPU wrote): llvmpipe has none, so its
    /// times include no rejection.
    pub depth_id: Vec<(usize, TileStats)>,
    /// The steady clock's record: its canary, warm-ups, retaken rounds; `None` without one.
    pub stability: Option<Stability>,
    /// The table's round at which the busy threads started, if they started part way.
    pub load_from_round: Option<usize>,
}

impl CompareReport {
    /// The coverage from which stencil stays faster than branching at every larger swept size:
    /// interpolated (in log coverage) between the largest size where branching is still at least
    /// as fast and the next. `None` when branching wins at the largest size; the smallest swept
    /// coverage when stencil wins everywhere. Single points that flip within the timing noise
    /// below a stencil-winning stretch do not move it.
    pub fn measured_crossover(&self) -> Option<f64> {
        let gains: Vec<(f64, f64)> = self
            .sizes
            .iter()
            .map(|p| (p.coverage, p.branching.median_ms - p.stencil.median_ms))
            .collect();
        stencil_wins_from(&gains)
    }
}

impl CompareReport {
    /// The crossover as a band: the smallest swept coverage from which stencil is faster
    /// (beyond the margin, [`Verdict`]) at every larger size, and the largest up to which
    /// branching is, likewise. Between them the techniques are within the margin or the data
    /// cannot say.
    pub fn crossover_bounds(&self) -> (Option<f64>, Option<f64>) {
        let verdicts: Vec<(f64, Verdict)> = self
            .sizes
            .iter()
            .map(|p| (p.coverage, p.stencil_over_branching().1))
            .collect();
        sure_bounds(&verdicts)
    }
}

/// See [`CompareReport::crossover_bounds`]; `verdicts` of stencil over branching by increasing
/// coverage.
fn sure_bounds(verdicts: &[(f64, Verdict)]) -> (Option<f64>, Option<f64>) {
    let stencil_from = verdicts
        .iter()
        .rposition(|(_, v)| *v != Verdict::Faster)
        .map_or(Some(0), |i| (i + 1 < verdicts.len()).then_some(i + 1))
        .and_then(|i| verdicts.get(i).map(|p| p.0));
    let branching_until = verdicts
        .iter()
        .position(|(_, v)| *v != Verdict::Slower)
        .map_or(verdicts.len(), |i| i)
        .checked_sub(1)
        .map(|i| verdicts[i].0);
    (stencil_from, branching_until)
}

/// See [`CompareReport::measured_crossover`]; `gains` are `(coverage, branching - stencil ms)`
/// by increasing coverage.
fn stencil_wins_from(gains: &[(f64, f64)]) -> Option<f64> {
    match gains.iter().rposition(|g| g.1 <= 0.0) {
        None => gains.first().map(|g| g.0),
        Some(i) if i + 1 == gains.len() => None,
        Some(i) => {
            let ((ca, a), (cb, b)) = (gains[i], gains[i + 1]);
            let t = -a / (b - a);
            Some((ca.ln() + t * (cb.ln() - ca.ln())).exp())
        }
    }
}

/// Runs the comparison; `progress` is told what is being measured next.
pub fn run_compare(
    ctx: &Context,
    settings: &CompareSettings,
    progress: &mut dyn FnMut(&str),
) -> Result<CompareReport> {
    histencil_vk::check_extent(ctx, settings.width, settings.height).map(drop)?;
    if settings.brdf_counts.first() != Some(&1) {
        return Err(crate::LabError::Settings(
            "the BRDF counts must start at 1: overheads are against the 1-BRDF time".into(),
        ));
    }
    let widest = settings.brdf_counts.iter().copied().max().unwrap_or(1);
    crate::variants::check_palette(&settings.scene, widest, &settings.brdfs.set)?;
    // Spins until the report is made, when it drops (from the table's round the settings say,
    // if they say one: `measure_table` starts it there).
    let _load = crate::measure::BusyThreads::start(if settings.load_from_round.is_some() {
        0
    } else {
        settings.beside_load
    });
    let mut steady = match settings.clock {
        Some(clock) => {
            let scene = with_brdf_count(&settings.scene, 1);
            let renderer = renderer_for(ctx, settings, scene)?;
            let (name, w, h) = (&settings.scene.name, settings.width, settings.height);
            SteadyClock::new(renderer, &format!("`{name}` at 1 BRDF, {w}x{h}"), clock)?
        }
        None => SteadyClock::off(),
    };
    let sampling = Sampling {
        min_rounds: settings.frames.max(1),
        target: settings.target_ci,
        budget: settings.budget,
        max_rounds: MAX_ROUNDS,
        until_decided: settings.until_decided,
        predict_budget: settings.predict_budget,
    };
    let mut table = measure_table(ctx, settings, &sampling, &mut steady, progress)?;
    // The stencil rows' per-pass breakdown, on the widest column's renderer.
    let mut breakdowns = Vec::new();
    if let Some((brdfs, renderer)) = table.widest.as_mut() {
        for (name, technique) in table_rows()
            .iter()
            .filter(|(n, _)| n.starts_with("stencil"))
        {
            progress(&format!("{brdfs} BRDF(s): {name} pass breakdown"));
            breakdowns.push(breakdown(
                renderer,
                name,
                *technique,
                *brdfs,
                settings.frames,
            )?);
        }
    }
    drop(table.widest);
    let sizes = measure_sizes(ctx, settings, &sampling, &mut steady, progress)?;
    Ok(CompareReport {
        device: ctx.device_name().to_owned(),
        driver: ctx.driver().to_string(),
        scene: settings.scene.name.clone(),
        scene_lights: settings.scene.lights.len(),
        models: brdf_palette(
            &settings.scene,
            settings.brdf_counts.iter().copied().max().unwrap_or(1),
        )
        .iter()
        .map(|b| b.name().to_owned())
        .collect(),
        engine_brdfs: settings
            .brdfs
            .set
            .engine()
            .map(|(_, spec)| spec.name.clone())
            .collect(),
        lut_left_out: lut_refusal(ctx, settings)?,
        first_left_out: table.first_left_out,
        width: settings.width,
        height: settings.height,
        frames: settings.frames,
        rows: table.rows,
        breakdowns,
        sizes,
        sampled: table.sampled,
        target_ci: settings.target_ci,
        lp_num_threads: std::env::var("LP_NUM_THREADS").ok(),
        beside_load: settings.beside_load,
        depth_bounds: ctx.depth_bounds(),
        costs: table.costs,
        costs_calibrated: settings.costs.is_some(),
        depth_id: table.depth_id,
        stability: steady.into_stability(),
        load_from_round: settings
            .load_from_round
            .filter(|_| settings.beside_load > 0),
    })
}

#[cfg(test)]
mod tests {
    use super::{stencil_wins_from, sure_bounds, talk_verdicts, Cell, Row};
    use crate::stats::Verdict::{Faster, Slower, Undecided, Within};

    /// The talk's verdicts pair each stencil row with branching round by round, at the same
    /// BRDF count: a load that slows a round slows both, and the ratio holds.
    #[test]
    fn the_talks_verdicts_pair_stencil_with_branching_by_round() {
        let row = |name: &'static str, per_count: [f64; 3]| Row {
            name,
            cells: per_count
                .iter()
                .enumerate()
                .map(|(i, ms)| Cell {
                    brdfs: i + 1,
                    // Every round twice as slow as the one before: only pairing survives it.
                    samples: (0..12).map(|r| ms * f64::from(1 << (r % 3))).collect(),
                    bookkeeping: Vec::new(),
                    single_brdf: Vec::new(),
                    error: Default::default(),
                })
                .collect(),
        };
        let rows = [
            row("branching", [1.0, 2.0, 3.0]),
            row("stencil ps3", [1.0, 1.6, 3.3]),
            row("stencil native", [1.0, 2.02, 3.0]),
            row("lut", [1.0, 1.0, 1.0]),
        ];
        let v = talk_verdicts(&rows);
        let got: Vec<_> = v
            .iter()
            .map(|v| (v.technique, v.brdfs, v.verdict))
            .collect();
        assert_eq!(
            got,
            [
                ("stencil ps3", 2, Faster),
                ("stencil ps3", 3, Slower),
                ("stencil native", 2, Within),
                ("stencil native", 3, Within),
            ]
        );
        assert!((v[0].ratio.median - 0.8).abs() < 1e-12 && v[0].ratio.lo == v[0].ratio.hi);
        assert_eq!(v[0].words(), "stencil faster");
        assert_eq!(v[1].words(), "branching faster");
        assert!(v.iter().all(|v| v.against == "branching"));
        assert!(talk_verdicts(&rows[1..]).is_empty());
    }

    #[test]
    fn the_crossover_bounds_rest_on_separated_intervals_only() {
        let v = [
            (0.001, Slower),
            (0.01, Slower),
            (0.03, Undecided),
            (0.1, Within),
            (0.3, Faster),
            (1.0, Faster),
        ];
        assert_eq!(sure_bounds(&v), (Some(0.3), Some(0.01)));
        // A tie at the largest size: stencil is never surely faster for good; the band
        // between the bounds holds the undecided and the within-margin sizes.
        assert_eq!(sure_bounds(&[(0.1, Faster), (1.0, Within)]), (None, None));
        assert_eq!(
            sure_bounds(&[(0.1, Faster), (1.0, Undecided)]),
            (None, None)
        );
        assert_eq!(
            sure_bounds(&[(0.1, Faster), (1.0, Faster)]),
            (Some(0.1), None)
        );
        assert_eq!(
            sure_bounds(&[(0.1, Slower), (1.0, Slower)]),
            (None, Some(1.0))
        );
        assert_eq!(sure_bounds(&[]), (None, None));
    }

    #[test]
    fn the_crossover_is_where_stencil_starts_to_win_for_good() {
        assert_eq!(stencil_wins_from(&[(0.01, 1.0), (1.0, 2.0)]), Some(0.01));
        assert_eq!(stencil_wins_from(&[(0.01, -1.0), (1.0, -2.0)]), None);
        // Branching ahead by 1 ms at 1 %, stencil ahead by 1 ms at 100 %: halfway in log.
        let x = stencil_wins_from(&[(0.001, 3.0), (0.01, -1.0), (1.0, 1.0)]).unwrap();
        assert!((x - 0.1).abs() < 1e-12, "{x}");
    }
}
