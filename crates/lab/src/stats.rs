//! Statistics that a noisy machine cannot talk into a verdict: the median with a
//! distribution-free 95 % confidence interval (order statistics of the binomial), ratios paired
//! by round, and verdicts with a practical margin: faster or slower only where the whole
//! interval lies beyond ±[`MARGIN`] of a tie, "within the margin" where it lies wholly inside
//! (an equivalence test), and nothing from fewer than [`MIN_VERDICT_ROUNDS`] rounds.
//!
//! Why a margin: contention changes the machine. On lavapipe a 5-round `compare` at 320x180
//! said branching was faster at the 1 % light size when run quietly (stencil / branching 1.149
//! [1.053, 1.182]) and stencil faster beside a CPU hog (0.959 [0.941, 0.973]): both intervals
//! excluded 1, in opposite directions. Near a crossover a verdict that only excludes 1 is a
//! statement about that moment; one that excludes ±5 % is about the techniques.
//!
//! Timings on a shared machine are neither normal nor independent of time: background load comes
//! in bursts. The lab therefore interleaves what it compares (one frame of each in turn, per
//! round), so a burst hits all alike, and compares them by the ratio within each round; the
//! median of those ratios, with its order-statistic interval, needs no assumption about the
//! shape of the noise.

/// A median and its 95 % confidence interval.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Interval {
    pub lo: f64,
    pub median: f64,
    pub hi: f64,
    /// Samples it was computed from.
    pub samples: usize,
    /// The medians of the first and the second half of the samples in the order they were
    /// taken (the middle one of an odd count in neither): what [`Verdict::at_margin`] holds
    /// each half to. `None` below two samples, and for intervals read from reports written
    /// before they were kept.
    pub halves: Option<(f64, f64)>,
}

impl Interval {
    /// Half the interval's width relative to the median (`0.03` is +-3 %); infinite without
    /// samples or for a zero median.
    pub fn relative_half_width(&self) -> f64 {
        if self.samples == 0 || self.median == 0.0 {
            f64::INFINITY
        } else {
            (self.hi - self.lo) / 2.0 / self.median.abs()
        }
    }

    /// An interval of 10 rounds with no halves: what the tests judge by hand.
    #[cfg(test)]
    pub(crate) fn of_ten(lo: f64, median: f64, hi: f64) -> Interval {
        Interval {
            lo,
            median,
            hi,
            samples: 10,
            halves: None,
        }
    }

    /// Whether the interval contains `value`.
    pub fn contains(&self, value: f64) -> bool {
        self.lo <= value && value <= self.hi
    }
}

/// `P(X <= k)` for `X ~ Binomial(n, 1/2)`.
fn binomial_half_cdf(k: usize, n: usize) -> f64 {
    // Terms in log space: n is at most a few thousand frames, C(n, i) overflows f64 from 1030.
    let ln_half_n = n as f64 * 0.5f64.ln();
    let mut ln_choose = 0.0; // ln C(n, 0)
    let mut sum = 0.0;
    for i in 0..=k.min(n) {
        if i > 0 {
            ln_choose += ((n - i + 1) as f64).ln() - (i as f64).ln();
        }
        sum += (ln_choose + ln_half_n).exp();
    }
    sum.min(1.0)
}

/// The median of `samples` with the order-statistic interval: the narrowest symmetric pair of
/// ranks whose coverage, from `X ~ Binomial(n, 1/2)`, is still at least 95 %. Below 6 samples
/// even the whole range (min to max, returned then) covers less than 95 %.
pub fn median_interval(samples: &[f64]) -> Interval {
    let taken: Vec<f64> = samples.iter().copied().filter(|v| v.is_finite()).collect();
    let half = taken.len() / 2;
    let halves = (half > 0).then(|| {
        let (first, second) = (&taken[..half], &taken[taken.len() - half..]);
        (median_of(first), median_of(second))
    });
    let mut sorted = taken;
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len();
    if n == 0 {
        return Interval::default();
    }
    let median = histencil_vk::median_of_sorted(&sorted);
    // [x_(j), x_(n+1-j)] (1-based ranks) covers the median with probability
    // 1 - 2 P(X <= j - 1): take the largest j for which that is still at least 95 %.
    let mut j = 0;
    while j < n / 2 && 2.0 * binomial_half_cdf(j, n) <= 0.05 {
        j += 1;
    }
    let (lo, hi) = if j == 0 {
        (sorted[0], sorted[n - 1])
    } else {
        (sorted[j - 1], sorted[n - j])
    };
    Interval {
        lo,
        median,
        hi,
        samples: n,
        halves,
    }
}

/// The median of unsorted `samples` (NaN for none): the steady clock's reference, and each
/// half's in [`median_interval`].
pub(crate) fn median_of(samples: &[f64]) -> f64 {
    let mut sorted = samples.to_vec();
    sorted.sort_by(f64::total_cmp);
    histencil_vk::median_of_sorted(&sorted)
}

/// The interval of `numerator[i] / denominator[i]`, paired by round `i`.
pub fn ratio_interval(numerator: &[f64], denominator: &[f64]) -> Interval {
    let ratios: Vec<f64> = numerator
        .iter()
        .zip(denominator)
        .filter(|(_, d)| **d > 0.0)
        .map(|(n, d)| n / d)
        .collect();
    median_interval(&ratios)
}

/// The practical margin of every verdict: a ratio within `1 ± MARGIN` is a tie in practice.
pub const MARGIN: f64 = 0.05;

/// Rounds (paired samples) below which no verdict is given: with 10 the 95 % interval of the
/// median spans ranks 2 to 9, so one outlying round on either side cannot decide.
pub const MIN_VERDICT_ROUNDS: usize = 10;

/// What the data says about a ratio `a / b` of times, at the margin [`MARGIN`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// `a` takes less time: the whole interval is below `1 - MARGIN`.
    Faster,
    /// The whole interval is above `1 + MARGIN`.
    Slower,
    /// The whole interval is within `1 ± MARGIN`: equal in practice (an equivalence test).
    Within,
    /// Too few rounds, or an interval reaching across a margin's edge: the data cannot say.
    Undecided,
}

impl Verdict {
    /// The verdict on `ratio` at [`MARGIN`].
    pub fn of(ratio: &Interval) -> Verdict {
        Self::at_margin(ratio, MARGIN)
    }

    /// The verdict on `ratio` at `margin` (`0.05`: ±5 %), given only where each half of the
    /// rounds, in the order they were taken ([`Interval::halves`]), has its median on the
    /// verdict's side of the margin too.
    ///
    /// Why the halves: a load that starts or stops part way changes the machine, and on a CPU
    /// driver it can change the techniques' ratio itself, not only their times (llvmpipe's
    /// rasterizer thread and the submitting thread share the cores with the load, and many
    /// small draws suffer otherwise than a few large ones: on lavapipe at 320x180 stencil over
    /// branching at 1 % lights read 1.17 quietly and 0.945 beside one busy process). Rounds
    /// from before and after such a change mix two answers, and the interval of their median
    /// can exclude the margin on the side of whichever condition has more rounds so far.
    /// Asking each half to agree turns that mix into "undecided", and more rounds, while the
    /// halves disagree: a median that moved across an edge during the run is a change of
    /// conditions, not a property of the techniques. Under steady conditions the halves agree
    /// wherever the whole interval clears an edge, but for chance (at 10 rounds always: an
    /// interval beyond an edge there has 9 of 10 rounds beyond it). A burst centred on the
    /// run's middle, or a periodic load, spoils both halves alike: that is the steady clock's
    /// to see.
    pub fn at_margin(ratio: &Interval, margin: f64) -> Verdict {
        let (lo_edge, hi_edge) = (1.0 - margin, 1.0 + margin);
        let verdict = if ratio.samples < MIN_VERDICT_ROUNDS {
            Verdict::Undecided
        } else if ratio.hi < lo_edge {
            Verdict::Faster
        } else if ratio.lo > hi_edge {
            Verdict::Slower
        } else if ratio.lo >= lo_edge && ratio.hi <= hi_edge {
            Verdict::Within
        } else {
            Verdict::Undecided
        };
        let side = |m: f64| match verdict {
            Verdict::Faster => m < lo_edge,
            Verdict::Slower => m > hi_edge,
            Verdict::Within => (lo_edge..=hi_edge).contains(&m),
            Verdict::Undecided => true,
        };
        match ratio.halves {
            Some((first, second)) if !(side(first) && side(second)) => Verdict::Undecided,
            _ => verdict,
        }
    }

    /// How many rounds in all a ratio now at `ratio` (from `ratio.samples` rounds) would need
    /// for a verdict at `margin`, if its interval kept its centre and narrowed as the
    /// interval of a median does, like 1/sqrt(rounds): the distance from the median to the
    /// margin edge the verdict needs, against the interval's present half-width on that side.
    /// Never below [`MIN_VERDICT_ROUNDS`]; `None` where no number of rounds decides it (a
    /// median on an edge) or nothing was sampled.
    pub fn rounds_to_decide(ratio: &Interval, margin: f64) -> Option<usize> {
        let (lo_edge, hi_edge) = (1.0 - margin, 1.0 + margin);
        let m = ratio.median;
        if ratio.samples == 0 || !m.is_finite() {
            return None;
        }
        // The interval clears an edge and only the halves disagree: conditions changed part
        // way, and the rounds after the change must come to hold most of both halves (four
        // times the rounds before it): ask for twice the rounds so far, and again after.
        let whole = Self::at_margin(
            &Interval {
                halves: None,
                ..*ratio
            },
            margin,
        );
        if whole.decided() && !Self::at_margin(ratio, margin).decided() {
            return Some((2 * ratio.samples).max(MIN_VERDICT_ROUNDS));
        }
        // How far the interval must stay from the median, and how far it reaches now.
        let (room, reach) = if m < lo_edge {
            (lo_edge - m, ratio.hi - m)
        } else if m > hi_edge {
            (m - hi_edge, m - ratio.lo)
        } else {
            let room = (m - lo_edge).min(hi_edge - m);
            (room, (ratio.hi - m).max(m - ratio.lo))
        };
        if room <= 0.0 {
            return None;
        }
        let scale = (reach / room).max(0.0);
        // Less a hair: 2.0000000000000004 squared is no reason for one more round.
        let rounds = (ratio.samples as f64 * scale * scale - 1e-9).ceil();
        Some((rounds as usize).max(MIN_VERDICT_ROUNDS))
    }

    /// Whether the data decided something: faster, slower or within the margin.
    pub fn decided(self) -> bool {
        self != Verdict::Undecided
    }

    /// Whether `self` and `other` are decided the opposite way (faster against slower): what no
    /// change of conditions may do to a verdict.
    pub fn reverses(self, other: Verdict) -> bool {
        matches!(
            (self, other),
            (Verdict::Faster, Verdict::Slower) | (Verdict::Slower, Verdict::Faster)
        )
    }

    pub fn word(self) -> &'static str {
        match self {
            Verdict::Faster => "faster",
            Verdict::Slower => "slower",
            Verdict::Within => "within ±5 %",
            Verdict::Undecided => "undecided",
        }
    }
}

/// How long a measurement keeps sampling: at least `min_rounds` rounds, then until every
/// interval it tracks is narrow enough or its time budget is spent.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sampling {
    pub min_rounds: usize,
    /// Stop once every tracked interval's relative half-width is at most this (`0.03`: +-3 %);
    /// `None`: stop at `min_rounds`.
    pub target: Option<f64>,
    /// Wall-clock time a measurement may take before it stops short of the target.
    pub budget: std::time::Duration,
    /// A cap on rounds, whatever the budget (the interval of the median narrows like
    /// 1/sqrt(rounds); past a few hundred rounds more buys little).
    pub max_rounds: usize,
    /// Stop once every verdict the measurement tracks is decided (after `min_rounds`), instead
    /// of at `min_rounds` or at a width target: what a question needs answered, not an interval
    /// width chosen beforehand.
    pub until_decided: bool,
    /// Predict the budget from a pilot: after `max(min_rounds, MIN_VERDICT_ROUNDS)` rounds, the
    /// budget becomes the time the slowest open verdict needs at the pilot's rate
    /// ([`Verdict::rounds_to_decide`]), a tenth over, and never more than `budget`.
    pub predict_budget: bool,
}

/// Why a measurement stopped sampling.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stop {
    /// `min_rounds` done and no target asked for.
    Rounds,
    /// Every tracked interval reached the target.
    Target,
    /// The budget ran out first.
    Budget,
    /// `max_rounds` ran out first.
    MaxRounds,
    /// Every tracked verdict was decided.
    Decided,
}

impl Stop {
    pub fn word(self) -> &'static str {
        match self {
            Stop::Rounds => "rounds",
            Stop::Target => "target reached",
            Stop::Budget => "budget spent",
            Stop::MaxRounds => "round cap",
            Stop::Decided => "every verdict decided",
        }
    }
}

impl Sampling {
    /// A fixed number of rounds.
    pub fn rounds(n: usize) -> Self {
        Self {
            min_rounds: n.max(1),
            target: None,
            budget: std::time::Duration::MAX,
            max_rounds: n.max(1),
            until_decided: false,
            predict_budget: false,
        }
    }

    /// Whether to stop after `rounds` rounds taking `elapsed`, with the tracked intervals now
    /// `widths` wide (relative half-widths) and `open` tracked verdicts undecided, under
    /// `budget` (the sampling's own, or a pilot's prediction), and why. Pure, so the rule is
    /// unit-tested.
    pub fn stop(
        &self,
        rounds: usize,
        widths: &[f64],
        open: usize,
        elapsed: std::time::Duration,
        budget: std::time::Duration,
    ) -> Option<Stop> {
        if rounds < self.min_rounds {
            return None;
        }
        if self.until_decided {
            if open == 0 {
                return Some(Stop::Decided);
            }
        } else {
            let Some(target) = self.target else {
                return Some(Stop::Rounds);
            };
            if widths.iter().all(|w| *w <= target) {
                return Some(Stop::Target);
            }
        }
        if rounds >= self.max_rounds {
            Some(Stop::MaxRounds)
        } else if elapsed >= budget {
            Some(Stop::Budget)
        } else {
            None
        }
    }
}

/// What a measurement's sampling came to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sampled {
    pub rounds: usize,
    pub stop: Stop,
    /// The widest tracked interval at the end (relative half-width).
    pub widest: f64,
    pub seconds: f64,
    /// Tracked verdicts still undecided at the end.
    pub open: usize,
    /// The pilot's prediction, where the budget was predicted.
    pub prediction: Option<Prediction>,
}

/// What a pilot predicted: after `pilot_rounds` rounds in `pilot_seconds`, `rounds` in all
/// would decide every open verdict that rounds can decide (`None`: none can), `on_edge` verdicts
/// sit on a margin's edge where no number of rounds decides them, and the budget that follows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Prediction {
    pub pilot_rounds: usize,
    pub pilot_seconds: f64,
    pub rounds: Option<usize>,
    pub on_edge: usize,
    pub budget_seconds: f64,
}

impl Prediction {
    /// The prediction after `pilot_rounds` rounds in `pilot_seconds`, with `open` holding each
    /// undecided verdict's rounds to decide (`None` for one on a margin's edge); the budget at
    /// most `cap` seconds: the slowest decidable verdict's rounds at the pilot's pace, a tenth
    /// over. With nothing decidable open, the pilot's own time (more rounds would only spend
    /// the budget).
    pub fn of(pilot_rounds: usize, pilot_seconds: f64, open: &[Option<usize>], cap: f64) -> Self {
        let on_edge = open.iter().filter(|r| r.is_none()).count();
        let per_round = pilot_seconds / pilot_rounds.max(1) as f64;
        let (rounds, budget_seconds) = if open.is_empty() {
            // Decided already: the pilot was enough.
            (Some(pilot_rounds), pilot_seconds)
        } else {
            match open.iter().flatten().copied().max() {
                Some(r) => {
                    let r = r.max(pilot_rounds);
                    (Some(r), (per_round * r as f64 * 1.1).min(cap))
                }
                None => (None, pilot_seconds),
            }
        };
        Prediction {
            pilot_rounds,
            pilot_seconds,
            rounds,
            on_edge,
            budget_seconds,
        }
    }
}

/// Runs rounds of `round` until `sampling` says stop; `widths` gives the tracked intervals'
/// relative half-widths after each round.
pub fn sample<E>(
    sampling: &Sampling,
    round: impl FnMut(&RoundStart) -> Result<(), E>,
    widths: impl Fn() -> Vec<f64>,
) -> Result<Sampled, E> {
    sample_deciding(sampling, round, widths, Vec::new)
}

/// Where a sampling stands as a round starts: what a progress line says.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoundStart {
    /// The round about to run, from 0.
    pub index: usize,
    /// Seconds since the sampling started.
    pub seconds: f64,
    /// The budget in force: the cap, or the pilot's prediction once made.
    pub budget_seconds: f64,
    /// The pilot's length while it runs (its prediction not made yet).
    pub pilot: Option<usize>,
    /// The rounds the pilot predicted would decide every open verdict.
    pub predicted_rounds: Option<usize>,
    /// The rounds a fixed-length sampling takes.
    pub fixed_rounds: Option<usize>,
    /// Verdicts still undecided after the last round (none before the first).
    pub open: Option<usize>,
}

impl RoundStart {
    /// `round 14 of about 40 (predicted), 3 verdicts open, 35 s of a 88 s budget`.
    pub fn line(&self) -> String {
        let n = self.index + 1;
        let of = match (self.fixed_rounds, self.pilot, self.predicted_rounds) {
            (Some(k), _, _) => format!(" of {k}"),
            (None, Some(p), _) => format!(" of a {p}-round pilot"),
            (None, None, Some(r)) => format!(" of about {} (predicted)", r.max(n)),
            (None, None, None) => String::new(),
        };
        let open = match self.open {
            Some(o) if self.fixed_rounds.is_none() => format!(", {o} verdicts open"),
            _ => String::new(),
        };
        format!(
            "round {n}{of}{open}, {:.0} s of a {:.0} s budget",
            self.seconds, self.budget_seconds
        )
    }
}

/// [`sample`], with `open` giving, for each tracked verdict still undecided, the rounds in all
/// its interval predicts would decide it ([`Verdict::rounds_to_decide`]): what
/// [`Sampling::until_decided`] stops on and [`Sampling::predict_budget`] predicts from.
pub fn sample_deciding<E>(
    sampling: &Sampling,
    mut round: impl FnMut(&RoundStart) -> Result<(), E>,
    widths: impl Fn() -> Vec<f64>,
    open: impl Fn() -> Vec<Option<usize>>,
) -> Result<Sampled, E> {
    let start = std::time::Instant::now();
    let pilot = sampling.min_rounds.max(MIN_VERDICT_ROUNDS);
    let mut budget = sampling.budget;
    let mut prediction: Option<Prediction> = None;
    let mut rounds = 0;
    let mut still_open = None;
    loop {
        round(&RoundStart {
            index: rounds,
            seconds: start.elapsed().as_secs_f64(),
            budget_seconds: budget.as_secs_f64(),
            pilot: (sampling.predict_budget && prediction.is_none()).then_some(pilot),
            predicted_rounds: prediction.as_ref().and_then(|p| p.rounds),
            fixed_rounds: (sampling.target.is_none() && !sampling.until_decided)
                .then_some(sampling.min_rounds),
            open: still_open,
        })?;
        rounds += 1;
        let w = widths();
        let o = open();
        still_open = Some(o.len());
        if sampling.predict_budget && rounds == pilot {
            let p = Prediction::of(
                rounds,
                start.elapsed().as_secs_f64(),
                &o,
                sampling.budget.as_secs_f64(),
            );
            budget = std::time::Duration::from_secs_f64(p.budget_seconds);
            prediction = Some(p);
        }
        if let Some(stop) = sampling.stop(rounds, &w, o.len(), start.elapsed(), budget) {
            return Ok(Sampled {
                rounds,
                stop,
                widest: w.iter().copied().fold(0.0, f64::max),
                seconds: start.elapsed().as_secs_f64(),
                open: o.len(),
                prediction,
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounds_to_decide_scale_with_the_square_of_reach_over_room() {
        let at = |lo: f64, median: f64, hi: f64, samples: usize| Interval {
            lo,
            median,
            hi,
            samples,
            halves: None,
        };
        // Slower by 20 %, the interval reaching 0.9 above 1.05 edge: room 0.15, reach 0.3,
        // four times the rounds.
        assert_eq!(
            Verdict::rounds_to_decide(&at(0.9, 1.2, 1.3, 10), MARGIN),
            Some(40)
        );
        // Decided with room to spare: the minimum.
        assert_eq!(
            Verdict::rounds_to_decide(&at(1.1, 1.2, 1.3, 12), MARGIN),
            Some(10)
        );
        assert_eq!(
            Verdict::rounds_to_decide(&at(1.1, 1.2, 1.3, 4), MARGIN),
            Some(10)
        );
        // Cleared an edge, but the halves disagree (a load came part way): twice the rounds.
        let split = Interval {
            halves: Some((1.2, 0.94)),
            ..at(1.1, 1.2, 1.3, 30)
        };
        assert_eq!(Verdict::of(&split), Verdict::Undecided);
        assert_eq!(Verdict::rounds_to_decide(&split, MARGIN), Some(60));
        // Within the margin: the nearer edge counts.
        assert_eq!(
            Verdict::rounds_to_decide(&at(0.96, 1.0, 1.08, 10), MARGIN),
            Some(26)
        );
        // Faster: the upper side.
        assert_eq!(
            Verdict::rounds_to_decide(&at(0.7, 0.8, 1.1, 10), MARGIN),
            Some(40)
        );
        // On an edge no number of rounds decides.
        assert_eq!(
            Verdict::rounds_to_decide(&at(1.0, 1.05, 1.1, 10), MARGIN),
            None
        );
        assert_eq!(
            Verdict::rounds_to_decide(&at(0.0, 0.0, 0.0, 0), MARGIN),
            None
        );
    }

    #[test]
    fn sampling_stops_at_the_target_the_budget_or_the_cap_never_before_the_minimum() {
        use std::time::Duration;
        let s = Sampling {
            min_rounds: 5,
            target: Some(0.03),
            budget: Duration::from_secs(10),
            max_rounds: 100,
            until_decided: false,
            predict_budget: false,
        };
        let b = s.budget;
        let narrow = [0.01, 0.03];
        let wide = [0.01, 0.2];
        let early = Duration::from_secs(1);
        assert_eq!(
            s.stop(4, &narrow, 0, early, b),
            None,
            "the minimum comes first"
        );
        assert_eq!(s.stop(4, &wide, 0, Duration::from_secs(60), b), None);
        assert_eq!(s.stop(5, &narrow, 0, early, b), Some(Stop::Target));
        assert_eq!(s.stop(5, &wide, 0, early, b), None);
        assert_eq!(
            s.stop(9, &wide, 0, Duration::from_secs(10), b),
            Some(Stop::Budget)
        );
        assert_eq!(s.stop(100, &wide, 0, early, b), Some(Stop::MaxRounds));
        assert_eq!(
            s.stop(5, &[f64::INFINITY], 0, early, b),
            None,
            "no interval yet"
        );
        let fixed = Sampling::rounds(3);
        assert_eq!(fixed.stop(2, &wide, 0, early, b), None);
        assert_eq!(fixed.stop(3, &wide, 0, early, b), Some(Stop::Rounds));
        let mut n = 0;
        let round = |_: &RoundStart| {
            n += 1;
            Ok::<_, ()>(())
        };
        let sampled = sample(&fixed, round, || vec![0.5]).unwrap();
        assert_eq!((n, sampled.rounds, sampled.stop), (3, 3, Stop::Rounds));
        assert_eq!(sampled.widest, 0.5);
        // Until decided: open verdicts keep it going past the minimum, to the budget.
        let deciding = Sampling {
            until_decided: true,
            ..s
        };
        assert_eq!(deciding.stop(5, &narrow, 1, early, b), None);
        assert_eq!(deciding.stop(5, &wide, 0, early, b), Some(Stop::Decided));
        assert_eq!(deciding.stop(9, &narrow, 2, b, b), Some(Stop::Budget));
    }

    #[test]
    fn a_pilot_predicts_the_budget_its_slowest_verdict_needs() {
        use std::time::Duration;
        // 10 rounds in 20 s; verdicts needing 40 and 25 rounds: 40 rounds, 88 s.
        let p = Prediction::of(10, 20.0, &[Some(40), Some(25)], 600.0);
        assert_eq!(p.rounds, Some(40));
        assert!((p.budget_seconds - 88.0).abs() < 1e-9, "{p:?}");
        // At most the cap.
        assert_eq!(
            Prediction::of(10, 20.0, &[Some(4000)], 600.0).budget_seconds,
            600.0
        );
        // Nothing open: no more than the pilot.
        assert_eq!(Prediction::of(10, 20.0, &[], 600.0).budget_seconds, 20.0);
        // A verdict on an edge does not cost the others their rounds.
        let edge = Prediction::of(10, 20.0, &[Some(40), None], 600.0);
        assert_eq!((edge.rounds, edge.on_edge), (Some(40), 1));
        assert!((edge.budget_seconds - 88.0).abs() < 1e-9, "{edge:?}");
        let only_edge = Prediction::of(10, 20.0, &[None], 600.0);
        assert_eq!((only_edge.rounds, only_edge.budget_seconds), (None, 20.0));
        // The rule end to end: a verdict that never decides stops at the pilot's budget.
        let s = Sampling {
            min_rounds: 2,
            target: None,
            budget: Duration::from_secs(600),
            max_rounds: 1000,
            until_decided: true,
            predict_budget: true,
        };
        let sampled = sample_deciding(
            &s,
            |_: &RoundStart| Ok::<_, ()>(()),
            Vec::new,
            || vec![None],
        )
        .unwrap();
        assert_eq!(
            (sampled.rounds, sampled.stop, sampled.open),
            (10, Stop::Budget, 1)
        );
        assert_eq!(sampled.prediction.unwrap().rounds, None);
    }

    #[test]
    fn a_round_says_where_the_sampling_stands() {
        let start = RoundStart {
            index: 13,
            seconds: 35.2,
            budget_seconds: 88.0,
            pilot: None,
            predicted_rounds: Some(40),
            fixed_rounds: None,
            open: Some(3),
        };
        assert_eq!(
            start.line(),
            "round 14 of about 40 (predicted), 3 verdicts open, 35 s of a 88 s budget"
        );
        let pilot = RoundStart {
            index: 0,
            pilot: Some(10),
            predicted_rounds: None,
            open: None,
            ..start
        };
        assert_eq!(
            pilot.line(),
            "round 1 of a 10-round pilot, 35 s of a 88 s budget"
        );
        let fixed = RoundStart {
            fixed_rounds: Some(5),
            ..start
        };
        assert!(
            fixed.line().starts_with("round 14 of 5, 35 s"),
            "{}",
            fixed.line()
        );
        // Past the prediction, never "of about 40" at round 41.
        let late = RoundStart { index: 44, ..start };
        assert!(
            late.line().starts_with("round 45 of about 45"),
            "{}",
            late.line()
        );
        // What the sampler hands each round: the pilot first, then its prediction.
        let s = Sampling {
            min_rounds: 2,
            target: None,
            budget: std::time::Duration::from_secs(600),
            max_rounds: 1000,
            until_decided: true,
            predict_budget: true,
        };
        let mut seen = Vec::new();
        sample_deciding(
            &s,
            |r: &RoundStart| {
                seen.push((r.index, r.pilot, r.open));
                Ok::<_, ()>(())
            },
            Vec::new,
            || vec![None],
        )
        .unwrap();
        assert_eq!(seen[0], (0, Some(10), None));
        assert_eq!(seen[9], (9, Some(10), Some(1)));
    }

    #[test]
    fn the_binomial_matches_known_values() {
        assert!((binomial_half_cdf(0, 1) - 0.5).abs() < 1e-12);
        assert!((binomial_half_cdf(2, 4) - 11.0 / 16.0).abs() < 1e-12);
        assert!((binomial_half_cdf(5000, 5000) - 1.0).abs() < 1e-9);
    }

    #[test]
    fn the_median_interval_uses_the_textbook_ranks() {
        // n = 20: the 95 % interval is [x_(6), x_(15)] in 1-based ranks (coverage 95.9 %).
        let samples: Vec<f64> = (1..=20).map(f64::from).collect();
        let i = median_interval(&samples);
        assert_eq!((i.lo, i.median, i.hi, i.samples), (6.0, 10.5, 15.0, 20));
        // Too few samples for 95 %: the whole range.
        let i = median_interval(&[3.0, 1.0, 2.0]);
        assert_eq!((i.lo, i.median, i.hi), (1.0, 2.0, 3.0));
        assert_eq!(median_interval(&[]).samples, 0);
    }

    #[test]
    fn verdicts_need_intervals_beyond_the_margin_and_enough_rounds() {
        let a = [10.0, 11.0, 10.5, 10.2, 10.8, 10.1, 10.9, 10.4, 10.6, 10.3];
        let b: Vec<f64> = a.iter().map(|x| x * 2.0).collect();
        assert_eq!(Verdict::of(&ratio_interval(&a, &b)), Verdict::Faster);
        assert_eq!(Verdict::of(&ratio_interval(&b, &a)), Verdict::Slower);
        // Noise around equality, wider than the margin: undecided.
        let c = [10.0, 12.0, 8.0, 11.0, 9.0, 10.2, 9.8, 10.1, 9.9, 10.0];
        let d = [10.1, 10.0, 10.0, 10.0, 10.0, 10.0, 10.0, 10.0, 10.0, 10.0];
        assert_eq!(Verdict::of(&ratio_interval(&c, &d)), Verdict::Undecided);
        // Equal within ±5 %: decided, as a tie.
        let e: Vec<f64> = d
            .iter()
            .zip([1.01, 0.99, 1.02, 1.0, 0.98, 1.01, 1.0, 0.99, 1.01, 1.0])
            .map(|(x, f)| x * f)
            .collect();
        assert_eq!(Verdict::of(&ratio_interval(&e, &d)), Verdict::Within);
        // The measured flip (1.149 [1.053, 1.182] quiet, 0.959 [0.941, 0.973] loaded, from 5
        // rounds, so undecided now), as if from 10 rounds: at the margin the first is slower,
        // the second undecided (it reaches into ±5 %), so no reversal.
        let interval = Interval::of_ten;
        let quiet = Verdict::of(&interval(1.053, 1.149, 1.182));
        let loaded = Verdict::of(&interval(0.941, 0.959, 0.973));
        assert_eq!((quiet, loaded), (Verdict::Slower, Verdict::Undecided));
        assert!(!quiet.reverses(loaded));
        // Intervals just beyond the edges decide; reaching across an edge does not.
        assert_eq!(Verdict::of(&interval(0.90, 0.92, 0.949)), Verdict::Faster);
        assert_eq!(
            Verdict::of(&interval(0.90, 0.93, 0.951)),
            Verdict::Undecided
        );
        assert_eq!(Verdict::of(&interval(0.95, 1.0, 1.05)), Verdict::Within);
        // Five rounds never decide, however separated.
        let five = Interval {
            samples: 5,
            ..interval(0.5, 0.5, 0.5)
        };
        assert_eq!(Verdict::of(&five), Verdict::Undecided);
        assert!(Verdict::Faster.reverses(Verdict::Slower));
        assert!(!Verdict::Faster.reverses(Verdict::Within));
    }

    /// A load that starts or stops part way, as measured on lavapipe (stencil over branching at
    /// 1 % lights: 1.17 with a wide spread quietly, 0.945 tightly beside one busy process),
    /// sampled until decided: a decided verdict is the verdict of the condition that held over
    /// most of each half of its rounds, never the reverse of it. Without the halves (the rule
    /// before), some of these runs decide against the condition of one of their halves.
    #[test]
    fn a_load_that_starts_or_stops_part_way_reverses_no_decided_verdict() {
        // A small deterministic generator: noise in [-1, 1).
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut noise = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        };
        let quiet = |n: f64| 1.17 * (1.0 + 0.15 * n);
        let loaded = |n: f64| 0.945 * (1.0 + 0.004 * n);
        let own = |is_loaded: bool| {
            if is_loaded {
                Verdict::Faster
            } else {
                Verdict::Slower
            }
        };
        let (mut decided, mut against_a_half_without) = (0, 0);
        for starts in [true, false] {
            for change in (0..=90).step_by(3) {
                for _seed in 0..4 {
                    let mut samples = Vec::new();
                    let mut conditions = Vec::new();
                    let mut without_halves_done = false;
                    for round in 0..200 {
                        let is_loaded = (round >= change) == starts;
                        let n = noise();
                        samples.push(if is_loaded { loaded(n) } else { quiet(n) });
                        conditions.push(is_loaded);
                        let ratio = median_interval(&samples);
                        // Which condition holds over most of each half of the rounds so far.
                        let half = samples.len() / 2;
                        let most = |c: &[bool]| 2 * c.iter().filter(|l| **l).count() > c.len();
                        let (first, second) = (
                            most(&conditions[..half]),
                            most(&conditions[samples.len() - half..]),
                        );
                        let old = Verdict::of(&Interval {
                            halves: None,
                            ..ratio
                        });
                        if !without_halves_done && old.decided() {
                            without_halves_done = true;
                            if old.reverses(own(first)) || old.reverses(own(second)) {
                                against_a_half_without += 1;
                            }
                        }
                        let verdict = Verdict::of(&ratio);
                        if verdict.decided() {
                            decided += 1;
                            assert_eq!(
                                first,
                                second,
                                "decided {verdict:?} after {} rounds while the halves' \
                                 conditions differ (load {} at round {change})",
                                samples.len(),
                                if starts { "starting" } else { "stopping" }
                            );
                            assert!(
                                !verdict.reverses(own(first)),
                                "{verdict:?} reverses the verdict of the condition it was \
                                 measured under"
                            );
                            break;
                        }
                    }
                }
            }
        }
        assert!(decided > 100, "the rule still decides: {decided}");
        assert!(
            against_a_half_without > 0,
            "without the halves some run decides against one half's condition"
        );
    }
}
