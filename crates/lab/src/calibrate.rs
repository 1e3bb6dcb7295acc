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

use crate::measure::{time_lighting, Timing, WARM_UP_FRAMES};
use crate::variants::{light_size_scene, with_brdf_count};
use crate::{LabError, Result};
use histencil_vk::{Backend, Context, CostModel, FlushPolicy, Renderer, Technique};
use serde_json::{json, Value};
use std::path::Path;

/// Coverage of the small lights: large enough that each touches two or three stripes.
const SMALL_COVERAGE: f64 = 0.01;

/// The fitted costs and what they were fitted to.
#[derive(Clone, Debug)]
pub struct Calibration {
    pub device: String,
    pub width: u32,
    pub height: u32,
    pub frames: usize,
    pub costs: CostModel,
    /// `(what, lighting time)` of every measured frame kind.
    pub measurements: Vec<(String, Timing)>,
}

/// Measures the four costs at `width` x `height`; `progress` is told each step.
pub fn calibrate(
    ctx: &Context,
    width: u32,
    height: u32,
    frames: usize,
    progress: &mut dyn FnMut(&str),
) -> Result<Calibration> {
    // Before the wall is built: its shape follows the aspect ratio.
    histencil_vk::check_extent(ctx, width, height).map(drop)?;
    let aspect = width as f32 / height as f32;
    let mut measurements = Vec::new();
    // Per technique: (1-BRDF time, extra time per extra BRDF), per light. One renderer per BRDF
    // count times every technique on it.
    let mut per_light = |coverage: f64, techniques: &[Technique]| -> Result<Vec<(f64, f64)>> {
        let wall = light_size_scene(coverage, aspect);
        let lights = wall.lights.len() as f64;
        // Extra BRDFs each light touches, on average (small lights at the wall's edge miss one).
        let touched = wall
            .lights
            .iter()
            .map(|l| wall.brdfs_lit_by(l).len() as f64)
            .sum::<f64>();
        let extra_brdfs = (touched / lights - 1.0).max(1e-6);
        let mut times = vec![[0.0; 2]; techniques.len()];
        for (slot, brdfs) in [1, 3].into_iter().enumerate() {
            let scene = with_brdf_count(&wall, brdfs);
            let mut renderer = Renderer::new(ctx, scene, width, height)?;
            for (t, technique) in techniques.iter().enumerate() {
                let what = format!("{technique:?}, {brdfs} BRDF(s), coverage {coverage}");
                progress(&what);
                let timing = time_lighting(&mut renderer, *technique, frames)?;
                times[t][slot] = timing.median_ms / lights;
                measurements.push((what, timing));
            }
        }
        Ok(times
            .iter()
            .map(|[one, three]| (*one, (three - one) / extra_brdfs))
            .collect())
    };
    let (backend, flush) = (Backend::Native, FlushPolicy::Auto);
    let stencil = Technique::Stencil { backend, flush };
    let branching = Technique::Branching { backend, flush };
    let full = per_light(1.0, &[branching, stencil])?;
    let ((shade, tax), (_, a)) = (full[0], full[1]);
    let (_, b) = per_light(SMALL_COVERAGE, &[stencil])?[0];
    let per_brdf = ((a - b) / (1.0 - SMALL_COVERAGE)).max(0.0);
    let costs = CostModel {
        pass_overhead_ms: ((a - per_brdf) / 2.0).max(0.0),
        stencil_per_brdf_ms: per_brdf,
        branch_tax_per_brdf_ms: tax.max(0.0),
        shade_ms: shade.max(0.0),
    };
    Ok(Calibration {
        device: ctx.device_name().to_owned(),
        width,
        height,
        frames,
        costs,
        measurements,
    })
}

const FIELDS: [&str; 4] = [
    "pass_overhead_ms",
    "stencil_per_brdf_ms",
    "branch_tax_per_brdf_ms",
    "shade_ms",
];

fn fields(c: &CostModel) -> [f64; 4] {
    [
        c.pass_overhead_ms,
        c.stencil_per_brdf_ms,
        c.branch_tax_per_brdf_ms,
        c.shade_ms,
    ]
}

impl Calibration {
    /// The costs at the top level (what [`read_costs`] reads), then the device, the settings and
    /// the measurements.
    pub fn json(&self) -> Value {
        let mut out = json!({
            "device": self.device,
            "settings": {"width": self.width, "height": self.height, "frames": self.frames,
                         "warm_up_frames": WARM_UP_FRAMES},
            "measurements": self.measurements.iter().map(|(what, t)| json!({
                "what": what, "median_ms": t.median_ms, "min_ms": t.min_ms, "max_ms": t.max_ms,
            })).collect::<Vec<_>>(),
        });
        for (name, value) in FIELDS.iter().zip(fields(&self.costs)) {
            out[*name] = json!(value);
        }
        if let Some(x) = self.costs.crossover_coverage() {
            out["crossover_coverage"] = json!(x);
        }
        out
    }

    pub fn write(&self, path: &Path) -> Result<()> {
        crate::write_json(path, &self.json())
    }
}

/// Reads the costs a calibration wrote (`pass_overhead_ms`, `stencil_per_brdf_ms`,
/// `branch_tax_per_brdf_ms`, `shade_ms`: finite, non-negative milliseconds).
pub fn read_costs(path: &Path) -> Result<CostModel> {
    let bad = |problem: String| LabError::Costs {
        path: path.display().to_string(),
        problem,
    };
    let text = std::fs::read_to_string(path).map_err(|e| bad(e.to_string()))?;
    let value: Value = serde_json::from_str(&text).map_err(|e| bad(format!("not JSON: {e}")))?;
    let mut v = [0.0; 4];
    for (out, name) in v.iter_mut().zip(FIELDS) {
        *out = value
            .get(name)
            .and_then(Value::as_f64)
            .filter(|x| x.is_finite() && *x >= 0.0)
            .ok_or_else(|| bad(format!("`{name}` must be a finite, non-negative number")))?;
    }
    Ok(CostModel {
        pass_overhead_ms: v[0],
        stencil_per_brdf_ms: v[1],
        branch_tax_per_brdf_ms: v[2],
        shade_ms: v[3],
    })
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
        };
        let calibration = Calibration {
            device: "test".into(),
            width: 64,
            height: 64,
            frames: 1,
            costs,
            measurements: vec![],
        };
        let path = dir.join("costs.json");
        calibration.write(&path).unwrap();
        assert_eq!(read_costs(&path).unwrap(), costs);
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
