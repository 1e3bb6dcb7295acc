//! `histencil calibrate`: this device's costs for the adaptive technique's [`CostModel`].
//!
//! The model (see `histencil_model::CostModel`) prices the BRDFs beyond the first of a light
//! covering `c` of the screen and touching `n` BRDFs at `(n - 1) * (2 * overhead + c * stencil)`
//! with stencil and `(n - 1) * c * tax` with branching. Two light sizes on the same striped wall
//! give two equations for stencil's unknowns:
//!
//! ```text
//! full-screen lights:   a = stencil extra per light / (n - 1) = 2 * overhead + s
//! small lights (c):     b = stencil extra per light / (n - 1) = 2 * overhead + c * s
//! => s = (a - b) / (1 - c),   overhead = (a - s) / 2
//! ```
//!
//! The branch tax is branching's extra per full-screen light per extra BRDF, and the shade cost
//! the 1-BRDF time per full-screen light. Extras are each technique's 3-BRDF time minus its own
//! 1-BRDF time on the same wall, so what both share (setup, cleanup, the shading itself) cancels.
//!
//! The tiled technique's two costs come from its frames on the full-screen wall in 3 BRDFs
//! (mixed tiles included): the classification pass per frame, and the shading per light.
//!
//! Each BRDF's weight (`brdf_weights`, what branching's tax is weighted by) is its full-screen
//! 1-BRDF time per light over the mean of the weighed BRDFs' times in the same round: the wall's
//! three BRDFs and every engine BRDF of the set. That time includes what every BRDF shares (the
//! G-buffer decode, the light, the blend), so the weights understate how far apart the BRDFs'
//! own code is: the chooser moves less on them than the code would justify, never more.

use crate::measure::{Timing, WARM_UP_FRAMES};
use crate::stats::{median_interval, sample, Interval, Sampled, Sampling};
use crate::steady::{ClockSettings, Stability, SteadyClock};
use crate::variants::{brdf_palette, light_size_scene, with_brdf_count, with_one_brdf};
use crate::{LabError, Result};
use histencil_model::{DepthIdCosts, TiledCosts, COST_FIELDS, DEPTH_ID_FIELDS, TILED_FIELDS};
use histencil_vk::passes::names;
use histencil_vk::{
    Backend, BrdfModules, Context, CostModel, FlushPolicy, MixedTiles, Renderer, RendererDesc,
    Technique, TileSide,
};
use serde_json::{json, Value};
use std::path::Path;

/// Coverage of the small lights: large enough that each touches two or three stripes.
const SMALL_COVERAGE: f64 = 0.01;

/// The fitted costs and what they were fitted to.
#[derive(Clone, Debug)]
pub struct Calibration {
    pub device: String,
    /// The driver as Vulkan names it (name, build, conformance) and the validation layer: two
    /// builds of one driver share a device name.
    pub driver: String,
    pub width: u32,
    pub height: u32,
    /// Rounds taken (each renders one frame of every measured kind, interleaved).
    pub frames: usize,
    /// The median over rounds of each round's fit, with the 95 % intervals in
    /// [`CostModel::interval`].
    pub costs: CostModel,
    /// Each weighed BRDF's name and weight with its 95 % interval (see the module doc): what
    /// the costs file's `brdf_weights` holds.
    pub brdf_weights: Vec<(String, Interval)>,
    /// How the sampling ended.
    pub sampled: Sampled,
    /// `(what, lighting time)` of every measured frame kind.
    pub measurements: Vec<(String, Timing)>,
    /// The steady clock's record: its canary's warm-ups and times, and the rounds it retook
    /// (`None` without the clock). A cost fitted from rounds whose clock moved would steer the
    /// adaptive technique wrong on every frame after.
    pub stability: Option<Stability>,
}

/// One measured frame kind: the wall at a coverage, a BRDF count, a technique.
struct Kind {
    what: String,
    renderer: usize,
    technique: Technique,
    /// Per-light lighting time of every round.
    per_light_ms: Vec<f64>,
    /// The tiled classification of every round (per frame; empty for other techniques).
    classify_ms: Vec<f64>,
}

/// The costs each round fits: the four of [`COST_FIELDS`], then the two of [`TILED_FIELDS`],
/// then the two of [`DEPTH_ID_FIELDS`].
const FITTED: usize = 8;

/// Measures the six costs at `width` x `height` over interleaved rounds (at least
/// `sampling.min_rounds`, until each cost's interval is within the target or the budget is
/// spent); every round fits all four costs from its own frames, and each cost is the median of
/// those fits with its order-statistic interval. `progress` is told each step.
pub fn calibrate(
    ctx: &Context,
    width: u32,
    height: u32,
    sampling: &Sampling,
    progress: &mut dyn FnMut(&str),
) -> Result<Calibration> {
    let clock = Some(ClockSettings::default());
    let modules = BrdfModules::builtin();
    calibrate_with(ctx, (width, height), modules, sampling, clock, progress)
}

/// [`calibrate`] with the wall striped in `brdfs`' engine BRDFs, when it has any (`calibrate
/// --brdfs`): the costs are then those of the engine's shading models, averaged over them, which
/// the adaptive technique takes through `--costs`; with `clock`, every round kept by the steady
/// clock ([`crate::steady`]: branching's lighting on the full-screen wall at 1 BRDF its canary),
/// without it every round kept as taken.
///
/// # Errors
/// As [`calibrate`].
pub fn calibrate_with(
    ctx: &Context,
    (width, height): (u32, u32),
    modules: &'static BrdfModules,
    sampling: &Sampling,
    clock: Option<ClockSettings>,
    progress: &mut dyn FnMut(&str),
) -> Result<Calibration> {
    // Before the wall is built: its shape follows the aspect ratio.
    histencil_vk::check_extent(ctx, width, height).map(drop)?;
    let aspect = width as f32 / height as f32;
    let (backend, flush) = (Backend::Native, FlushPolicy::Auto);
    let stencil = Technique::Stencil { backend, flush };
    let branching = Technique::Branching { backend, flush };
    // The side the adaptive technique resolves to on this device.
    let side = TileSide::for_context(ctx);
    let tiled = Technique::Tiled {
        mixed: MixedTiles::PerBrdf,
        side,
    };
    let depth_id = Technique::DepthId { side };
    // Full-screen lights: branching, stencil, tiled and depth-id; small lights: stencil. 1 and
    // 3 BRDFs each.
    let walls = [
        (1.0, vec![branching, stencil, tiled, depth_id]),
        (SMALL_COVERAGE, vec![stencil]),
    ];
    // Every renderer of the calibration: at its size, in the modules' BRDFs, lighting the wall
    // at a coverage in those BRDFs.
    let desc = RendererDesc {
        brdfs: modules,
        ..RendererDesc::new(width, height)
    };
    let wall_at = |coverage: f64| {
        let mut wall = light_size_scene(coverage, aspect);
        histencil_scene::retarget_brdfs(&mut wall, &modules.set);
        wall
    };
    let mut renderers = Vec::new();
    let mut kinds = Vec::new();
    // Extra BRDFs each light touches, on average (small lights at the wall's edge miss one).
    let mut extra_brdfs = Vec::new();
    for (coverage, techniques) in &walls {
        let wall = wall_at(*coverage);
        crate::variants::check_palette(&wall, 3, &modules.set)?;
        let lights = wall.lights.len() as f64;
        let touched = wall
            .lights
            .iter()
            .map(|l| wall.brdfs_lit_by(l).len() as f64)
            .sum::<f64>();
        extra_brdfs.push((touched / lights - 1.0).max(1e-6));
        for brdfs in [1, 3] {
            progress(&format!("coverage {coverage}, {brdfs} BRDF(s): building"));
            let mut renderer = Renderer::with_desc(ctx, with_brdf_count(&wall, brdfs), &desc)?;
            // Tiled is fitted from the 3-BRDF wall only.
            let measured = techniques
                .iter()
                .filter(|t| brdfs == 3 || !matches!(t, Technique::Tiled { .. }));
            for technique in measured {
                for _ in 0..WARM_UP_FRAMES {
                    renderer.render(*technique, histencil_vk::Readback::NONE)?;
                }
                kinds.push(Kind {
                    what: format!("{technique:?}, {brdfs} BRDF(s), coverage {coverage}"),
                    renderer: renderers.len(),
                    technique: *technique,
                    per_light_ms: Vec::new(),
                    classify_ms: Vec::new(),
                });
            }
            renderers.push((renderer, lights));
        }
    }
    // Each weighed BRDF alone on the full-screen wall, with single-BRDF lights.
    let weighed = weighed_brdfs(aspect, &modules.set);
    let first_weighed = kinds.len();
    for brdf in &weighed {
        let name = brdf.id().name();
        progress(&format!("{name} alone: building"));
        let wall = wall_at(1.0);
        let lights = wall.lights.len() as f64;
        let mut renderer = Renderer::with_desc(ctx, with_one_brdf(&wall, *brdf), &desc)?;
        for _ in 0..WARM_UP_FRAMES {
            renderer.render(stencil, histencil_vk::Readback::NONE)?;
        }
        kinds.push(Kind {
            what: format!("{name} alone, coverage 1"),
            renderer: renderers.len(),
            technique: stencil,
            per_light_ms: Vec::new(),
            classify_ms: Vec::new(),
        });
        renderers.push((renderer, lights));
    }
    let mut steady = match clock {
        Some(settings) => {
            let canary = Renderer::with_desc(ctx, with_brdf_count(&wall_at(1.0), 1), &desc)?;
            let scene = format!("the full-screen wall at 1 BRDF, {width}x{height}");
            SteadyClock::new(canary, &scene, settings)?
        }
        None => SteadyClock::off(),
    };
    steady.begin_set("the calibration", progress)?;
    // Kinds in push order: full 1 BRDF (branching, stencil, depth-id), full 3 (branching,
    // stencil, tiled, depth-id), small 1 (stencil), small 3 (stencil), then each weighed BRDF.
    let full_lights = renderers[0].1;
    let fit = |k: &[Kind], round: usize| -> [f64; FITTED] {
        let t = |i: usize| k[i].per_light_ms[round];
        let (shade, tax) = (t(0), (t(3) - t(0)) / extra_brdfs[0]);
        let a = (t(4) - t(1)) / extra_brdfs[0];
        let b = (t(8) - t(7)) / extra_brdfs[1];
        let per_brdf = (a - b) / (1.0 - SMALL_COVERAGE);
        let classify = k[5].classify_ms[round];
        // Depth-id per light: its BRDFs' full-screen passes shared by the wall's lights, and
        // each light's shading; two BRDFs more add two passes.
        let ids_per_brdf = (t(6) - t(2)) * full_lights / 2.0;
        let ids_shade = t(2) - ids_per_brdf / full_lights;
        [
            (a - per_brdf) / 2.0,
            per_brdf,
            tax,
            shade,
            classify,
            t(5),
            ids_per_brdf,
            ids_shade,
        ]
    };
    let kinds = std::cell::RefCell::new(kinds);
    let fits = std::cell::RefCell::new(Vec::<[f64; FITTED]>::new());
    let widths = || {
        let f = fits.borrow();
        (0..FITTED)
            .map(|i| median_interval(&f.iter().map(|x| x[i]).collect::<Vec<_>>()))
            .map(|iv| iv.relative_half_width())
            .collect()
    };
    let sampled = sample(
        sampling,
        |start: &crate::stats::RoundStart| -> Result<()> {
            progress(&start.line());
            let round = start.index;
            let mut k = kinds.borrow_mut();
            // One try of the round: every kind's per-light time and classification, committed
            // only once the steady clock keeps the try.
            let mut one_try = || -> Result<Vec<(f64, Option<f64>)>> {
                k.iter()
                    .map(|kind| {
                        let (renderer, lights) = &mut renderers[kind.renderer];
                        let t = renderer
                            .render(kind.technique, histencil_vk::Readback::NONE)?
                            .timings;
                        // A tiled frame's light lists cost per light, as its shading does.
                        let ms = t.pass_ms(names::LIGHTING).unwrap_or(0.0)
                            + t.pass_ms(names::TILE_LIGHTS).unwrap_or(0.0);
                        Ok((ms / *lights, t.pass_ms(names::TILE_CLASSIFY)))
                    })
                    .collect()
            };
            let kept = steady.round(start, progress, &mut one_try)?;
            for (kind, (per_light, classify)) in k.iter_mut().zip(kept) {
                kind.per_light_ms.push(per_light);
                kind.classify_ms.extend(classify);
            }
            fits.borrow_mut().push(fit(&k, round));
            Ok(())
        },
        widths,
    )?;
    let fits = fits.into_inner();
    let intervals: [Interval; FITTED] =
        std::array::from_fn(|i| median_interval(&fits.iter().map(|x| x[i]).collect::<Vec<_>>()));
    let m = |i: usize| intervals[i].median.max(0.0);
    let iv = |i: usize| (intervals[i].lo.max(0.0), intervals[i].hi.max(0.0));
    let costs = CostModel {
        slot_weights: None,
        pass_overhead_ms: m(0),
        stencil_per_brdf_ms: m(1),
        branch_tax_per_brdf_ms: m(2),
        shade_ms: m(3),
        interval: Some([iv(0), iv(1), iv(2), iv(3)]),
        tiled: Some(TiledCosts {
            classify_ms: m(4),
            shade_ms: m(5),
            interval: Some([iv(4), iv(5)]),
            depth_id: Some(DepthIdCosts {
                per_brdf_ms: m(6),
                shade_ms: m(7),
                interval: Some([iv(6), iv(7)]),
            }),
        }),
    };
    let kinds = kinds.into_inner();
    let weights_per_round: Vec<Vec<f64>> = (0..sampled.rounds)
        .map(|round| {
            let times: Vec<f64> = kinds[first_weighed..]
                .iter()
                .map(|k| k.per_light_ms[round])
                .collect();
            let mean = times.iter().sum::<f64>() / times.len() as f64;
            times.iter().map(|t| t / mean).collect()
        })
        .collect();
    let brdf_weights = weighed
        .iter()
        .enumerate()
        .map(|(i, brdf)| {
            let of_rounds: Vec<f64> = weights_per_round.iter().map(|w| w[i]).collect();
            (brdf.id().name().to_owned(), median_interval(&of_rounds))
        })
        .collect();
    let measurements = kinds
        .into_iter()
        .map(|k| (k.what, Timing::from_samples(k.per_light_ms)))
        .collect();
    Ok(Calibration {
        device: ctx.device_name().to_owned(),
        driver: ctx.driver().to_string(),
        width,
        height,
        frames: sampled.rounds,
        costs,
        brdf_weights,
        sampled,
        measurements,
        stability: steady.into_stability(),
    })
}

/// The BRDFs [`calibrate_with`] weighs: the full-screen wall's three, then every engine BRDF of
/// `set` they leave out (with its defaults).
fn weighed_brdfs(aspect: f32, set: &histencil_brdf::BrdfSet) -> Vec<histencil_brdf::Brdf> {
    let mut wall = light_size_scene(1.0, aspect);
    histencil_scene::retarget_brdfs(&mut wall, set);
    let mut out = brdf_palette(&wall, 3);
    for (id, _) in set.engine() {
        if out.iter().all(|b| b.id() != id) {
            out.push(
                set.engine_brdf(id.name(), &[])
                    .expect("an engine BRDF of the set with its defaults"),
            );
        }
    }
    out
}

impl Calibration {
    /// The costs at the top level (what [`read_costs`] reads), then the device, the settings and
    /// the measurements.
    pub fn json(&self) -> Value {
        let mut out = json!({
            "device": self.device,
            "driver": self.driver,
            "settings": {"width": self.width, "height": self.height, "frames": self.frames,
                         "warm_up_frames": WARM_UP_FRAMES},
            "measurements": self.measurements.iter().map(|(what, t)| json!({
                "what": what, "per_light_median_ms": t.median_ms, "min_ms": t.min_ms,
                "max_ms": t.max_ms,
            })).collect::<Vec<_>>(),
            "sampling": {"rounds": self.sampled.rounds, "stopped": self.sampled.stop.word(),
                         "seconds": self.sampled.seconds},
        });
        if let Some(stability) = &self.stability {
            out["stability"] = stability.json();
        }
        // The costs as `CostModel::from_json` reads them back: each group's costs by name, with
        // their intervals beside them.
        for (name, value) in costs_object(&COST_FIELDS, &self.costs.fields(), self.costs.interval) {
            out[name] = value;
        }
        if let Some(tiled) = self.costs.tiled {
            let mut t = costs_object(&TILED_FIELDS, &tiled.fields(), tiled.interval);
            if let Some(ids) = tiled.depth_id {
                let d = costs_object(&DEPTH_ID_FIELDS, &ids.fields(), ids.interval);
                t.insert("depth_id".into(), Value::Object(d));
            }
            out["tiled"] = Value::Object(t);
        }
        if let Some(x) = self.costs.crossover_coverage() {
            out["crossover_coverage"] = json!(x);
        }
        if !self.brdf_weights.is_empty() {
            let weights = |f: fn(&Interval) -> Value| -> serde_json::Map<String, Value> {
                self.brdf_weights
                    .iter()
                    .map(|(name, w)| (name.clone(), f(w)))
                    .collect()
            };
            out["brdf_weights"] = Value::Object(weights(|w| json!(w.median)));
            out["brdf_weight_intervals"] = Value::Object(weights(|w| json!([w.lo, w.hi])));
        }
        out
    }

    pub fn write(&self, path: &Path) -> Result<()> {
        crate::write_json(path, &self.json())
    }
}

/// `names` with their `values`, and an `intervals` object of `[lo, hi]` pairs when measured.
fn costs_object<const N: usize>(
    names: &[&str; N],
    values: &[f64; N],
    interval: Option<[(f64, f64); N]>,
) -> serde_json::Map<String, Value> {
    let mut object: serde_json::Map<String, Value> = names
        .iter()
        .zip(values)
        .map(|(name, value)| (name.to_string(), json!(value)))
        .collect();
    if let Some(iv) = interval {
        let intervals = names
            .iter()
            .zip(iv)
            .map(|(name, (lo, hi))| (name.to_string(), json!([lo, hi])))
            .collect();
        object.insert("intervals".into(), Value::Object(intervals));
    }
    object
}

/// Reads the costs a calibration wrote ([`CostModel::from_json`]), naming the file in errors.
pub fn read_costs(path: &Path) -> Result<CostModel> {
    let text = std::fs::read_to_string(path).map_err(|e| bad_costs(path, e.to_string()))?;
    CostModel::from_json(&text).map_err(|e| bad_costs(path, e.to_string()))
}

/// The BRDF weights of the costs at `path` for `set`'s BRDFs, or `None` where the file has
/// none; a name `set` does not hold is refused (costs calibrated with other BRDFs).
pub fn read_brdf_weights(
    path: &Path,
    set: &histencil_brdf::BrdfSet,
) -> Result<Option<histencil_brdf::BrdfWeights>> {
    let text = std::fs::read_to_string(path).map_err(|e| bad_costs(path, e.to_string()))?;
    let named = histencil_model::brdf_weights_from_json(&text)
        .map_err(|e| bad_costs(path, e.to_string()))?;
    if named.is_empty() {
        return Ok(None);
    }
    histencil_brdf::BrdfWeights::by_name(set, &named)
        .map(Some)
        .map_err(|e| bad_costs(path, e.to_string()))
}

fn bad_costs(path: &Path, problem: String) -> LabError {
    LabError::Costs {
        path: path.display().to_string(),
        problem,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn costs_round_trip_and_bad_files_are_named() {
        let dir = std::env::temp_dir().join(format!("histencil-costs-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let costs = CostModel {
            pass_overhead_ms: 0.01,
            stencil_per_brdf_ms: 0.2,
            branch_tax_per_brdf_ms: 0.5,
            shade_ms: 2.0,
            interval: Some([(0.0, 0.02), (0.1, 0.3), (0.5, 0.5), (1.5, 2.5)]),
            tiled: Some(TiledCosts {
                classify_ms: 0.4,
                shade_ms: 1.0,
                interval: Some([(0.3, 0.5), (0.9, 1.2)]),
                depth_id: Some(DepthIdCosts {
                    per_brdf_ms: 0.3,
                    shade_ms: 0.8,
                    interval: Some([(0.2, 0.4), (0.7, 0.9)]),
                }),
            }),
            slot_weights: None,
        };
        let calibration = Calibration {
            device: "test".into(),
            driver: "test driver".into(),
            width: 64,
            height: 64,
            frames: 1,
            costs,
            brdf_weights: vec![
                (
                    "ggx".into(),
                    Interval {
                        median: 1.2,
                        lo: 1.1,
                        hi: 1.3,
                        samples: 5,
                        halves: None,
                    },
                ),
                (
                    "lambert".into(),
                    Interval {
                        median: 0.8,
                        lo: 0.7,
                        hi: 0.9,
                        samples: 5,
                        halves: None,
                    },
                ),
            ],
            sampled: Sampled {
                rounds: 1,
                stop: crate::stats::Stop::Rounds,
                widest: 0.0,
                seconds: 0.0,
                open: 0,
                prediction: None,
            },
            measurements: vec![],
            stability: None,
        };
        let path = dir.join("costs.json");
        calibration.write(&path).unwrap();
        assert_eq!(read_costs(&path).unwrap(), costs);
        let set = histencil_brdf::BrdfSet::new(&histencil_brdf::BrdfId::ALL, Vec::new()).unwrap();
        let weights = read_brdf_weights(&path, &set).unwrap().unwrap();
        assert_eq!(weights.get(histencil_brdf::BrdfId::Ggx), 1.2);
        let two = histencil_brdf::BrdfSet::new(&[histencil_brdf::BrdfId::Ggx], Vec::new()).unwrap();
        let err = read_brdf_weights(&path, &two).unwrap_err().to_string();
        assert!(
            err.contains("`lambert`") && err.contains("costs.json"),
            "{err}"
        );
        // Hand-written costs without intervals still read; a bad interval is named.
        std::fs::write(
            &path,
            r#"{"pass_overhead_ms": 0, "stencil_per_brdf_ms": 1, "branch_tax_per_brdf_ms": 2,
                "shade_ms": 3}"#,
        )
        .unwrap();
        assert_eq!(read_costs(&path).unwrap().interval, None);
        assert_eq!(read_brdf_weights(&path, &set).unwrap(), None);
        std::fs::write(
            &path,
            r#"{"pass_overhead_ms": 0, "stencil_per_brdf_ms": 1, "branch_tax_per_brdf_ms": 2,
                "shade_ms": 3, "intervals": {"pass_overhead_ms": [0, 1],
                "stencil_per_brdf_ms": [2, 3], "branch_tax_per_brdf_ms": [2, 2],
                "shade_ms": [3, 3]}}"#,
        )
        .unwrap();
        let err = read_costs(&path).unwrap_err().to_string();
        assert!(err.contains("intervals.stencil_per_brdf_ms"), "{err}");
        std::fs::write(&path, r#"{"pass_overhead_ms": -1}"#).unwrap();
        let err = read_costs(&path).unwrap_err().to_string();
        assert!(
            err.contains("pass_overhead_ms") && err.contains("costs.json"),
            "{err}"
        );
        std::fs::write(&path, "{").unwrap();
        assert!(read_costs(&path)
            .unwrap_err()
            .to_string()
            .contains("not JSON"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
