//! A steady clock under a measurement: a fixed reference workload (the canary) warmed up until
//! its time settles, then timed at the edges of every round; a round whose canary strays beyond
//! the tolerance is thrown away and retaken.
//!
//! Pairing by round cancels a change of speed that a whole round shares, not one that happens
//! inside a round, and it does nothing for the milliseconds and medians a report also gives.
//! GPUs move their clocks under load (boost, power and thermal limits: on an NVIDIA H200 the
//! light-size samples of one technique spread 3.4x to 5.7x in one run, the first rounds slow),
//! and llvmpipe shares its cores with whatever else runs. nvbench measures each sample's clock
//! and throws throttled samples away; Google Benchmark and criterion warm up until stable. A
//! canary asks no clock counter of the driver (Vulkan has none), so it works on every device:
//! it sees what the measured work would see.
//!
//! A canary can miss what slows the measured work. On lavapipe beside one busy process, a
//! `compare` at 320x180 read its canary alike (56-62 ms quiet, 52-60 ms loaded) while the set
//! it guarded changed its times and even its ratio (stencil over branching at 1 % lights 1.17
//! quiet, 0.945 loaded). The canary is another workload, three frames at the edges of a round;
//! the load took the cores the round's own work ran on. So the clock also reads that directly:
//! how much CPU time other processes (and the hypervisor, as steal) took while the round's
//! work ran, in cores: the machine's busy time from `/proc/stat` less this process's own from
//! `/proc/self/stat`. A round beside more than [`ClockSettings::max_foreign_load`] strays like
//! a canary that strayed: thrown away and retaken, kept flagged unsteady where it goes on.
//! Work of this process's own threads is not foreign: a load made inside it (`compare
//! --beside-load`) is for the canary to see, as it does. The reading is taken only where
//! `/proc/stat` counts the cores this process may use (a container's view of its host's cores
//! would count other tenants); elsewhere no round strays by it.
//!
//! The decisions are pure functions ([`settled`], [`strays`]) and [`Clock`] is generic over the
//! canary, the load meter and the round's work, so the whole policy is unit-tested without
//! a GPU.

use histencil_vk::{Backend, FlushPolicy, Readback, Renderer, Technique};
use std::time::{Duration, Instant};

/// How steady a clock must be, and how long to wait for it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClockSettings {
    /// A canary time further than this from the reference (relative: `0.10` is ±10 %) strays.
    pub tolerance: f64,
    /// The warm-up has settled when the last `window` canary times lie within the tolerance of
    /// each other (largest over smallest); their median is the reference.
    pub window: usize,
    /// The most canary frames one warm-up runs; it then takes the last window's median as the
    /// reference and says it did not settle.
    pub max_warm_up_frames: usize,
    /// The most wall-clock time one warm-up takes, likewise (a GPU's clock ramps within a
    /// second or two; a machine that needs longer is reported as not settled).
    pub max_warm_up: Duration,
    /// Strays in a row after which the conditions are taken to have changed for good: the
    /// canary is warmed up again and its new time becomes the reference. A round strays at most
    /// twice this often; its last try is kept and flagged unsteady.
    pub retakes_before_rewarm: usize,
    /// A round during whose work other processes kept more than this many cores busy (their
    /// CPU time over the round's wall time) strays, whatever its canary read.
    pub max_foreign_load: f64,
}

impl Default for ClockSettings {
    /// ±10 %: above llvmpipe's frame-to-frame noise at the lab's sizes on 2 cores (a canary
    /// frame's time varies by a few percent there) and far below what a GPU's clock change or a
    /// busy CPU does to a frame (1.5x to 5x).
    fn default() -> Self {
        Self {
            tolerance: 0.10,
            window: 5,
            max_warm_up_frames: 200,
            max_warm_up: Duration::from_secs(10),
            retakes_before_rewarm: 3,
            // Half a core: one busy process is a whole core, a quiet machine's daemons and the
            // readings' 10 ms ticks a few hundredths over a round.
            max_foreign_load: 0.5,
        }
    }
}

/// The reference of `times` if its last `window` lie within `tolerance` of each other (the
/// largest at most `1 + tolerance` times the smallest): their median. `None` before `window`
/// times or while they spread wider.
pub fn settled(times: &[f64], window: usize, tolerance: f64) -> Option<f64> {
    let window = window.max(1);
    let last = times.get(times.len().checked_sub(window)?..)?;
    let lo = last.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = last.iter().copied().fold(0.0, f64::max);
    (lo > 0.0 && hi <= lo * (1.0 + tolerance)).then(|| crate::stats::median_of(last))
}

/// Whether a canary time of `ms` strays from `reference` beyond `tolerance` (either way: a
/// faster clock is as much a change of conditions as a slower one).
pub fn strays(ms: f64, reference: f64, tolerance: f64) -> bool {
    !(ms.is_finite() && reference > 0.0 && (ms / reference - 1.0).abs() <= tolerance)
}

/// One warm-up: the canary run until its time settled (or the caps ran out).
#[derive(Clone, Debug, PartialEq)]
pub struct WarmUp {
    /// The round it ran before (0: before the set's first; later: conditions changed there).
    pub before_round: usize,
    /// Every canary time it took, in order.
    pub times_ms: Vec<f64>,
    pub seconds: f64,
    /// Whether the last window settled within the tolerance (otherwise a cap ended it).
    pub settled: bool,
    /// The reference it set: the last window's median.
    pub reference_ms: f64,
}

/// A round thrown away because its canary strayed or other processes took cores during it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Retake {
    pub round: usize,
    /// The canary time that strayed (or the last one, where the foreign load strayed), and the
    /// reference it is held to.
    pub canary_ms: f64,
    pub reference_ms: f64,
    /// Cores other processes kept busy during the round's work, where it ran and was measured.
    pub foreign_load: Option<f64>,
}

/// The canary after a kept round, and the reference in force then.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CanaryTime {
    pub round: usize,
    pub ms: f64,
    pub reference_ms: f64,
    /// Cores other processes kept busy during the round's work, where measured.
    pub foreign_load: Option<f64>,
}

/// How steady one measurement set's clock was.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SetStability {
    /// The set (`the table`, `light size 3.0 %`).
    pub set: String,
    /// Warm-ups: at the set's start where the canary strayed from the last reference (or there
    /// was none), and wherever strays in a row took the conditions to have changed.
    pub warm_ups: Vec<WarmUp>,
    /// The canary after each kept round, in round order.
    pub canary: Vec<CanaryTime>,
    pub retaken: Vec<Retake>,
    /// Rounds kept though their canary strayed (their last try, after a new warm-up).
    pub unsteady: Vec<usize>,
}

impl SetStability {
    /// The kept rounds' canary times over the reference in force when each was taken: `(lowest,
    /// highest)`; `None` without rounds.
    pub fn canary_range(&self) -> Option<(f64, f64)> {
        let ratios = self.canary.iter().map(|c| c.ms / c.reference_ms);
        let lo = ratios.clone().fold(f64::INFINITY, f64::min);
        let hi = ratios.fold(0.0, f64::max);
        (!self.canary.is_empty()).then_some((lo, hi))
    }

    /// The most cores other processes kept busy during any kept round; `None` where unmeasured.
    pub fn most_foreign_load(&self) -> Option<f64> {
        self.canary
            .iter()
            .filter_map(|c| c.foreign_load)
            .reduce(f64::max)
    }
}

/// The steady clock's record of a run: what the canary was, and every set's stability.
#[derive(Clone, Debug, PartialEq)]
pub struct Stability {
    /// What the canary renders, in words.
    pub workload: String,
    pub settings: ClockSettings,
    pub sets: Vec<SetStability>,
}

impl Stability {
    /// Where other processes kept more than [`ClockSettings::max_foreign_load`] cores busy in
    /// kept rounds: `(those rounds, all kept rounds, the most cores)`. A run like that is a run
    /// of a busy machine, whatever its canary read: its report and `compare merge` say so.
    pub fn busy_elsewhere(&self) -> Option<(usize, usize, f64)> {
        let limit = self.settings.max_foreign_load;
        let kept = self.sets.iter().flat_map(|s| &s.canary);
        let busy: Vec<f64> = kept
            .clone()
            .filter_map(|c| c.foreign_load)
            .filter(|l| *l > limit)
            .collect();
        let most = busy.iter().copied().reduce(f64::max)?;
        Some((busy.len(), kept.count(), most))
    }

    /// The record as JSON: the canary, the tolerance, and per set its warm-ups, kept rounds'
    /// canary times (with the reference in force), retaken and unsteady rounds.
    pub fn json(&self) -> serde_json::Value {
        use serde_json::json;
        let s = &self.settings;
        let mut out = json!({
            "canary": self.workload,
            "tolerance": s.tolerance,
            "settle_window": s.window,
            "retakes_before_rewarm": s.retakes_before_rewarm,
            "max_foreign_load_cores": s.max_foreign_load,
            "sets": self.sets.iter().map(|set| json!({
                "set": set.set,
                "warm_ups": set.warm_ups.iter().map(|w| json!({
                    "before_round": w.before_round,
                    "frames": w.times_ms.len(),
                    "seconds": w.seconds,
                    "settled": w.settled,
                    "reference_ms": w.reference_ms,
                    "times_ms": w.times_ms,
                })).collect::<Vec<_>>(),
                "canary_ms": set.canary.iter().map(|c| c.ms).collect::<Vec<_>>(),
                "canary_reference_ms": set.canary.iter().map(|c| c.reference_ms).collect::<Vec<_>>(),
                // [round, cores other processes kept busy] of each kept round whose load was
                // read (rounds too short to read, or a meter that cannot, have none).
                "foreign_load_cores": set.canary.iter()
                    .filter_map(|c| c.foreign_load.map(|l| json!([c.round, l])))
                    .collect::<Vec<_>>(),
                "retaken": set.retaken.iter().map(|r| {
                    let mut retake = json!({
                        "round": r.round,
                        "canary_ms": r.canary_ms,
                        "reference_ms": r.reference_ms,
                    });
                    if let Some(w) = r.foreign_load {
                        retake["foreign_load_cores"] = json!(w);
                    }
                    retake
                }).collect::<Vec<_>>(),
                "unsteady_rounds": set.unsteady,
            })).collect::<Vec<_>>(),
        });
        // What `compare merge` reads: the kept rounds beside other processes' load (absent
        // for a quiet run: the report holds no nulls).
        if let Some((busy, kept, most)) = self.busy_elsewhere() {
            out["busy_elsewhere"] =
                json!({"rounds": busy, "kept_rounds": kept, "most_cores": most});
        }
        out
    }

    /// A report's section: what the canary is and how steady each set's clock was.
    pub fn markdown(&self) -> String {
        use std::fmt::Write as _;
        let tolerance = 100.0 * self.settings.tolerance;
        let mut md = format!(
            "## Steady clock\n\n\
             Canary: {}, warmed up until {} canary times in a row agree within \
             ±{tolerance:.0} % (their median is the reference), then timed between every two \
             rounds; a round whose canary before or after strays beyond ±{tolerance:.0} % is \
             thrown away and retaken, and so is a round during which other processes kept more \
             than {:.2} cores busy (what a canary misses); {} strays in a row warm the \
             canary up again (the conditions changed for good), and a round that strays twice \
             that often is kept and flagged unsteady.\n\n\
             | set | warm-ups: canary times (s) -> reference | kept rounds' canary over its \
             reference | most cores busy elsewhere | rounds retaken | unsteady |\n\
             |---|---|---|---|---|---|\n",
            self.workload,
            self.settings.window,
            self.settings.max_foreign_load,
            self.settings.retakes_before_rewarm
        );
        for set in &self.sets {
            let warm: Vec<String> = set
                .warm_ups
                .iter()
                .map(|w| {
                    format!(
                        "{}{} ({:.1} s) -> {:.3} ms{}",
                        if w.before_round > 0 {
                            format!("before round {}: ", w.before_round + 1)
                        } else {
                            String::new()
                        },
                        w.times_ms.len(),
                        w.seconds,
                        w.reference_ms,
                        if w.settled { "" } else { ", not settled" }
                    )
                })
                .collect();
            let range = set
                .canary_range()
                .map_or("-".to_owned(), |(lo, hi)| format!("{:.3} to {:.3}", lo, hi));
            let mut retaken: Vec<usize> = set.retaken.iter().map(|r| r.round + 1).collect();
            retaken.dedup();
            let list = |rounds: &[usize]| {
                if rounds.is_empty() {
                    "none".to_owned()
                } else {
                    let r: Vec<String> = rounds.iter().map(usize::to_string).collect();
                    r.join(", ")
                }
            };
            let unsteady: Vec<usize> = set.unsteady.iter().map(|r| r + 1).collect();
            let _ = writeln!(
                md,
                "| {} | {} | {range} | {} | {} ({} tries) | {} |",
                set.set,
                if warm.is_empty() {
                    "none (the last reference held)".to_owned()
                } else {
                    warm.join("; ")
                },
                set.most_foreign_load()
                    .map_or("-".to_owned(), |w| format!("{w:.2}")),
                list(&retaken),
                set.retaken.len(),
                list(&unsteady)
            );
        }
        md.push('\n');
        md
    }
}

/// What a clock did that its user may want to say as it happens: a round thrown away, or the
/// canary warmed up (at a set's start, or again where conditions changed).
#[derive(Clone, Debug, PartialEq)]
pub enum News {
    Retaken(Retake),
    WarmedUp(WarmUp),
}

/// The steady clock of a run: the reference in force and the record so far.
pub struct Clock {
    settings: ClockSettings,
    reference_ms: Option<f64>,
    /// The last canary time, if it did not stray: the next round's "before".
    last_steady: Option<f64>,
    record: Stability,
    /// What happened since the last [`Clock::take_news`].
    news: Vec<News>,
    /// Reads `(CPU seconds other processes have taken, wall seconds)`, both cumulative;
    /// `None` where it cannot be read.
    meter: Option<Box<Meter>>,
}

/// A load meter: cumulative `(CPU seconds other processes took, wall seconds)`, or `None`.
pub type Meter = dyn FnMut() -> Option<(f64, f64)>;

/// The shortest round whose load is read: the kernel counts CPU time in 10 ms ticks, so a
/// round's difference is off by a tick or two per core, which over 0.25 s is under a tenth of
/// a core each; over a 20 ms round (five frames on a GPU) it would be whole cores.
pub const MIN_METERED_SECONDS: f64 = 0.25;

impl Clock {
    pub fn new(workload: impl Into<String>, settings: ClockSettings) -> Self {
        Self {
            settings,
            reference_ms: None,
            last_steady: None,
            record: Stability {
                workload: workload.into(),
                settings,
                sets: Vec::new(),
            },
            news: Vec::new(),
            meter: None,
        }
    }

    /// Reads the load beside each round from `meter` ([`foreign_cpu_seconds`] on a device): a
    /// round beside more than [`ClockSettings::max_foreign_load`] strays.
    pub fn with_meter(mut self, meter: Box<Meter>) -> Self {
        self.meter = Some(meter);
        self
    }

    fn read_meter(&mut self) -> Option<(f64, f64)> {
        self.meter.as_mut().and_then(|m| m())
    }

    /// The retakes and warm-ups since the last call, in order: what a progress line says.
    pub fn take_news(&mut self) -> Vec<News> {
        std::mem::take(&mut self.news)
    }

    /// The record so far.
    pub fn stability(&self) -> &Stability {
        &self.record
    }

    pub fn into_stability(self) -> Stability {
        self.record
    }

    fn strays(&self, ms: f64) -> bool {
        self.reference_ms
            .is_none_or(|r| strays(ms, r, self.settings.tolerance))
    }

    fn set(&mut self) -> &mut SetStability {
        if self.record.sets.is_empty() {
            self.record.sets.push(SetStability::default());
        }
        self.record.sets.last_mut().expect("a set")
    }

    /// Starts the set `name`: one canary frame, and a warm-up unless it agrees with the
    /// reference already set (between sets the device may have idled, or rebuilt pipelines).
    pub fn begin_set<E>(
        &mut self,
        name: impl Into<String>,
        canary: &mut dyn FnMut() -> Result<f64, E>,
    ) -> Result<(), E> {
        self.record.sets.push(SetStability {
            set: name.into(),
            ..SetStability::default()
        });
        let first = canary()?;
        if self.strays(first) {
            self.warm_up(0, vec![first], None, canary)?;
        } else {
            self.last_steady = Some(first);
        }
        Ok(())
    }

    /// Runs the canary until it settles or a cap runs out; its median becomes the reference.
    fn warm_up<E>(
        &mut self,
        before_round: usize,
        mut times: Vec<f64>,
        deadline: Option<Instant>,
        canary: &mut dyn FnMut() -> Result<f64, E>,
    ) -> Result<(), E> {
        let s = self.settings;
        let start = Instant::now();
        let end = deadline.map_or(start + s.max_warm_up, |d| d.min(start + s.max_warm_up));
        let reference = loop {
            if let Some(r) = settled(&times, s.window, s.tolerance) {
                break Some(r);
            }
            if times.len() >= s.max_warm_up_frames || (!times.is_empty() && Instant::now() >= end) {
                break None;
            }
            times.push(canary()?);
        };
        let tail = &times[times.len().saturating_sub(s.window)..];
        let reference_ms = reference.unwrap_or_else(|| crate::stats::median_of(tail));
        self.reference_ms = Some(reference_ms);
        self.last_steady = times.last().copied().filter(|t| !self.strays(*t));
        let warm_up = WarmUp {
            before_round,
            times_ms: times,
            seconds: start.elapsed().as_secs_f64(),
            settled: reference.is_some(),
            reference_ms,
        };
        self.news.push(News::WarmedUp(warm_up.clone()));
        self.set().warm_ups.push(warm_up);
        Ok(())
    }

    /// Round `index` of the current set: `work` between two canary frames (the one before is
    /// the last round's where it did not stray), kept where neither strays, else thrown away
    /// and retaken; after [`ClockSettings::retakes_before_rewarm`] strays in a row the canary
    /// is warmed up again, and after twice that, or once `deadline` (the set's budget) has
    /// passed, the next try is kept and flagged unsteady where it strays. Returns what the
    /// kept try's `work` returned: its samples, committed by the caller.
    pub fn round<T, E>(
        &mut self,
        index: usize,
        deadline: Instant,
        canary: &mut dyn FnMut() -> Result<f64, E>,
        work: &mut dyn FnMut() -> Result<T, E>,
    ) -> Result<T, E> {
        let rewarm = self.settings.retakes_before_rewarm.max(1);
        let mut strays_in_a_row = 0;
        loop {
            let last_try = strays_in_a_row >= 2 * rewarm || Instant::now() >= deadline;
            let before = match self.last_steady.take() {
                Some(ms) => ms,
                None => canary()?,
            };
            let (strayed, foreign_load) = if self.strays(before) && !last_try {
                (before, None)
            } else {
                let start = self.read_meter();
                let kept = work()?;
                let foreign_load = match (start, self.read_meter()) {
                    (Some((c0, t0)), Some((c1, t1))) if t1 - t0 >= MIN_METERED_SECONDS => {
                        Some((c1 - c0).max(0.0) / (t1 - t0))
                    }
                    _ => None,
                };
                let after = canary()?;
                let beside_load = foreign_load.is_some_and(|l| l > self.settings.max_foreign_load);
                let steady = !self.strays(before) && !self.strays(after) && !beside_load;
                self.last_steady = (!self.strays(after)).then_some(after);
                if steady || last_try {
                    let reference_ms = self.reference_ms.unwrap_or(0.0);
                    let set = self.set();
                    set.canary.push(CanaryTime {
                        round: index,
                        ms: after,
                        reference_ms,
                        foreign_load,
                    });
                    if !steady {
                        set.unsteady.push(index);
                    }
                    return Ok(kept);
                }
                let strayed = if self.strays(before) { before } else { after };
                (strayed, foreign_load)
            };
            let retake = Retake {
                round: index,
                canary_ms: strayed,
                reference_ms: self.reference_ms.unwrap_or(0.0),
                foreign_load,
            };
            self.news.push(News::Retaken(retake));
            self.set().retaken.push(retake);
            strays_in_a_row += 1;
            if strays_in_a_row % rewarm == 0 {
                self.warm_up(index, Vec::new(), Some(deadline), canary)?;
            }
        }
    }
}

/// CPU seconds every process but this one has taken (and the hypervisor, as steal) since the
/// machine started: `/proc/stat`'s busy time (user, nice, system, irq, softirq, steal) less
/// this process's (`/proc/self/stat`'s utime and stime, all its threads), both in the kernel's
/// 100 Hz ticks. `None` where either cannot be read, or where `/proc/stat` counts other cores
/// than this process may use (a container, whose `/proc/stat` is its host's: other tenants'
/// work is not this machine's load).
pub fn foreign_cpu_seconds() -> Option<f64> {
    const TICKS_PER_SECOND: f64 = 100.0;
    let stat = std::fs::read_to_string("/proc/stat").ok()?;
    let cores = stat
        .lines()
        .filter(|l| l.starts_with("cpu") && !l.starts_with("cpu "))
        .count();
    if Some(cores) != std::thread::available_parallelism().ok().map(|n| n.get()) {
        return None;
    }
    let total: Vec<f64> = stat
        .lines()
        .next()?
        .split_whitespace()
        .skip(1)
        .map(|t| t.parse().ok())
        .collect::<Option<_>>()?;
    // user nice system idle iowait irq softirq steal: all but idle and iowait.
    let busy: f64 = [0, 1, 2, 5, 6, 7]
        .iter()
        .filter_map(|&i| total.get(i))
        .sum();
    let own = std::fs::read_to_string("/proc/self/stat").ok()?;
    // The fields after the command's closing parenthesis (a command may contain spaces):
    // state is field 3, utime and stime fields 14 and 15.
    let after = own.get(own.rfind(')')? + 1..)?;
    let fields: Vec<&str> = after.split_whitespace().collect();
    let own_ticks: f64 =
        fields.get(11)?.parse::<f64>().ok()? + fields.get(12)?.parse::<f64>().ok()?;
    Some((busy - own_ticks).max(0.0) / TICKS_PER_SECOND)
}

/// The steady clock with its canary on a device: branching's lighting (native backend), the
/// median of [`CANARY_FRAMES`] frames, on a renderer of its own (the measured renderers keep
/// their state). Off, it keeps every round as taken.
pub(crate) struct SteadyClock<'c> {
    clock: Option<Clock>,
    renderer: Option<Renderer<'c>>,
}

/// The canary's technique.
const CANARY: Technique = Technique::Branching {
    backend: Backend::Native,
    flush: FlushPolicy::Auto,
};

/// Frames one canary time is the median of: a single frame's hiccup (a scheduler's time
/// slice on llvmpipe's cores) is not a change of conditions; a clock that moved moves all three.
const CANARY_FRAMES: usize = 3;

/// One canary time: the median lighting time of [`CANARY_FRAMES`] frames.
fn canary_ms(renderer: &mut Renderer) -> crate::Result<f64> {
    let mut times = (0..CANARY_FRAMES)
        .map(|_| crate::measure::lighting_ms(renderer, CANARY).map(|(ms, _)| ms))
        .collect::<crate::Result<Vec<f64>>>()?;
    times.sort_by(f64::total_cmp);
    Ok(histencil_vk::median_of_sorted(&times))
}

impl<'c> SteadyClock<'c> {
    /// No clock: every round kept as taken.
    pub(crate) fn off() -> Self {
        Self {
            clock: None,
            renderer: None,
        }
    }

    /// A clock whose canary lights `renderer`'s scene (`scene` says which, for the report),
    /// its pipelines built before the first timed frame.
    pub(crate) fn new(
        mut renderer: Renderer<'c>,
        scene: &str,
        settings: ClockSettings,
    ) -> crate::Result<Self> {
        renderer.render(CANARY, Readback::NONE)?;
        let workload =
            format!("the median of {CANARY_FRAMES} frames of branching's lighting on {scene}");
        let origin = Instant::now();
        let meter = move || Some((foreign_cpu_seconds()?, origin.elapsed().as_secs_f64()));
        Ok(Self {
            clock: Some(Clock::new(workload, settings).with_meter(Box::new(meter))),
            renderer: Some(renderer),
        })
    }

    /// The record, if the clock ran.
    pub(crate) fn into_stability(self) -> Option<Stability> {
        self.clock.map(Clock::into_stability)
    }

    /// Starts the set `name` (a warm-up where the canary strays).
    pub(crate) fn begin_set(
        &mut self,
        name: &str,
        progress: &mut dyn FnMut(&str),
    ) -> crate::Result<()> {
        let (Some(clock), Some(renderer)) = (self.clock.as_mut(), self.renderer.as_mut()) else {
            return Ok(());
        };
        clock.begin_set(name, &mut || canary_ms(renderer))?;
        Self::tell(clock, name, progress);
        Ok(())
    }

    /// The round `start` says: `work`'s kept try ([`Clock::round`]), retaken only while the
    /// set's budget lasts; or `work` once without a clock.
    pub(crate) fn round<T>(
        &mut self,
        start: &crate::stats::RoundStart,
        progress: &mut dyn FnMut(&str),
        work: &mut dyn FnMut() -> crate::Result<T>,
    ) -> crate::Result<T> {
        let (Some(clock), Some(renderer)) = (self.clock.as_mut(), self.renderer.as_mut()) else {
            return work();
        };
        // A fixed number of rounds has no budget (`Duration::MAX`): a year stands for it.
        let left = (start.budget_seconds - start.seconds).clamp(0.0, 3.2e7);
        let deadline = Instant::now() + Duration::from_secs_f64(left);
        let kept = clock.round(start.index, deadline, &mut || canary_ms(renderer), work)?;
        let set = clock
            .stability()
            .sets
            .last()
            .map(|s| s.set.clone())
            .unwrap_or_default();
        Self::tell(clock, &set, progress);
        Ok(kept)
    }

    /// Says what the clock did since it was last asked, a line each.
    fn tell(clock: &mut Clock, set: &str, progress: &mut dyn FnMut(&str)) {
        for news in clock.take_news() {
            progress(&match news {
                News::Retaken(r) => format!(
                    "{set}: round {} retaken, canary {:.3} ms against {:.3} ms{}",
                    r.round + 1,
                    r.canary_ms,
                    r.reference_ms,
                    r.foreign_load
                        .map_or(String::new(), |l| format!(", {l:.2} cores busy elsewhere"))
                ),
                News::WarmedUp(w) if w.before_round == 0 => format!(
                    "{set}: steady clock warmed up in {} canary times ({:.1} s), canary {:.3} ms{}",
                    w.times_ms.len(),
                    w.seconds,
                    w.reference_ms,
                    if w.settled { "" } else { " (not settled)" }
                ),
                News::WarmedUp(w) => format!(
                    "{set}: conditions changed, canary warmed up again: {:.3} ms",
                    w.reference_ms
                ),
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_warm_up_settles_on_its_last_window_within_the_tolerance() {
        assert_eq!(settled(&[1.0, 1.0], 3, 0.1), None);
        assert_eq!(settled(&[3.0, 1.0, 1.05, 1.02], 3, 0.1), Some(1.02));
        assert_eq!(settled(&[1.0, 1.2, 1.0], 3, 0.1), None);
        assert_eq!(settled(&[0.0, 0.0, 0.0], 3, 0.1), None);
        assert!(!strays(1.09, 1.0, 0.1) && strays(1.11, 1.0, 0.1) && strays(0.89, 1.0, 0.1));
        assert!(strays(f64::NAN, 1.0, 0.1) && strays(1.0, 0.0, 0.1));
    }

    /// A canary that replays `times` (then repeats the last), counting its frames.
    fn replay(times: Vec<f64>) -> impl FnMut() -> Result<f64, ()> {
        let mut i = 0;
        move || {
            let t = times[i.min(times.len() - 1)];
            i += 1;
            Ok(t)
        }
    }

    fn far() -> Instant {
        Instant::now() + Duration::from_secs(3600)
    }

    fn settings() -> ClockSettings {
        ClockSettings {
            window: 3,
            ..ClockSettings::default()
        }
    }

    /// Slow first frames (a GPU ramping its clock) are warm-up; the rounds then share the
    /// canary frame between them: one per round.
    #[test]
    fn the_warm_up_waits_out_a_ramp_and_steady_rounds_cost_one_canary_each() {
        let mut clock = Clock::new("test", settings());
        let mut canary = replay(vec![3.0, 2.0, 1.0, 1.01, 0.99, 1.0]);
        clock.begin_set("set", &mut canary).unwrap();
        let w = &clock.stability().sets[0].warm_ups[0];
        assert_eq!(
            (w.times_ms.len(), w.settled, w.reference_ms),
            (5, true, 1.0)
        );
        let mut works = 0;
        for index in 0..4 {
            let kept = clock
                .round(index, far(), &mut canary, &mut || {
                    works += 1;
                    Ok::<_, ()>(index)
                })
                .unwrap();
            assert_eq!(kept, index);
        }
        let set = &clock.stability().sets[0];
        assert_eq!(works, 4);
        assert_eq!(set.canary.len(), 4);
        assert!(set.retaken.is_empty() && set.unsteady.is_empty());
    }

    /// A round during which the clock moved is thrown away and retaken; a change that lasts
    /// makes a new reference after the stated strays in a row, and the set goes on.
    #[test]
    fn a_straying_round_is_retaken_and_a_lasting_change_warms_up_again() {
        let mut clock = Clock::new("test", settings());
        // Settled at 1.0; round 0 steady; during round 1 a load starts and stays (2.0).
        let mut times = vec![1.0, 1.0, 1.0, 1.0];
        times.extend([2.0; 20]);
        let mut canary = replay(times);
        clock.begin_set("set", &mut canary).unwrap();
        let mut kept = Vec::new();
        for index in 0..3 {
            let r = clock.round(index, far(), &mut canary, &mut || Ok::<_, ()>(index));
            kept.push(r.unwrap());
        }
        assert_eq!(kept, [0, 1, 2]);
        let set = &clock.stability().sets[0];
        let retaken: Vec<usize> = set.retaken.iter().map(|r| r.round).collect();
        assert_eq!(
            retaken,
            [1, 1, 1],
            "three strays in a row, then a new warm-up"
        );
        assert_eq!(set.warm_ups.len(), 2);
        assert_eq!(
            (set.warm_ups[1].before_round, set.warm_ups[1].reference_ms),
            (1, 2.0)
        );
        assert!(set.unsteady.is_empty());
        assert_eq!(set.canary_range(), Some((1.0, 1.0)));
        assert_eq!(set.canary[2].reference_ms, 2.0);
        let news = clock.take_news();
        assert!(
            matches!(news[..], [News::WarmedUp(_), News::Retaken(_), News::Retaken(_), News::Retaken(_), News::WarmedUp(ref w)] if w.before_round == 1)
        );
        assert!(clock.take_news().is_empty(), "news is told once");
        // A one-round hiccup is retaken once, nothing else.
        let mut clock = Clock::new("test", settings());
        let mut canary = replay(vec![1.0, 1.0, 1.0, 1.0, 1.5, 1.0, 1.0, 1.0]);
        clock.begin_set("set", &mut canary).unwrap();
        for index in 0..3 {
            clock
                .round(index, far(), &mut canary, &mut || Ok::<_, ()>(()))
                .unwrap();
        }
        let set = &clock.stability().sets[0];
        assert_eq!(set.retaken.len(), 1);
        assert_eq!(set.warm_ups.len(), 1);
        assert_eq!(set.canary.len(), 3);
    }

    /// A clock that never settles still ends: each warm-up at its cap, each round after twice
    /// the strays in a row, kept and flagged.
    #[test]
    fn a_clock_that_never_settles_ends_every_round_flagged() {
        let s = ClockSettings {
            max_warm_up_frames: 6,
            ..settings()
        };
        let mut clock = Clock::new("test", s);
        let mut flip = false;
        let mut canary = move || {
            flip = !flip;
            Ok::<_, ()>(if flip { 1.0 } else { 3.0 })
        };
        clock.begin_set("set", &mut canary).unwrap();
        for index in 0..2 {
            clock
                .round(index, far(), &mut canary, &mut || Ok::<_, ()>(()))
                .unwrap();
        }
        let set = &clock.stability().sets[0];
        assert!(!set.warm_ups[0].settled);
        assert_eq!(set.unsteady, [0, 1]);
        assert_eq!(set.canary.len(), 2);
    }

    /// Past the set's budget a straying round is kept at once, flagged: retakes never take a
    /// set beyond its budget.
    #[test]
    fn past_the_deadline_a_straying_round_is_kept_flagged() {
        let mut clock = Clock::new("test", settings());
        let mut canary = replay(vec![1.0, 1.0, 1.0, 2.0]);
        clock.begin_set("set", &mut canary).unwrap();
        let mut works = 0;
        clock
            .round(0, Instant::now(), &mut canary, &mut || {
                works += 1;
                Ok::<_, ()>(())
            })
            .unwrap();
        let set = &clock.stability().sets[0];
        assert_eq!((works, set.retaken.len()), (1, 0));
        assert_eq!(set.unsteady, [0]);
    }

    /// The canary misses a load that takes the round's own cores (it reads alike, as on
    /// lavapipe beside a busy process); the meter does not: from the round the load starts in,
    /// rounds beside more than the limit are retaken, and where the load lasts they are kept
    /// flagged unsteady, with the load in the record.
    #[test]
    fn a_round_beside_another_process_strays_though_the_canary_held() {
        use std::cell::Cell;
        use std::rc::Rc;
        // (others' CPU seconds, wall seconds), advanced by the work: one second per round,
        // others taking 0.01 s quietly and 0.7 s under load.
        let counters = Rc::new(Cell::new((0.0, 0.0)));
        let meter = {
            let counters = counters.clone();
            move || Some(counters.get())
        };
        let mut clock = Clock::new("test", settings()).with_meter(Box::new(meter));
        let mut canary = replay(vec![1.0]);
        clock.begin_set("set", &mut canary).unwrap();
        let load_from = 2;
        let mut works = 0;
        for index in 0..4 {
            clock
                .round(index, far(), &mut canary, &mut || {
                    works += 1;
                    let (w, t) = counters.get();
                    let others = if index >= load_from { 0.7 } else { 0.01 };
                    counters.set((w + others, t + 1.0));
                    Ok::<_, ()>(())
                })
                .unwrap();
        }
        let set = &clock.stability().sets[0];
        let near = |w: Option<f64>, v: f64| w.is_some_and(|w| (w - v).abs() < 1e-9);
        assert!(set
            .retaken
            .iter()
            .all(|r| r.round >= load_from && near(r.foreign_load, 0.7)));
        // Each loaded round: six tries (a warm-up after three), the last kept, flagged.
        assert_eq!(set.retaken.len(), 2 * 6);
        assert_eq!(set.unsteady, [2, 3]);
        assert_eq!(works, 2 + 2 * 7);
        assert!(near(set.canary[0].foreign_load, 0.01));
        assert!(near(set.most_foreign_load(), 0.7));
        assert!(clock.stability().markdown().contains("| 0.70 |"));
    }

    #[test]
    fn a_canary_error_ends_the_round() {
        let mut clock = Clock::new("test", settings());
        let mut canary = || Err::<f64, &str>("device lost");
        assert_eq!(clock.begin_set("set", &mut canary), Err("device lost"));
    }
}
