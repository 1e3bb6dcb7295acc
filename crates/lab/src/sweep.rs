//! `histencil sweep`: one setting against speed and error, with its Pareto front.
//!
//! - `lut-res`: the LUT technique's table resolution; lighting time against error of the frame
//!   against forward.
//! - `lightmap-res`: the alpha entities' lightmap side; lightmap + alpha pass time against the
//!   error over the pixels the entities cover, against forward-lit alpha.
//! - `slices`: every camera-facing particle system's slice count (1: a billboard), its side
//!   still chosen by the estimate; the same times and error.
//!
//! The alpha sweeps also report the largest estimated error over the entities
//! (`estimate_mean`, `histencil_alpha::choose_parameters`), so the estimate can be read against
//! what was measured.
//! - `tile-size`: the hi-stencil tile size. The GPU emulation's tile size is a shader constant,
//!   so this one runs the hi-stencil simulator on the GPU's own captured light footprints (the
//!   simulator agrees with the GPU at that size, `render --stats`). Culling is exact at every
//!   size, so there is no error to trade, and the fragments shaded are the same at every size:
//!   the trade is tile tests (the culling surface's work) against the pixels left in unculled
//!   tiles (the per-pixel stencil test's work; an upper bound, as edge tiles are partly outside
//!   the light's footprint).

use crate::image_error::{image_error, ImageError};
use crate::measure::{frame, time_lighting, time_passes, Timing, WARM_UP_FRAMES};
use crate::plot::{self, Axis};
use crate::stats::RoundStart;
use crate::steady::{ClockSettings, Stability, SteadyClock};
use crate::variants::with_brdf_count;
use crate::{write_file, AlphaReference, LabError, Result};
use histencil_scene::{ParticleLayout, ParticleSystem, Scene, MAX_SLICES};
use histencil_vk::passes::names;
use histencil_vk::{Backend, Context, FlushPolicy, Renderer, RendererDesc, Shading, Technique};
use serde_json::{json, Value};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// What the alpha sweeps time: the lightmaps and the alpha pass that reads them.
const ALPHA_PASSES: &[&str] = &[names::ALPHA_LIGHTMAPS, names::ALPHA];

/// The setting a sweep varies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SweepParam {
    LutRes,
    LightmapRes,
    Slices,
    TileSize,
}

impl SweepParam {
    pub fn name(self) -> &'static str {
        match self {
            SweepParam::LutRes => "lut-res",
            SweepParam::LightmapRes => "lightmap-res",
            SweepParam::Slices => "slices",
            SweepParam::TileSize => "tile-size",
        }
    }

    pub fn default_values(self) -> Vec<u32> {
        match self {
            SweepParam::LutRes => vec![8, 16, 32, 64, 96],
            SweepParam::LightmapRes => vec![4, 8, 16, 32, 64, 128],
            SweepParam::Slices => vec![1, 2, 4, 8, 16, 32],
            SweepParam::TileSize => vec![2, 4, 8, 16, 32, 64],
        }
    }

    /// The embedded scene that exercises the setting: Blinn-Phong up to 256 for the LUT, glass and
    /// smoke for the lightmaps, a thick smoke ball around a light for the slices, tiny to huge
    /// lights for the tiles.
    pub fn default_scene(self) -> &'static str {
        match self {
            SweepParam::LutRes | SweepParam::TileSize => "default",
            SweepParam::LightmapRes => "alpha",
            SweepParam::Slices => "volume",
        }
    }

    /// `(speed column, error column)` names and the speed unit.
    fn columns(self) -> (&'static str, &'static str) {
        match self {
            SweepParam::LutRes => ("lighting_ms", "mean error, 8-bit steps"),
            SweepParam::LightmapRes | SweepParam::Slices => {
                ("alpha_ms", "mean error over alpha pixels, 8-bit steps")
            }
            SweepParam::TileSize => ("tiles_tested", "pixels in unculled tiles"),
        }
    }
}

/// One setting's measurements.
#[derive(Clone, Debug)]
pub struct SweepPoint {
    pub setting: u32,
    /// Milliseconds for timed settings; tile tests for `tile-size`.
    pub speed: Timing,
    pub error: ImageError,
    /// Further figures: `(name, value)`.
    pub extra: Vec<(&'static str, f64)>,
}

/// A sweep's measurements.
#[derive(Clone, Debug)]
pub struct SweepReport {
    pub device: String,
    /// The driver as Vulkan names it (name, build, conformance) and the validation layer: two
    /// builds of one driver share a device name.
    pub driver: String,
    pub param: SweepParam,
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub frames: usize,
    pub points: Vec<SweepPoint>,
    /// The steady clock's record (`None` without the clock, and for tile sizes, which are
    /// simulated, not timed): each value's timing is a round, retaken where the canary strayed.
    pub stability: Option<Stability>,
}

/// Every value of `values` in `param`'s range, so that a sweep refuses a bad value before it
/// renders anything rather than after the good ones before it.
///
/// # Errors
/// [`LabError::Settings`] (slices, tile sizes) or the renderer's own error (LUT resolution,
/// lightmap side) naming the first value out of range.
pub fn check_values(param: SweepParam, values: &[u32], width: u32, height: u32) -> Result<()> {
    for &value in values {
        match param {
            SweepParam::LutRes => histencil_brdf::lut::Lut::check_resolution(value)
                .map_err(histencil_vk::Error::from)?,
            SweepParam::LightmapRes => {
                histencil_alpha::check_forced_side(value).map_err(histencil_vk::Error::from)?
            }
            SweepParam::Slices if !(1..=MAX_SLICES).contains(&value) => {
                return Err(LabError::Settings(format!(
                    "{value} slices: a system has 1 (a billboard) to {MAX_SLICES}"
                )))
            }
            SweepParam::TileSize if value == 0 || value > width.max(height) => {
                return Err(LabError::Settings(format!(
                    "tile size {value} must be between 1 and the frame's larger side"
                )))
            }
            SweepParam::Slices | SweepParam::TileSize => {}
        }
    }
    Ok(())
}

/// Measures `scene` at every value, each value's timing a round of the steady clock where
/// `clock` asks for one (its canary branching's lighting on `scene` at 1 BRDF); `progress` is
/// told each value measured and each retake.
#[allow(clippy::too_many_arguments)]
pub fn run_sweep(
    ctx: &Context,
    scene: Scene,
    param: SweepParam,
    values: &[u32],
    (width, height): (u32, u32),
    frames: usize,
    clock: Option<ClockSettings>,
    progress: &mut dyn FnMut(&str),
) -> Result<SweepReport> {
    histencil_vk::check_extent(ctx, width, height).map(drop)?;
    if values.is_empty() {
        return Err(LabError::Settings("no values to sweep".into()));
    }
    if param == SweepParam::LightmapRes && scene.alpha_entity_count() == 0 {
        return Err(LabError::Settings(format!(
            "scene `{}` has no alpha objects or particles to light",
            scene.name
        )));
    }
    if param == SweepParam::Slices && sliceable(&scene).next().is_none() {
        return Err(LabError::Settings(format!(
            "scene `{}` has no camera-facing particle systems to slice",
            scene.name
        )));
    }
    check_values(param, values, width, height)?;
    let name = scene.name.clone();
    let original = scene.clone();
    let mut steady = match clock.filter(|_| param != SweepParam::TileSize) {
        Some(settings) => {
            let canary = Renderer::new(ctx, with_brdf_count(&scene, 1), width, height)?;
            let what = format!("`{name}` at 1 BRDF, {width}x{height}");
            SteadyClock::new(canary, &what, settings)?
        }
        None => SteadyClock::off(),
    };
    let set = format!("{} on {name}", param.name());
    steady.begin_set(&set, progress)?;
    let start = std::time::Instant::now();
    // Value `i`'s round: its place in the set, for the clock and the progress lines.
    let round = |i: usize| RoundStart {
        index: i,
        seconds: start.elapsed().as_secs_f64(),
        budget_seconds: f64::INFINITY,
        pilot: None,
        predicted_rounds: None,
        fixed_rounds: Some(values.len()),
        open: None,
    };
    let total = values.len();
    let measured = |i: usize| format!("{set}: {} of {total} values measured", i + 1);
    let mut renderer = Renderer::new(ctx, scene, width, height)?;
    let mut points = Vec::new();
    match param {
        SweepParam::LutRes => {
            let reference = frame(&mut renderer, Shading::Forward)?;
            // Each point has a renderer of its own.
            drop(renderer);
            let lut = Technique::Lut {
                backend: Backend::Native,
                flush: FlushPolicy::Auto,
            };
            for (i, &res) in values.iter().enumerate() {
                let desc = RendererDesc {
                    lut_resolution: res,
                    ..RendererDesc::new(width, height)
                };
                let mut renderer = Renderer::with_desc(ctx, original.clone(), &desc)?;
                let mut timed = || time_lighting(&mut renderer, lut, frames);
                let speed = steady.round(&round(i), progress, &mut timed)?;
                let error = image_error(&frame(&mut renderer, lut)?, &reference);
                let bytes = renderer.lut_tables()?.size_bytes();
                points.push(SweepPoint {
                    setting: res,
                    speed,
                    error,
                    extra: vec![("table_bytes", bytes as f64)],
                });
                progress(&measured(i));
            }
        }
        SweepParam::LightmapRes => {
            let technique = Technique::DEFERRED;
            let reference = AlphaReference::render(ctx, &mut renderer, technique)?;
            drop(renderer);
            for (i, &side) in values.iter().enumerate() {
                let desc = RendererDesc {
                    lightmap_side: Some(side),
                    ..RendererDesc::new(width, height)
                };
                let mut renderer = Renderer::with_desc(ctx, original.clone(), &desc)?;
                let mut timed = || time_passes(&mut renderer, technique, ALPHA_PASSES, frames);
                let speed = steady.round(&round(i), progress, &mut timed)?;
                let lit = frame(&mut renderer, technique)?;
                let masked = reference.error(&lit);
                let whole = image_error(&lit, &reference.forward);
                points.push(alpha_point(&mut renderer, side, speed, &masked, &whole)?);
                progress(&measured(i));
            }
        }
        SweepParam::Slices => {
            let technique = Technique::DEFERRED;
            let reference = AlphaReference::render(ctx, &mut renderer, technique)?;
            drop(renderer);
            for (i, &count) in values.iter().enumerate() {
                let mut scene = original.clone();
                for system in sliceable_mut(&mut scene) {
                    system.layout = match count {
                        1 => ParticleLayout::Billboard,
                        count => ParticleLayout::Slices { count },
                    };
                }
                let mut renderer = Renderer::new(ctx, scene, width, height)?;
                let mut timed = || time_passes(&mut renderer, technique, ALPHA_PASSES, frames);
                let speed = steady.round(&round(i), progress, &mut timed)?;
                let lit = frame(&mut renderer, technique)?;
                let masked = reference.error(&lit);
                let whole = image_error(&lit, &reference.forward);
                points.push(alpha_point(&mut renderer, count, speed, &masked, &whole)?);
                progress(&measured(i));
            }
        }
        SweepParam::TileSize => {
            let technique = Technique::Stencil {
                backend: Backend::X360 {
                    zero_preserved: true,
                    save_restore: false,
                },
                flush: FlushPolicy::Auto,
            };
            let mut inputs = renderer.simulator_inputs(technique)?;
            for (i, &tile) in values.iter().enumerate() {
                inputs.tile_size = tile;
                let stats = inputs.predict().0.stats;
                let tested = stats.tiles_tested as f64;
                points.push(SweepPoint {
                    setting: tile,
                    speed: Timing {
                        median_ms: tested,
                        min_ms: tested,
                        max_ms: tested,
                    },
                    error: ImageError {
                        max: 0.0,
                        mean: ((stats.tiles_tested - stats.tiles_culled) * u64::from(tile * tile))
                            as f64,
                        flip: 0.0,
                    },
                    extra: vec![
                        ("tiles_culled", stats.tiles_culled as f64),
                        ("fragments_shaded", stats.fragments_shaded as f64),
                        ("flushes", stats.flushes as f64),
                    ],
                });
                progress(&measured(i));
            }
        }
    }
    Ok(SweepReport {
        device: ctx.device_name().to_owned(),
        driver: ctx.driver().to_string(),
        param,
        scene: name,
        width,
        height,
        frames,
        points,
        stability: steady.into_stability(),
    })
}

/// The camera-facing particle systems of `scene` (billboards, slices, automatic): the ones
/// whose slice count a sweep may set.
fn sliceable(scene: &Scene) -> impl Iterator<Item = &ParticleSystem> {
    scene
        .particle_systems
        .iter()
        .filter(|s| !matches!(s.layout, ParticleLayout::Dust | ParticleLayout::Ribbon))
}

fn sliceable_mut(scene: &mut Scene) -> impl Iterator<Item = &mut ParticleSystem> {
    scene
        .particle_systems
        .iter_mut()
        .filter(|s| !matches!(s.layout, ParticleLayout::Dust | ParticleLayout::Ribbon))
}

/// One alpha sweep point: the error over the alpha pixels (FLIP over the whole frame), with the
/// atlas, the draws and the largest estimated error beside it.
fn alpha_point(
    renderer: &mut Renderer,
    setting: u32,
    speed: Timing,
    masked: &histencil_vk::MaskedError,
    whole: &ImageError,
) -> Result<SweepPoint> {
    let atlas = renderer
        .lightmap_layout()?
        .map_or(0, |layout| layout.atlas.size().0);
    let estimate = renderer
        .lightmap_parameters()?
        .iter()
        .map(|p| f64::from(p.estimate.mean))
        .fold(0.0, f64::max);
    Ok(SweepPoint {
        setting,
        speed,
        error: ImageError {
            max: f64::from(masked.max),
            mean: masked.mean,
            flip: whole.flip,
        },
        extra: vec![
            ("alpha_pixels", masked.pixels as f64),
            ("atlas_side", f64::from(atlas)),
            ("lightmap_draws", renderer.lightmap_draws()? as f64),
            ("estimate_mean", estimate),
        ],
    })
}

impl SweepReport {
    /// Writes `sweep.csv`, `sweep.json` and `pareto.png` into `dir`; returns their paths.
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>> {
        let csv = dir.join("sweep.csv");
        write_file(&csv, self.csv().as_bytes())?;
        let js = dir.join("sweep.json");
        crate::write_json(&js, &self.json())?;
        let png = dir.join("pareto.png");
        let (speed, error) = self.param.columns();
        let points: Vec<(f64, f64, String)> = self
            .points
            .iter()
            .map(|p| (p.speed.median_ms, p.error.mean, p.setting.to_string()))
            .collect();
        plot::pareto_chart(
            &png,
            &format!(
                "{} sweep on {} ({})",
                self.param.name(),
                self.scene,
                self.device
            ),
            Axis {
                label: speed,
                log: false,
            },
            Axis {
                label: error,
                log: self.param == SweepParam::TileSize,
            },
            &points,
        )?;
        Ok(vec![csv, js, png])
    }

    fn csv(&self) -> String {
        let (speed, _) = self.param.columns();
        let mut out = if self.param == SweepParam::TileSize {
            "tile_size,tiles_tested,unculled_tile_pixels".to_owned()
        } else {
            format!(
                "{},{speed},{speed}_min,{speed}_max,error_max,error_mean,flip",
                self.param.name().replace('-', "_")
            )
        };
        for (name, _) in self.points.first().map_or(&[][..], |p| &p.extra[..]) {
            let _ = write!(out, ",{name}");
        }
        out.push('\n');
        for p in &self.points {
            if self.param == SweepParam::TileSize {
                let _ = write!(out, "{},{},{}", p.setting, p.speed.median_ms, p.error.mean);
            } else {
                let _ = write!(
                    out,
                    "{},{},{},{},{},{},{}",
                    p.setting,
                    p.speed.median_ms,
                    p.speed.min_ms,
                    p.speed.max_ms,
                    p.error.max,
                    p.error.mean,
                    p.error.flip
                );
            }
            for (_, v) in &p.extra {
                let _ = write!(out, ",{v}");
            }
            out.push('\n');
        }
        out
    }

    /// Every figure of the sweep; all numbers are finite.
    pub fn json(&self) -> Value {
        let (speed, _) = self.param.columns();
        let points: Vec<Value> = self
            .points
            .iter()
            .map(|p| {
                let mut v = json!({ "setting": p.setting });
                if self.param == SweepParam::TileSize {
                    v["tiles_tested"] = json!(p.speed.median_ms);
                    v["unculled_tile_pixels"] = json!(p.error.mean);
                } else {
                    v[speed] = json!({"median": p.speed.median_ms, "min": p.speed.min_ms,
                                      "max": p.speed.max_ms});
                    v["error"] = json!({"max": p.error.max, "mean": p.error.mean,
                                        "flip": p.error.flip});
                }
                for (name, value) in &p.extra {
                    v[*name] = json!(value);
                }
                v
            })
            .collect();
        let mut out = json!({
            "device": self.device,
            "driver": self.driver,
            "param": self.param.name(),
            "settings": {"scene": self.scene, "width": self.width, "height": self.height,
                         "frames": self.frames, "warm_up_frames": WARM_UP_FRAMES},
            "points": points,
        });
        if let Some(stability) = &self.stability {
            out["stability"] = stability.json();
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each setting's range, at both ends and past them, and a bad value anywhere in the list
    /// (not only the first) refuses the whole sweep.
    #[test]
    fn values_outside_each_settings_range_are_refused_up_front() {
        let (w, h) = (160, 90);
        let cases = [
            (
                SweepParam::LutRes,
                2,
                histencil_brdf::lut::Lut::MAX_RESOLUTION,
            ),
            (SweepParam::LightmapRes, 2, histencil_alpha::MAX_FORCED_SIDE),
            (SweepParam::Slices, 1, MAX_SLICES),
            (SweepParam::TileSize, 1, w.max(h)),
        ];
        for (param, lo, hi) in cases {
            check_values(param, &[lo, hi], w, h).unwrap_or_else(|e| panic!("{param:?}: {e}"));
            for bad in [lo - 1, hi + 1, u32::MAX] {
                let err = check_values(param, &[lo, hi, bad], w, h)
                    .expect_err(&format!("{param:?} {bad}"));
                assert!(err.to_string().contains(&bad.to_string()), "{err}");
            }
        }
    }
}
