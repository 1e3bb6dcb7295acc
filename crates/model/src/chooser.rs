//! Choosing stencil, branching or single-BRDF per light from calibrated costs.
//!
//! Cost of the BRDFs beyond the first, for a light covering `c` of the screen and touching `n`
//! BRDFs (everything else, setup, cleanup and the shading itself, is common to both):
//! ```text
//! stencil:   (n - 1) * (2 * pass_overhead + c * per_brdf_stencil)   one mask + one render each
//! branching: (n - 1) * c * branch_tax                               paid by every shaded pixel
//! ```
//! Stencil costs a fixed overhead per extra pass, branching a tax per pixel: huge lights favour
//! stencil, tiny ones branching (the talk's "tiny lights? try branching instead").
//!
//! Branching's tax is the code of the BRDFs a pixel does not take, run by its divergent
//! neighbours: it grows with what those BRDFs cost. Where a calibration measured each BRDF's
//! shading cost ([`SlotWeights`], 1 = the measured BRDFs' mean), a light's tax is weighted by the
//! mean weight of the BRDFs it touches: `(n - 1) * mean(w) * c * branch_tax`. Stencil's extra
//! passes (a mask, a culled render) and the shading every pixel does once with its own BRDF cost
//! the same whatever the BRDF, so they keep no weight.
//!
//! Costs measured on a device come with 95 % intervals ([`CostModel::interval`]). The chooser
//! takes stencil only where it is cheaper at every end of those intervals; where the intervals
//! cannot tell the two apart it takes branching, the simpler technique (one draw per light, no
//! mask passes, no stencil state), rather than act on noise.

use crate::plan::LightTechnique;

/// Costs of one device in milliseconds; per-screen figures are for a light covering the whole
/// screen and scale linearly with coverage.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CostModel {
    /// Fixed cost of one extra light-volume draw, whatever its size.
    pub pass_overhead_ms: f64,
    /// Mask plus hi-stencil-culled render of one extra BRDF, full screen, overhead excluded.
    pub stencil_per_brdf_ms: f64,
    /// Branch tax of one extra BRDF in the light shader, full screen.
    pub branch_tax_per_brdf_ms: f64,
    /// Shading one BRDF, full screen (the single-BRDF light).
    pub shade_ms: f64,
    /// The 95 % interval `(lo, hi)` of each cost above, in field order, when the costs were
    /// measured; `None` for costs taken as exact (fitted to the talk's figures).
    pub interval: Option<[(f64, f64); 4]>,
    /// The tiled technique's costs, when measured on a device (`histencil calibrate`): the
    /// adaptive technique then lights a frame tiled where that is surely cheaper
    /// ([`CostModel::prefers_tiled`]). `None` for the talk's consoles, which had no tiles.
    pub tiled: Option<crate::TiledCosts>,
    /// Each BRDF slot's shading cost relative to the others, which weights branching's tax;
    /// `None`: every BRDF costs the same (the talk's table has no per-BRDF figures).
    pub slot_weights: Option<SlotWeights>,
}

/// Each stencil slot's BRDF shading cost relative to the mean of the BRDFs a calibration
/// measured (1.0 for a BRDF as costly as their mean): indexed by slot, as
/// [`crate::PlanInputs::brdf_bounds`] is, for every slot a stencil byte can hold (7 BRDF bits).
/// A renderer makes it from its BRDFs' measured costs and its own slot order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlotWeights(pub [f32; SlotWeights::SLOTS]);

impl SlotWeights {
    /// Slots of the widest BRDF field: 7 bits beside the culling bit.
    pub const SLOTS: usize = 128;

    /// Every slot at 1.0: the unweighted model.
    pub const UNIFORM: Self = Self([1.0; Self::SLOTS]);

    /// The weight of a light touching `affected` slots beyond its first: `(n - 1)` times their
    /// mean weight; `n - 1` when uniform. A slot past [`SlotWeights::SLOTS`] weighs 1.
    pub fn extra(&self, affected: &[u32]) -> f64 {
        let n = affected.len();
        if n <= 1 {
            return 0.0;
        }
        let sum: f64 = affected
            .iter()
            .map(|&s| self.0.get(s as usize).map_or(1.0, |&w| f64::from(w)))
            .sum();
        (n - 1) as f64 * sum / n as f64
    }
}

/// One platform row of the talk's measurements (huge lights, milliseconds).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TalkFigures {
    /// Lighting time with one BRDF, the talk's baseline.
    pub one_brdf: f64,
    /// Lighting time with 2 and 3 BRDFs compiled into the branching shader.
    pub branching: [f64; 2],
    /// Lighting time with 2 and 3 BRDFs drawn with the stencil technique.
    pub stencil: [f64; 2],
    /// Per-BRDF cost breakdown: setup, mask, render (a lower bound), cleanup. This one: the
    /// setup pass of one BRDF.
    pub setup: f64,
    /// The mask pass of one BRDF.
    pub mask: f64,
    /// The render pass of one BRDF (a lower bound).
    pub render: f64,
    /// The cleanup pass of one BRDF.
    pub cleanup: f64,
}

impl TalkFigures {
    /// The Xbox 360's row of "Solving some common problems in a modern deferred rendering
    /// engine", Develop 2012.
    pub const X360: Self = Self {
        one_brdf: 1.85,
        branching: [2.1, 2.35],
        stencil: [1.99, 2.13],
        setup: 0.03,
        mask: 0.1,
        render: 0.036,
        cleanup: 0.022,
    };
    /// The PS3's row of the same talk.
    pub const PS3: Self = Self {
        one_brdf: 1.9,
        branching: [2.48, 2.8],
        stencil: [2.13, 2.31],
        setup: 0.03,
        mask: 0.1,
        render: 0.06,
        cleanup: 0.14,
    };
}

impl CostModel {
    /// Fits the talk's lighting-time table: increments linear in the number of extra BRDFs,
    /// least squares through the 1-BRDF time. The talk gives no fixed per-draw overhead, so the
    /// caller states one; it is taken out of the per-BRDF stencil increment.
    pub fn from_talk(figures: &TalkFigures, pass_overhead_ms: f64) -> Self {
        let per_extra = |times: [f64; 2]| {
            let (a, b) = (times[0] - figures.one_brdf, times[1] - figures.one_brdf);
            (a + 2.0 * b) / 5.0
        };
        Self {
            pass_overhead_ms,
            stencil_per_brdf_ms: (per_extra(figures.stencil) - 2.0 * pass_overhead_ms).max(0.0),
            branch_tax_per_brdf_ms: per_extra(figures.branching),
            shade_ms: figures.one_brdf,
            interval: None,
            tiled: None,
            slot_weights: None,
        }
    }

    /// The costs at one end of their intervals (`hi`: the upper ends), or these costs when they
    /// have none.
    pub(crate) fn at(&self, hi: bool) -> CostModel {
        let Some(iv) = self.interval else {
            return *self;
        };
        let pick = |i: usize| if hi { iv[i].1 } else { iv[i].0 };
        CostModel {
            pass_overhead_ms: pick(0),
            stencil_per_brdf_ms: pick(1),
            branch_tax_per_brdf_ms: pick(2),
            shade_ms: pick(3),
            interval: None,
            tiled: self.tiled,
            slot_weights: self.slot_weights,
        }
    }

    /// Predicted extra time of `technique` for a light covering `coverage` (0..=1 of the
    /// screen) and touching `brdfs` BRDFs, each of the mean cost.
    pub fn extra_ms(&self, technique: LightTechnique, coverage: f64, brdfs: u32) -> f64 {
        let extra = f64::from(brdfs.saturating_sub(1));
        self.weighted_extra_ms(technique, coverage, extra, extra)
    }

    /// [`CostModel::extra_ms`] for a light touching the stencil slots `affected`, branching's
    /// tax weighted by their [`SlotWeights`].
    pub fn extra_ms_for(&self, technique: LightTechnique, coverage: f64, affected: &[u32]) -> f64 {
        let passes = affected.len().saturating_sub(1) as f64;
        let weighted = self
            .slot_weights
            .unwrap_or(SlotWeights::UNIFORM)
            .extra(affected);
        self.weighted_extra_ms(technique, coverage, passes, weighted)
    }

    /// `passes` extra stencil passes, or branching's tax for `weighted` extra BRDFs.
    fn weighted_extra_ms(
        &self,
        technique: LightTechnique,
        coverage: f64,
        passes: f64,
        weighted: f64,
    ) -> f64 {
        match technique {
            LightTechnique::SingleBrdf => 0.0,
            LightTechnique::Stencil => {
                passes * (2.0 * self.pass_overhead_ms + coverage * self.stencil_per_brdf_ms)
            }
            LightTechnique::Branching => weighted * coverage * self.branch_tax_per_brdf_ms,
        }
    }

    /// The cheaper technique; a single affected BRDF needs neither. Stencil only where its
    /// most expensive prediction (upper interval ends) still undercuts branching's cheapest
    /// (lower ends); a tie, or a difference the intervals cannot resolve, goes to branching.
    pub fn choose(&self, coverage: f64, brdfs: u32) -> LightTechnique {
        let uniform = Self {
            slot_weights: None,
            ..*self
        };
        uniform.choose_for(coverage, &(0..brdfs).collect::<Vec<_>>())
    }

    /// [`CostModel::choose`] for a light touching the stencil slots `affected`, with their
    /// [`SlotWeights`].
    pub fn choose_for(&self, coverage: f64, affected: &[u32]) -> LightTechnique {
        if affected.len() <= 1 {
            return LightTechnique::SingleBrdf;
        }
        let stencil = self
            .at(true)
            .extra_ms_for(LightTechnique::Stencil, coverage, affected);
        let branching = self
            .at(false)
            .extra_ms_for(LightTechnique::Branching, coverage, affected);
        if stencil < branching {
            LightTechnique::Stencil
        } else {
            LightTechnique::Branching
        }
    }

    /// The coverage above which stencil wins, or `None` when branching is never taxed more.
    pub fn crossover_coverage(&self) -> Option<f64> {
        let slope = self.branch_tax_per_brdf_ms - self.stencil_per_brdf_ms;
        (slope > 0.0).then(|| 2.0 * self.pass_overhead_ms / slope)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An assumed 5 us per extra draw; the talk does not state one.
    const OVERHEAD: f64 = 0.005;

    #[test]
    fn huge_lights_choose_stencil_on_both_consoles() {
        for figures in [TalkFigures::X360, TalkFigures::PS3] {
            let model = CostModel::from_talk(&figures, OVERHEAD);
            assert_eq!(model.choose(1.0, 2), LightTechnique::Stencil);
            assert_eq!(model.choose(1.0, 3), LightTechnique::Stencil);
        }
    }

    /// The linear model fits the 360 rows to 0.01 ms; the PS3's branching tax grows less than
    /// linearly (+0.58, then +0.32 ms), so its fit is off by up to 0.11 ms.
    #[test]
    fn the_model_reproduces_the_talks_lighting_times() {
        for (figures, tolerance) in [(TalkFigures::X360, 0.01), (TalkFigures::PS3, 0.11)] {
            let model = CostModel::from_talk(&figures, OVERHEAD);
            for (i, brdfs) in [2, 3].into_iter().enumerate() {
                let stencil = model.shade_ms + model.extra_ms(LightTechnique::Stencil, 1.0, brdfs);
                let branching =
                    model.shade_ms + model.extra_ms(LightTechnique::Branching, 1.0, brdfs);
                assert!(
                    (stencil - figures.stencil[i]).abs() < tolerance,
                    "{stencil}"
                );
                assert!(
                    (branching - figures.branching[i]).abs() < tolerance,
                    "{branching}"
                );
            }
        }
    }

    /// On the 360 the per-BRDF breakdown (mask + render) accounts for the measured increment of
    /// the stencil technique; on the PS3 the talk's two tables do not add up (0.16 vs ~0.2 ms).
    #[test]
    fn the_per_brdf_breakdown_matches_the_360_increment() {
        let f = TalkFigures::X360;
        let increment = (f.stencil[1] - f.one_brdf) / 2.0;
        assert!((f.mask + f.render - increment).abs() < 0.01);
        let p = TalkFigures::PS3;
        assert!((p.mask + p.render - (p.stencil[1] - p.one_brdf) / 2.0).abs() > 0.03);
    }

    #[test]
    fn tiny_lights_choose_branching() {
        for figures in [TalkFigures::X360, TalkFigures::PS3] {
            let model = CostModel::from_talk(&figures, OVERHEAD);
            assert_eq!(model.choose(0.01, 2), LightTechnique::Branching);
            let crossover = model.crossover_coverage().unwrap();
            assert!(crossover > 0.01 && crossover < 1.0, "{crossover}");
            assert_eq!(model.choose(crossover * 1.01, 3), LightTechnique::Stencil);
            assert_eq!(model.choose(crossover * 0.99, 3), LightTechnique::Branching);
        }
    }

    /// Where measured intervals overlap the chooser does not act on the medians: a light the
    /// medians give to stencil by a hair goes to branching, one stencil wins at every interval
    /// end stays stencil.
    #[test]
    fn unresolved_differences_go_to_the_simpler_technique() {
        let exact = CostModel {
            pass_overhead_ms: 0.01,
            stencil_per_brdf_ms: 0.2,
            branch_tax_per_brdf_ms: 0.5,
            shade_ms: 2.0,
            interval: None,
            tiled: None,
            slot_weights: None,
        };
        let crossover = exact.crossover_coverage().unwrap();
        let just_above = crossover * 1.05;
        assert_eq!(exact.choose(just_above, 3), LightTechnique::Stencil);
        let measured = CostModel {
            interval: Some([(0.008, 0.012), (0.18, 0.22), (0.45, 0.55), (1.9, 2.1)]),
            ..exact
        };
        assert_eq!(measured.choose(just_above, 3), LightTechnique::Branching);
        assert_eq!(measured.choose(1.0, 3), LightTechnique::Stencil);
        assert_eq!(
            measured.choose(crossover * 0.5, 3),
            LightTechnique::Branching
        );
    }

    /// A light over costly BRDFs pays branching more tax than one over cheap ones: at a
    /// coverage between the two crossovers the costly pair goes to stencil, the cheap pair to
    /// branching; uniform weights reproduce the count-based choice.
    #[test]
    fn costly_brdfs_move_the_crossover_towards_stencil() {
        let model = CostModel::from_talk(&TalkFigures::X360, OVERHEAD);
        let crossover = model.crossover_coverage().unwrap();
        let mut weights = SlotWeights::UNIFORM;
        weights.0[..4].copy_from_slice(&[0.5, 0.5, 1.5, 1.5]);
        let weighted = CostModel {
            slot_weights: Some(weights),
            ..model
        };
        let c = crossover * 0.9;
        assert_eq!(weighted.choose_for(c, &[2, 3]), LightTechnique::Stencil);
        assert_eq!(weighted.choose_for(c, &[0, 1]), LightTechnique::Branching);
        assert_eq!(model.choose_for(c, &[2, 3]), model.choose(c, 2));
        // The weights' mean over the light's slots: one costly and one cheap is the uniform tax.
        assert_eq!(weights.extra(&[0, 2]), 1.0);
        assert_eq!(weights.extra(&[0]), 0.0);
        assert_eq!(SlotWeights::UNIFORM.extra(&[0, 1, 200]), 2.0);
    }

    #[test]
    fn one_brdf_is_always_single() {
        let model = CostModel::from_talk(&TalkFigures::X360, OVERHEAD);
        assert_eq!(model.choose(1.0, 1), LightTechnique::SingleBrdf);
        assert_eq!(model.choose(0.0, 0), LightTechnique::SingleBrdf);
    }
}
