//! GPU timestamps around the passes of a frame.

use crate::context::Context;
use crate::error::{Result, VkCall};
use ash::vk;

const MAX_MARKS: u32 = 16;

/// Milliseconds spent in each pass of one frame (or the median over several), in pass order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameTimings {
    pub passes: Vec<(&'static str, f64)>,
}

impl FrameTimings {
    pub fn total_ms(&self) -> f64 {
        self.passes.iter().map(|p| p.1).sum()
    }

    pub fn pass_ms(&self, name: &str) -> Option<f64> {
        self.passes.iter().find(|p| p.0 == name).map(|p| p.1)
    }

    /// Per-pass median over frames of the same technique.
    pub fn median(frames: &[FrameTimings]) -> FrameTimings {
        let Some(first) = frames.first() else {
            return FrameTimings::default();
        };
        let passes = first
            .passes
            .iter()
            .enumerate()
            .map(|(i, (name, _))| {
                let mut v: Vec<f64> = frames.iter().map(|f| f.passes[i].1).collect();
                v.sort_by(f64::total_cmp);
                (*name, median_of_sorted(&v))
            })
            .collect();
        FrameTimings { passes }
    }
}

/// The median of sorted values (mean of the middle two for even counts).
pub fn median_of_sorted(v: &[f64]) -> f64 {
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

pub(crate) struct Timestamps {
    pool: vk::QueryPool,
    names: Vec<&'static str>,
}

impl Timestamps {
    pub fn new(ctx: &Context) -> Result<Self> {
        let info = vk::QueryPoolCreateInfo::default()
            .query_type(vk::QueryType::TIMESTAMP)
            .query_count(MAX_MARKS);
        let pool =
            unsafe { ctx.device.create_query_pool(&info, None) }.call("vkCreateQueryPool")?;
        ctx.name(pool, "frame-timestamps");
        Ok(Self {
            pool,
            names: Vec::new(),
        })
    }

    pub fn begin_frame(&mut self, ctx: &Context, cmd: vk::CommandBuffer) {
        self.names.clear();
        unsafe {
            ctx.device
                .cmd_reset_query_pool(cmd, self.pool, 0, MAX_MARKS)
        };
        self.mark(ctx, cmd, "start");
    }

    /// Timestamp after all previous work: the end of pass `name`.
    pub fn mark(&mut self, ctx: &Context, cmd: vk::CommandBuffer, name: &'static str) {
        let index = self.names.len() as u32;
        assert!(
            index < MAX_MARKS,
            "more timestamp marks than the pool holds"
        );
        unsafe {
            ctx.device.cmd_write_timestamp2(
                cmd,
                vk::PipelineStageFlags2::ALL_COMMANDS,
                self.pool,
                index,
            )
        };
        self.names.push(name);
    }

    pub fn read(&self, ctx: &Context) -> Result<FrameTimings> {
        let mut ticks = vec![0u64; self.names.len()];
        unsafe {
            ctx.device
                .get_query_pool_results(
                    self.pool,
                    0,
                    &mut ticks,
                    vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
                )
                .call("vkGetQueryPoolResults")?;
        }
        let ms = |a: u64, b: u64| b.saturating_sub(a) as f64 * ctx.timestamp_period_ns * 1e-6;
        let passes = (1..ticks.len())
            .map(|i| (self.names[i], ms(ticks[i - 1], ticks[i])))
            .collect();
        Ok(FrameTimings { passes })
    }

    pub fn destroy(&mut self, ctx: &Context) {
        unsafe { ctx.device.destroy_query_pool(self.pool, None) };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_per_pass() {
        let f = |a, b| FrameTimings {
            passes: vec![("gbuffer", a), ("lighting", b)],
        };
        let m = FrameTimings::median(&[f(1.0, 9.0), f(3.0, 1.0), f(2.0, 5.0)]);
        assert_eq!(m, f(2.0, 5.0));
        assert_eq!(m.total_ms(), 7.0);
        assert_eq!(median_of_sorted(&[1.0, 2.0, 3.0, 4.0]), 2.5);
    }
}
