//! GPU timestamps around the passes of a frame.

use crate::gpu::device::context::Context;
use crate::gpu::device::error::{Result, VkCall};
use crate::gpu::encoder::recording::{PassClock, Recording};
use ash::vk;
use std::cell::RefCell;

const MAX_MARKS: u32 = 16;

/// Milliseconds spent in each pass of one frame (or the median over several), in pass order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameTimings {
    /// `(pass name, ms)` between consecutive timestamps, as `gbuffer`, `lighting`, `tonemap`.
    pub passes: Vec<(&'static str, f64)>,
    /// The lighting pass broken down by the talk's pass groups, when asked for
    /// (`FrameDesc::pass_timing`).
    pub lighting: Option<LightingBreakdown>,
    /// The alpha lightmap pass per entity, when asked for and the frame lights its alpha
    /// entities with lightmaps.
    pub lightmaps: Option<LightmapTimings>,
    /// Of the lighting pass, the milliseconds the hi-stencil emulator spent on bookkeeping a
    /// console does not do ([`crate::DeferredLighting::emulation_ms`]); the rest of `lighting`
    /// is the platform's technique. Only on the emulated backends (PS3-like, 360-like).
    pub bookkeeping_ms: Option<f64>,
}

/// The lightmap pass of one frame: clearing the atlas, then each entity's draws (one per light
/// that reaches it), so an engine sees what each of its alpha entities costs.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LightmapTimings {
    /// Beginning the pass, which clears the atlas (and the direction map).
    pub clear_ms: f64,
    /// `(entity index, ms)` for every entity some light reaches, in entity order.
    pub per_entity: Vec<(u32, f64)>,
}

impl LightmapTimings {
    /// Per-step durations `(group, entity, ms)` as [`StepTimer`] reads them: the `clear` step,
    /// then one `entity` step per entity drawn.
    fn from_steps(steps: &[(String, Option<u32>, f64)]) -> Self {
        let mut out = Self::default();
        for (_, entity, ms) in steps {
            match entity {
                Some(e) => add_to(&mut out.per_entity, e, *ms),
                None => out.clear_ms += ms,
            }
        }
        out
    }

    /// The whole lightmap pass: the clear and every entity.
    pub fn total_ms(&self) -> f64 {
        self.clear_ms + self.per_entity.iter().map(|e| e.1).sum::<f64>()
    }
}

/// Lighting time by pass group (`setup`, `mask-<brdf>`, `shade-<brdf>`, `cleanup`,
/// `zero-preserved`, `flush`), totalled over lights in first-seen order, and per light.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LightingBreakdown {
    /// `(group, ms)`, summed over every light.
    pub groups: Vec<(String, f64)>,
    /// `(scene light index, ms)`.
    pub per_light: Vec<(u32, f64)>,
}

impl LightingBreakdown {
    /// Totals per-step durations: `steps[i] = (group, light, ms)`.
    pub fn from_steps(steps: &[(String, Option<u32>, f64)]) -> Self {
        let mut out = Self::default();
        for (group, light, ms) in steps {
            add_to(&mut out.groups, group, *ms);
            if let Some(light) = light {
                add_to(&mut out.per_light, light, *ms);
            }
        }
        out
    }

    /// One group's total; `None` when the frame had no such pass.
    pub fn group_ms(&self, group: &str) -> Option<f64> {
        self.groups.iter().find(|g| g.0 == group).map(|g| g.1)
    }
}

impl FrameTimings {
    /// The whole frame: every pass, bookkeeping included.
    pub fn total_ms(&self) -> f64 {
        self.passes.iter().map(|p| p.1).sum()
    }

    /// One pass's time; `None` when the frame did not run it.
    pub fn pass_ms(&self, name: &str) -> Option<f64> {
        self.passes.iter().find(|p| p.0 == name).map(|p| p.1)
    }

    /// The summed time of `passes` (those the frame ran; [`crate::Shading::lighting_passes`]
    /// for its lighting) without the hi-stencil emulator's bookkeeping, which lies inside the
    /// lighting pass: the platform's technique (all of it on the native backend). Never
    /// negative: a frame with nothing to light is all bookkeeping, and the two timers' rounding
    /// must not print it as `-0.000 ms`.
    pub fn technique_ms(&self, passes: &[&str]) -> f64 {
        let sum: f64 = passes.iter().filter_map(|p| self.pass_ms(p)).sum();
        (sum - self.bookkeeping_ms.unwrap_or(0.0)).max(0.0)
    }

    /// Per-pass median over frames of the same technique.
    pub fn median(frames: &[FrameTimings]) -> FrameTimings {
        let Some(first) = frames.first() else {
            return FrameTimings::default();
        };
        let passes = median_per_key(&first.passes, frames.iter().map(|f| &f.passes));
        let breakdowns: Vec<&LightingBreakdown> =
            frames.iter().filter_map(|f| f.lighting.as_ref()).collect();
        let lighting = (breakdowns.len() == frames.len()).then(|| LightingBreakdown {
            groups: median_per_key(&breakdowns[0].groups, breakdowns.iter().map(|b| &b.groups)),
            per_light: median_per_key(
                &breakdowns[0].per_light,
                breakdowns.iter().map(|b| &b.per_light),
            ),
        });
        let lightmaps: Vec<&LightmapTimings> =
            frames.iter().filter_map(|f| f.lightmaps.as_ref()).collect();
        let lightmaps = (lightmaps.len() == frames.len()).then(|| {
            let mut clears: Vec<f64> = lightmaps.iter().map(|l| l.clear_ms).collect();
            clears.sort_by(f64::total_cmp);
            LightmapTimings {
                clear_ms: median_of_sorted(&clears),
                per_entity: median_per_key(
                    &lightmaps[0].per_entity,
                    lightmaps.iter().map(|l| &l.per_entity),
                ),
            }
        });
        let mut bookkeeping: Vec<f64> = frames.iter().filter_map(|f| f.bookkeeping_ms).collect();
        bookkeeping.sort_by(f64::total_cmp);
        let bookkeeping_ms =
            (bookkeeping.len() == frames.len()).then(|| median_of_sorted(&bookkeeping));
        FrameTimings {
            passes,
            lighting,
            lightmaps,
            bookkeeping_ms,
        }
    }
}

/// Adds `ms` to `key`'s total, appending the key the first time it is seen.
fn add_to<K: Clone + PartialEq>(totals: &mut Vec<(K, f64)>, key: &K, ms: f64) {
    match totals.iter_mut().find(|(k, _)| k == key) {
        Some(entry) => entry.1 += ms,
        None => totals.push((key.clone(), ms)),
    }
}

/// For each key of `keys` (in its order), the median of its values over `lists`.
fn median_per_key<'a, K: Clone + PartialEq + 'a>(
    keys: &[(K, f64)],
    lists: impl Iterator<Item = &'a Vec<(K, f64)>> + Clone,
) -> Vec<(K, f64)> {
    keys.iter()
        .map(|(key, _)| {
            let mut v: Vec<f64> = lists
                .clone()
                .filter_map(|l| l.iter().find(|(k, _)| k == key).map(|e| e.1))
                .collect();
            v.sort_by(f64::total_cmp);
            (key.clone(), median_of_sorted(&v))
        })
        .collect()
}

/// The median of sorted values (mean of the middle two for even counts).
pub fn median_of_sorted(v: &[f64]) -> f64 {
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

/// Queries per mark: the mark's own, and a second written right after it so that the first
/// holds the time where it stands. lavapipe flushes at every timestamp (but a top-of-pipe one)
/// and then bins it with the draws that follow; it takes its time when that bin is rasterised,
/// at the next flush. Compute dispatches run at once, outside the bins, so a mark after a
/// dispatch took the time of the next mark: the dispatches after it were counted before it (the
/// tiled technique's shading was timed as its classification, 2026-11-26). The second query's
/// flush rasterises the first's bin at once. On a GPU it is one timestamp more.
const QUERIES_PER_MARK: u32 = 2;

/// A pool for `marks` marks (`QUERIES_PER_MARK` queries each).
fn timestamp_pool(ctx: &Context, name: &str, marks: u32) -> Result<vk::QueryPool> {
    let info = vk::QueryPoolCreateInfo::default()
        .query_type(vk::QueryType::TIMESTAMP)
        .query_count(marks * QUERIES_PER_MARK);
    // SAFETY: `info` lives until the call returns; a timestamp pool needs no statistics flags.
    let pool = unsafe { ctx.device.create_query_pool(&info, None) }.call("vkCreateQueryPool")?;
    ctx.name(pool, name);
    Ok(pool)
}

/// Resets the queries of the first `marks` marks of `pool`.
fn reset_marks(rec: &Recording, pool: vk::QueryPool, marks: u32) {
    // SAFETY: the recording's command buffer is recording outside rendering (`StepTimer::reset` says so,
    // `start_clock` runs before any pass). Both callers pass `marks` equal to the pool's own
    // count (`MAX_MARKS`, `capacity`), so the range is the pool's queries.
    unsafe {
        rec.device()
            .cmd_reset_query_pool(rec.outside(), pool, 0, marks * QUERIES_PER_MARK)
    };
}

/// Mark `index`: a timestamp after all previous work (and its flushing twin).
fn write_timestamp(rec: &Recording, pool: vk::QueryPool, index: u32) {
    let bottom = vk::PipelineStageFlags2::BOTTOM_OF_PIPE;
    for query in index * QUERIES_PER_MARK..(index + 1) * QUERIES_PER_MARK {
        // SAFETY: the recording's command buffer is recording; its queue family has timestamps
        // (`REQUIREMENTS.timestamps`). `query` is in the pool (the callers assert `index`
        // below its mark count) and was reset earlier in the same recording (`start_clock`,
        // `StepTimer::reset`), so it is unavailable, as a timestamp write needs.
        unsafe {
            rec.device()
                .cmd_write_timestamp2(rec.any(), bottom, pool, query)
        };
    }
}

/// The times of the first `count` marks of `pool`, waiting for them.
fn read_ticks(ctx: &Context, pool: vk::QueryPool, count: usize) -> Result<Vec<u64>> {
    let per_mark = QUERIES_PER_MARK as usize;
    let mut ticks = vec![0u64; count * per_mark];
    // SAFETY: `pool` is live and holds at least `count` marks (the callers count only the marks
    // their last recording wrote, which `mark` asserts fit), and `ticks` has room for each of
    // those queries at 64 bits. Reading while that frame is pending is allowed: WAIT waits for
    // it (for a frame never submitted the spec allows VK_ERROR_DEVICE_LOST, an error).
    unsafe {
        ctx.device
            .get_query_pool_results(
                pool,
                0,
                &mut ticks,
                vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
            )
            .call("vkGetQueryPoolResults")?;
    }
    Ok(ticks.into_iter().step_by(per_mark).collect())
}

/// The frame's timestamp pool, and the names of the marks the last submission wrote.
pub(crate) struct Timestamps {
    pool: vk::QueryPool,
    names: Vec<&'static str>,
}

impl Timestamps {
    pub fn new(ctx: &Context) -> Result<Self> {
        let pool = timestamp_pool(ctx, "frame-timestamps", MAX_MARKS)?;
        Ok(Self {
            pool,
            names: Vec::new(),
        })
    }

    /// Gives `rec` this pool as its clock: its timed passes are the frame's.
    pub fn time(&self, rec: &mut Recording) {
        rec.start_clock(self.pool, MAX_MARKS);
    }

    /// Keeps the names of the marks the recording just submitted wrote (its `finish`'s): none
    /// for a submission without a clock, whose stall then says so instead of reading the last
    /// frame's marks as its own.
    pub fn submitted(&mut self, names: Vec<&'static str>) {
        self.names = names;
    }

    /// How many of the last submission's marks the GPU has written, without waiting: a
    /// bottom-of-pipe timestamp is written once every command before it has finished, so the
    /// marks written name the passes the GPU has finished. `None` where the results cannot be
    /// read (a lost device); 0 for a submission without a clock, which has no marks to read
    /// (and a read of no queries is invalid usage).
    pub fn written(&self, ctx: &Context) -> Option<usize> {
        if self.names.is_empty() {
            return Some(0);
        }
        let queries = self.names.len() * QUERIES_PER_MARK as usize;
        // Per query its value and its availability (`WITH_AVAILABILITY`, 64-bit each).
        let mut results = vec![[0u64; 2]; queries];
        let flags = vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WITH_AVAILABILITY;
        // SAFETY: the pool is live and holds the marks the last submission wrote (`mark`
        // asserts they fit), at least one (checked above); `results` has a value and an
        // availability word per query, the stride `[u64; 2]` gives. Without WAIT the call
        // returns at once: NOT_READY where some query is unwritten, which writes the
        // availability of every query and the values of the available ones only.
        let read = unsafe {
            ctx.device
                .get_query_pool_results(self.pool, 0, &mut results, flags)
        };
        match read {
            Ok(()) | Err(vk::Result::NOT_READY) => {}
            Err(_) => return None,
        }
        let marks = results.chunks(QUERIES_PER_MARK as usize);
        Some(marks.take_while(|m| m.iter().all(|q| q[1] != 0)).count())
    }

    /// The names of the last submission's marks, `start` first; none without a clock.
    pub fn names(&self) -> &[&'static str] {
        &self.names
    }

    pub fn read(&self, ctx: &Context) -> Result<FrameTimings> {
        if self.names.is_empty() {
            return Ok(FrameTimings::default());
        }
        let ticks = read_ticks(ctx, self.pool, self.names.len())?;
        let ms = |a: u64, b: u64| b.saturating_sub(a) as f64 * ctx.timestamp_period_ns * 1e-6;
        let passes = (1..ticks.len())
            .map(|i| (self.names[i], ms(ticks[i - 1], ticks[i])))
            .collect();
        Ok(FrameTimings {
            passes,
            ..FrameTimings::default()
        })
    }

    pub fn destroy(&mut self, ctx: &Context) {
        // SAFETY: the pool is this value's own; a null one is a no-op. The renderer destroys
        // it in its Drop after waiting for the device to go idle, or on a failed creation.
        unsafe { ctx.device.destroy_query_pool(self.pool, None) };
        self.pool = vk::QueryPool::null();
    }
}

/// What `written` of a frame's marks `names` (`start` first, then each pass's end) say of the
/// GPU's progress: `the GPU has finished gbuffer, lighting, not tonemap`.
pub(crate) fn progress_words(names: &[&str], written: usize) -> String {
    if names.is_empty() {
        return "the submission times no passes (not a frame), so how far the GPU got is unknown"
            .to_owned();
    }
    match (written, names.get(written)) {
        (0, _) => "the GPU has not begun the frame (its start timestamp is unwritten)".to_owned(),
        (1, Some(next)) => format!("the GPU has begun the frame, not finished {next}"),
        (n, Some(next)) => format!(
            "the GPU has finished {}, not {next}",
            names[1..n].join(", ")
        ),
        (_, None) => "the GPU has finished every pass of the frame".to_owned(),
    }
}

impl Recording<'_> {
    /// Times this recording's passes ([`Self::pass`]) with the first `capacity` marks of
    /// `pool`: resets them and writes the `start` mark. Outside rendering. Private: `capacity`
    /// is the pool's own count (`Timestamps::time`'s), which the queries' validity relies on.
    fn start_clock(&mut self, pool: vk::QueryPool, capacity: u32) {
        reset_marks(self, pool, capacity);
        self.clock = Some(PassClock {
            pool,
            capacity,
            names: RefCell::new(Vec::new()),
        });
        self.mark("start");
    }

    /// Records a pass: `body` inside its debug label `name` and, where this recording has a
    /// clock, a timestamp that ends the pass under the same name: written by the GPU once every
    /// command before it has finished, so the pass's GPU time is the distance from the mark
    /// before, and a stalled wait names the passes whose marks were written. The one call a
    /// pass makes, so that its label and its time cannot be spelled apart or cover different
    /// commands; without a clock (an engine's command buffer) the label alone.
    pub fn pass<R>(&self, name: &'static str, body: impl FnOnce(&Self) -> R) -> R {
        let out = self.step(name, body);
        self.mark(name);
        out
    }

    fn mark(&self, name: &'static str) {
        let Some(clock) = &self.clock else { return };
        let mut names = clock.names.borrow_mut();
        let index = names.len() as u32;
        assert!(
            index < clock.capacity,
            "more timed passes than the clock's pool holds"
        );
        write_timestamp(self, clock.pool, index);
        names.push(name);
    }
}

/// A timestamp after every step of the lighting plan, for the per-group breakdown. Opt-in: on
/// some drivers a timestamp between draws serialises them, so the breakdown costs time.
pub(crate) struct StepTimer {
    pool: vk::QueryPool,
    capacity: u32,
    /// `(group, light)` of each timed step, in order.
    steps: Vec<(String, Option<u32>)>,
}

impl StepTimer {
    pub fn new(ctx: &Context, name: &str, capacity: u32) -> Result<Self> {
        let pool = timestamp_pool(ctx, name, capacity)?;
        Ok(Self {
            pool,
            capacity,
            steps: Vec::new(),
        })
    }

    /// Steps (plus one start mark) this timer can hold.
    pub fn capacity(&self) -> u32 {
        self.capacity
    }

    /// Resets the queries: outside any rendering, as Vulkan requires.
    pub fn reset(&mut self, rec: &Recording) {
        self.steps.clear();
        reset_marks(rec, self.pool, self.capacity);
    }

    /// The mark the first step is timed from.
    pub fn start(&mut self, rec: &Recording) {
        write_timestamp(rec, self.pool, 0);
    }

    /// Marks the end of a step of `group`, drawn for scene light `light`.
    pub fn mark(&mut self, rec: &Recording, group: String, light: Option<u32>) {
        let index = self.steps.len() as u32 + 1;
        assert!(index < self.capacity, "more steps than the timer holds");
        write_timestamp(rec, self.pool, index);
        self.steps.push((group, light));
    }

    /// The lighting steps' times by pass group and light.
    pub fn read(&self, ctx: &Context) -> Result<LightingBreakdown> {
        Ok(LightingBreakdown::from_steps(&self.read_steps(ctx)?))
    }

    /// The lightmap steps' times: the clear, then per entity.
    pub fn read_lightmaps(&self, ctx: &Context) -> Result<LightmapTimings> {
        Ok(LightmapTimings::from_steps(&self.read_steps(ctx)?))
    }

    /// `(group, light or entity, ms)` per step, waiting for the queries.
    fn read_steps(&self, ctx: &Context) -> Result<Vec<(String, Option<u32>, f64)>> {
        let ticks = read_ticks(ctx, self.pool, self.steps.len() + 1)?;
        let steps: Vec<(String, Option<u32>, f64)> = self
            .steps
            .iter()
            .zip(ticks.windows(2))
            .map(|((group, light), t)| {
                let ms = t[1].saturating_sub(t[0]) as f64 * ctx.timestamp_period_ns * 1e-6;
                (group.clone(), *light, ms)
            })
            .collect();
        Ok(steps)
    }

    pub fn destroy(&mut self, ctx: &Context) {
        // SAFETY: the pool is this timer's own and destroyed once: `SlotTimer`, its only owner,
        // drops the timer right after. No pending frame writes it: a slot's timer is replaced
        // only when the slot records again, so after its last frame finished (`slot_finished`),
        // and the lighting's or lightmaps' Drop destroys it after waiting (`InFlight`) or once
        // every slot finished.
        unsafe { ctx.device.destroy_query_pool(self.pool, None) };
    }
}

/// A frame-in-flight slot's step timer: made, or made again larger, when a frame recorded into
/// the slot asks for timestamps, and read only when the slot's last frame did, so an untimed
/// frame never reports the times of an earlier one.
#[derive(Default)]
pub(crate) struct SlotTimer {
    timer: Option<StepTimer>,
    /// Whether the last frame recorded into the slot writes the timer's queries.
    timed: bool,
}

impl SlotTimer {
    /// Readies the slot for its next frame: timed (`timed`) with up to `steps` marks after the
    /// start mark, or untimed. A failure leaves the slot untimed.
    pub fn prepare(&mut self, ctx: &Context, name: &str, timed: bool, steps: u32) -> Result<()> {
        self.timed = false;
        if !timed {
            return Ok(());
        }
        let needed = steps + 1;
        if self.timer.as_ref().is_none_or(|t| t.capacity() < needed) {
            if let Some(mut old) = self.timer.take() {
                old.destroy(ctx);
            }
            self.timer = Some(StepTimer::new(ctx, name, needed.next_power_of_two())?);
        }
        self.timed = true;
        Ok(())
    }

    /// The timer the frame being recorded writes, if it is timed.
    pub fn active(&mut self) -> Option<&mut StepTimer> {
        self.timer.as_mut().filter(|_| self.timed)
    }

    /// The timer the slot's last frame wrote, if it was timed.
    pub fn last(&self) -> Option<&StepTimer> {
        self.timer.as_ref().filter(|_| self.timed)
    }

    pub fn destroy(&mut self, ctx: &Context) {
        if let Some(t) = self.timer.as_mut() {
            t.destroy(ctx);
        }
        *self = Self::default();
    }
}

crate::gpu::device::teardown::destroy_by_method!(Timestamps);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_marks_written_name_the_passes_the_gpu_finished() {
        let names = ["start", "gbuffer", "lighting", "tonemap"];
        let words = |n| progress_words(&names, n);
        assert_eq!(
            words(0),
            "the GPU has not begun the frame (its start timestamp is unwritten)"
        );
        assert_eq!(
            words(1),
            "the GPU has begun the frame, not finished gbuffer"
        );
        assert_eq!(
            words(3),
            "the GPU has finished gbuffer, lighting, not tonemap"
        );
        assert_eq!(words(4), "the GPU has finished every pass of the frame");
        // A submission without a clock (the simulator's captures) once read the last frame's
        // marks as its own: "every pass finished" of a submission that had stalled.
        assert!(progress_words(&[], 0).contains("times no passes (not a frame)"));
    }

    #[test]
    fn median_per_pass() {
        let f = |a, b| FrameTimings {
            passes: vec![("gbuffer", a), ("lighting", b)],
            ..FrameTimings::default()
        };
        let m = FrameTimings::median(&[f(1.0, 9.0), f(3.0, 1.0), f(2.0, 5.0)]);
        assert_eq!(m, f(2.0, 5.0));
        assert_eq!(m.total_ms(), 7.0);
        assert_eq!(median_of_sorted(&[1.0, 2.0, 3.0, 4.0]), 2.5);
    }

    #[test]
    fn breakdown_totals_groups_and_lights() {
        let b = LightingBreakdown::from_steps(&[
            ("setup".into(), Some(3), 1.0),
            ("shade-ggx".into(), Some(3), 2.0),
            ("setup".into(), Some(5), 0.5),
            ("flush".into(), None, 0.25),
        ]);
        assert_eq!(b.group_ms("setup"), Some(1.5));
        assert_eq!(b.groups.len(), 3);
        assert_eq!(b.per_light, vec![(3, 3.0), (5, 0.5)]);
    }
}
