//! The adaptive technique's frame-level choice: the whole frame lit by the tiled technique
//! (classification, then one dispatch per BRDF over its tiles), by the depth-id technique (the
//! same classification and light lists, then one full-screen pass per BRDF in the frame
//! selected by a depth test), or by its plan (each light's passes, stencil or branching per
//! light as [`CostModel::choose`] decided).
//!
//! ```text
//! planned frame:  sum over its lights of  pass_overhead + c * shade + extra(technique, c, n)
//! tiled frame:    classify + sum over its lights of  c * tiled_shade
//! depth-id frame: classify + b * depth_id_per_brdf + sum over its lights of  c * depth_id_shade
//! ```
//! `c` is a light's screen coverage, `n` the BRDFs it touches. The tiled kernel pays no extra
//! per BRDF beyond the pixels' own shading, and a fixed classification per frame; the plan pays
//! a draw per light and its per-BRDF extras. So many small lights or several BRDFs under large
//! lights favour tiles, a few lights over one BRDF the plan. As the per-light choice does, tiled
//! is taken only where its most expensive prediction (upper interval ends) still undercuts the
//! plan's cheapest; costs without tiled figures (fitted to the talk, whose consoles had no
//! compute tiles) never choose it. `b` is the frame's BRDF count: depth-id draws a full-screen
//! pass for each, which a GPU's hierarchical depth makes cheap where a BRDF's pixels are few,
//! and a CPU rasteriser pays in full. Depth-id is taken over tiled only where it too is surely
//! cheaper, and only with its own measured figures.

use crate::frame::FramePlan;
use crate::CostModel;

/// The tiled technique's costs on one device, in milliseconds; per-screen figures are for a
/// light covering the whole screen and scale linearly with coverage.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TiledCosts {
    /// Classifying every tile of the frame (BRDFs, depth range).
    pub classify_ms: f64,
    /// One full-screen light in the tiled kernels: its light list and its shading.
    pub shade_ms: f64,
    /// The 95 % interval `(lo, hi)` of each cost above, when measured.
    pub interval: Option<[(f64, f64); 2]>,
    /// The depth-id technique's own costs on the device, when measured (it shares the
    /// classification and the light lists).
    pub depth_id: Option<DepthIdCosts>,
}

/// The depth-id technique's costs beyond the tiled classification, in milliseconds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DepthIdCosts {
    /// One BRDF's full-screen pass, whatever its pixels (with the id copy's share).
    pub per_brdf_ms: f64,
    /// One full-screen light: its light list and its shading in the passes.
    pub shade_ms: f64,
    /// The 95 % interval `(lo, hi)` of each cost above, when measured.
    pub interval: Option<[(f64, f64); 2]>,
}

/// How the adaptive technique lights a whole frame ([`CostModel::frame_choice`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameChoice {
    /// By its plan, light by light.
    Planned,
    /// By the tiled technique's compute kernels.
    Tiled,
    /// By the depth-id technique's full-screen passes.
    DepthId,
}

/// Costs `(a, b)` at one end of their `interval` (`hi`: the upper ends).
fn pair_at(a: f64, b: f64, interval: Option<[(f64, f64); 2]>, hi: bool) -> (f64, f64) {
    match interval {
        None => (a, b),
        Some(iv) if hi => (iv[0].1, iv[1].1),
        Some(iv) => (iv[0].0, iv[1].0),
    }
}

impl TiledCosts {
    /// The costs at one end of their intervals (`hi`: the upper ends).
    fn at(&self, hi: bool) -> (f64, f64) {
        pair_at(self.classify_ms, self.shade_ms, self.interval, hi)
    }
}

impl CostModel {
    /// Predicted lighting time of `plan` (its lights' techniques as planned); coverage unknown
    /// (a plan built from bare requests) counts as the whole screen.
    pub fn planned_ms(&self, plan: &FramePlan) -> f64 {
        self.planned_ms_at(plan, false)
    }

    fn planned_ms_at(&self, plan: &FramePlan, hi: bool) -> f64 {
        let costs = self.at(hi);
        plan.lights
            .iter()
            .map(|light| {
                let c = light.coverage.unwrap_or(1.0);
                let r = &light.request;
                costs.pass_overhead_ms
                    + c * costs.shade_ms
                    + costs.extra_ms_for(r.technique, c, &r.affected)
            })
            .sum()
    }

    /// Predicted lighting time of the same lights with the tiled technique, when these costs
    /// have tiled figures.
    pub fn tiled_ms(&self, plan: &FramePlan) -> Option<f64> {
        self.tiled_ms_at(plan, false)
    }

    fn tiled_ms_at(&self, plan: &FramePlan, hi: bool) -> Option<f64> {
        let (classify, shade) = self.tiled?.at(hi);
        let coverage: f64 = plan.lights.iter().map(|l| l.coverage.unwrap_or(1.0)).sum();
        Some(classify + coverage * shade)
    }

    /// Whether the tiled technique lights `plan`'s frame for less at every end of the cost
    /// intervals: its upper prediction below the plan's lower one.
    pub fn prefers_tiled(&self, plan: &FramePlan) -> bool {
        self.tiled_ms_at(plan, true)
            .is_some_and(|tiled| tiled < self.planned_ms_at(plan, false))
    }

    /// Predicted lighting time of the same lights with the depth-id technique over `brdfs`
    /// BRDFs, when these costs have its figures.
    pub fn depth_id_ms(&self, plan: &FramePlan, brdfs: usize) -> Option<f64> {
        self.depth_id_ms_at(plan, brdfs, false)
    }

    fn depth_id_ms_at(&self, plan: &FramePlan, brdfs: usize, hi: bool) -> Option<f64> {
        let tiled = self.tiled?;
        let d = tiled.depth_id?;
        let classify = tiled.at(hi).0;
        let (per_brdf, shade) = pair_at(d.per_brdf_ms, d.shade_ms, d.interval, hi);
        let coverage: f64 = plan.lights.iter().map(|l| l.coverage.unwrap_or(1.0)).sum();
        Some(classify + brdfs as f64 * per_brdf + coverage * shade)
    }

    /// How the adaptive technique lights `plan`'s frame of `brdfs` BRDFs: tiled where
    /// [`CostModel::prefers_tiled`]; depth-id instead where its upper prediction is also below
    /// the plan's lower one and the tiled technique's lower one; else the plan.
    pub fn frame_choice(&self, plan: &FramePlan, brdfs: usize) -> FrameChoice {
        let planned = self.planned_ms_at(plan, false);
        let depth_id = self.depth_id_ms_at(plan, brdfs, true);
        let tiled_lo = self.tiled_ms_at(plan, false);
        if let (Some(d), Some(t)) = (depth_id, tiled_lo) {
            if d < planned && d < t {
                return FrameChoice::DepthId;
            }
        }
        if self.prefers_tiled(plan) {
            FrameChoice::Tiled
        } else {
            FrameChoice::Planned
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{FlushPolicy, PlannedLight};
    use crate::plan::{LightCase, LightRequest, LightTechnique};
    use crate::{Native, PlatformBackend, StencilLayout};

    fn plan(lights: &[(f64, u32, LightTechnique)]) -> FramePlan {
        let layout = StencilLayout::new(3, 0).unwrap();
        let lights = lights
            .iter()
            .enumerate()
            .map(|(input, &(c, n, technique))| PlannedLight {
                input,
                coverage: Some(c),
                screen_rect: None,
                depth_range: None,
                request: LightRequest {
                    case: LightCase::Outside,
                    affected: (0..n).collect(),
                    technique,
                },
            })
            .collect();
        let caps = Native.caps();
        let depth = crate::DepthConvention::Standard;
        FramePlan::build(&layout, &caps, depth, lights, FlushPolicy::Auto).unwrap()
    }

    fn costs(tiled: Option<TiledCosts>) -> CostModel {
        CostModel {
            pass_overhead_ms: 0.01,
            stencil_per_brdf_ms: 0.2,
            branch_tax_per_brdf_ms: 0.5,
            shade_ms: 1.0,
            interval: None,
            tiled,
            slot_weights: None,
        }
    }

    const TILED: TiledCosts = TiledCosts {
        classify_ms: 0.5,
        shade_ms: 1.0,
        interval: None,
        depth_id: None,
    };

    #[test]
    fn the_predictions_add_up_per_light() {
        let p = plan(&[
            (0.5, 1, LightTechnique::SingleBrdf),
            (1.0, 3, LightTechnique::Stencil),
        ]);
        let model = costs(Some(TILED));
        let stencil = 2.0 * (2.0 * 0.01 + 0.2);
        let planned = (0.01 + 0.5) + (0.01 + 1.0 + stencil);
        assert!((model.planned_ms(&p) - planned).abs() < 1e-12);
        assert!((model.tiled_ms(&p).unwrap() - (0.5 + 1.5)).abs() < 1e-12);
        assert_eq!(costs(None).tiled_ms(&p), None);
    }

    /// One large light over one BRDF: the classification is not worth it. Many large lights
    /// over three BRDFs: the plan's per-BRDF passes are.
    #[test]
    fn tiles_win_where_the_plan_pays_per_brdf_and_per_light() {
        let model = costs(Some(TILED));
        let one = plan(&[(1.0, 1, LightTechnique::SingleBrdf)]);
        assert!(!model.prefers_tiled(&one));
        let many: Vec<_> = (0..8).map(|_| (1.0, 3, LightTechnique::Stencil)).collect();
        assert!(model.prefers_tiled(&plan(&many)));
        // Without tiled figures (the talk's consoles) it is never chosen.
        assert!(!costs(None).prefers_tiled(&plan(&many)));
    }

    /// A difference the intervals cannot resolve stays with the plan.
    #[test]
    fn unresolved_differences_stay_planned() {
        let many: Vec<_> = (0..3).map(|_| (1.0, 3, LightTechnique::Stencil)).collect();
        let p = plan(&many);
        let exact = costs(Some(TILED));
        let (planned, tiled) = (exact.planned_ms(&p), exact.tiled_ms(&p).unwrap());
        assert!(tiled < planned, "{tiled} {planned}");
        let wide = costs(Some(TiledCosts {
            interval: Some([(0.4, 0.6), (0.9, 1.5)]),
            ..TILED
        }));
        assert!(exact.prefers_tiled(&p));
        assert!(!wide.prefers_tiled(&p));
    }

    /// Depth-id pays a full-screen pass per BRDF in the frame and shades each pixel once: it is
    /// taken over tiled where its shading is surely cheaper than the kernels' and the BRDFs few,
    /// and never without figures of its own.
    #[test]
    fn depth_id_wins_where_its_passes_cost_less_than_the_kernels_save() {
        let many: Vec<_> = (0..8).map(|_| (1.0, 3, LightTechnique::Stencil)).collect();
        let p = plan(&many);
        assert_eq!(costs(Some(TILED)).frame_choice(&p, 3), FrameChoice::Tiled);
        let with = |per_brdf_ms, shade_ms| {
            costs(Some(TiledCosts {
                depth_id: Some(DepthIdCosts {
                    per_brdf_ms,
                    shade_ms,
                    interval: None,
                }),
                ..TILED
            }))
        };
        // 8 lights: tiled 0.5 + 8 = 8.5; depth-id 0.5 + 3 * 0.2 + 8 * 0.8 = 7.5.
        let cheap = with(0.2, 0.8);
        assert!((cheap.depth_id_ms(&p, 3).unwrap() - 7.5).abs() < 1e-12);
        assert_eq!(cheap.frame_choice(&p, 3), FrameChoice::DepthId);
        // Thirty BRDFs' passes cost more than the kernels' whole shading saves.
        assert_eq!(cheap.frame_choice(&p, 30), FrameChoice::Tiled);
        // A frame the plan lights for less stays planned, whatever depth-id's figures.
        let one = plan(&[(1.0, 1, LightTechnique::SingleBrdf)]);
        assert_eq!(cheap.frame_choice(&one, 1), FrameChoice::Planned);
        // An interval that reaches above tiled's prediction keeps tiled.
        let wide = costs(Some(TiledCosts {
            depth_id: Some(DepthIdCosts {
                per_brdf_ms: 0.2,
                shade_ms: 0.8,
                interval: Some([(0.1, 0.3), (0.7, 1.2)]),
            }),
            ..TILED
        }));
        assert_eq!(wide.frame_choice(&p, 3), FrameChoice::Tiled);
    }
}
