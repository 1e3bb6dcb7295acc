//! Timing a technique over frames, and the frame it renders.

use crate::Result;
use histencil_vk::{median_of_sorted, FrameDesc, Readback, Renderer, Shading, Technique};
use image::RgbaImage;

/// Milliseconds of one measured quantity over frames: the median and the spread.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Timing {
    pub median_ms: f64,
    pub min_ms: f64,
    pub max_ms: f64,
}

impl Timing {
    pub fn from_samples(mut samples: Vec<f64>) -> Self {
        samples.sort_by(f64::total_cmp);
        Self {
            median_ms: median_of_sorted(&samples),
            min_ms: samples.first().copied().unwrap_or(0.0),
            max_ms: samples.last().copied().unwrap_or(0.0),
        }
    }

    /// `max - min`.
    pub fn spread_ms(&self) -> f64 {
        self.max_ms - self.min_ms
    }
}

/// Frames rendered and thrown away before timing: the first frame of a technique builds its
/// pipelines and tables and bakes lightmap probes.
pub const WARM_UP_FRAMES: usize = 1;

/// The summed time of `passes` in each of `frames` frames after the warm-up.
pub fn time_passes(
    renderer: &mut Renderer,
    desc: impl Into<FrameDesc>,
    passes: &[&str],
    frames: usize,
) -> Result<Timing> {
    let samples = measured(renderer, desc, frames)?
        .iter()
        .map(|timings| passes.iter().filter_map(|p| timings.pass_ms(p)).sum())
        .collect();
    Ok(Timing::from_samples(samples))
}

/// As [`time_passes`], without the hi-stencil emulator's bookkeeping, which comes second
/// (`None` where the frames emulate nothing): the platform's technique and the emulator apart.
pub fn time_technique(
    renderer: &mut Renderer,
    desc: impl Into<FrameDesc>,
    passes: &[&str],
    frames: usize,
) -> Result<(Timing, Option<Timing>)> {
    let frames = measured(renderer, desc, frames)?;
    let bookkeeping: Option<Vec<f64>> = frames.iter().map(|t| t.bookkeeping_ms).collect();
    let technique = frames.iter().map(|t| t.technique_ms(passes)).collect();
    Ok((
        Timing::from_samples(technique),
        bookkeeping.map(Timing::from_samples),
    ))
}

/// The timings of `frames` frames of `desc` without readback, after the warm-up.
fn measured(
    renderer: &mut Renderer,
    desc: impl Into<FrameDesc>,
    frames: usize,
) -> Result<Vec<histencil_vk::FrameTimings>> {
    let desc = FrameDesc {
        readback: Readback::NONE,
        ..desc.into()
    };
    for _ in 0..WARM_UP_FRAMES {
        renderer.render_frame(&desc)?;
    }
    Ok(renderer.measure_frames(desc, frames)?)
}

/// The lighting pass's time (the talk's figure).
pub fn time_lighting(
    renderer: &mut Renderer,
    technique: Technique,
    frames: usize,
) -> Result<Timing> {
    time_passes(
        renderer,
        technique,
        &[histencil_vk::passes::names::LIGHTING],
        frames,
    )
}

/// The lighting's time in one frame: the technique's (the lighting pass without the
/// hi-stencil emulator's bookkeeping, and the tiled technique's classification before it), and
/// on an emulated backend the bookkeeping's.
pub(crate) fn lighting_ms(
    renderer: &mut Renderer,
    technique: Technique,
) -> Result<(f64, Option<f64>)> {
    let timings = renderer.render(technique, Readback::NONE)?.timings;
    let own = timings.technique_ms(Shading::Deferred(technique).lighting_passes());
    Ok((own, timings.bookkeeping_ms))
}

/// The tonemapped frame.
pub fn frame(renderer: &mut Renderer, desc: impl Into<FrameDesc>) -> Result<RgbaImage> {
    let desc = FrameDesc {
        readback: Readback {
            ldr: true,
            ..Readback::NONE
        },
        ..desc.into()
    };
    let images = renderer.render_frame(&desc)?.images;
    Ok(images.ldr.expect("the LDR frame was asked for"))
}

/// Busy threads that spin until dropped: a measurement run under contention on purpose, to see
/// what a change of conditions does to its verdicts (`compare --beside-load`).
pub struct BusyThreads {
    stop: std::sync::Arc<std::sync::atomic::AtomicBool>,
    threads: Vec<std::thread::JoinHandle<()>>,
}

impl BusyThreads {
    /// Starts `count` spinning threads (none for 0).
    pub fn start(count: usize) -> Self {
        use std::sync::atomic::{AtomicBool, Ordering};
        let stop = std::sync::Arc::new(AtomicBool::new(false));
        let threads = (0..count)
            .map(|_| {
                let stop = stop.clone();
                std::thread::spawn(move || {
                    let mut x = 1u64;
                    while !stop.load(Ordering::Relaxed) {
                        for _ in 0..10_000 {
                            x = std::hint::black_box(x.wrapping_mul(6364136223846793005) + 1);
                        }
                    }
                })
            })
            .collect();
        Self { stop, threads }
    }
}

impl Drop for BusyThreads {
    fn drop(&mut self) {
        self.stop.store(true, std::sync::atomic::Ordering::Relaxed);
        for t in self.threads.drain(..) {
            let _ = t.join();
        }
    }
}
