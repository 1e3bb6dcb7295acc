//! The lighting's GPU time with the engine's compact G-buffer against histencil's own 40-byte
//! layout, on the same frame, in one run: the two are recorded in turn (compact, histencil,
//! compact, ...) so drift lands on both, each frame waited for, and the lighting's own
//! timestamps (`LightingFrame::timestamps`) give its time. Reported as medians with 95 %
//! distribution-free intervals (order statistics) and the ratio of the medians.

use crate::device::Gpu;
use crate::gbuffer::GBufferPass;
use crate::world::World;
use ash::vk;
use histencil::{
    BrdfSource, Context, DeferredLighting, HookSets, ImageRef, LightingFrame, LightingTargets,
};
use histencil::{FramePlan, Light, ViewDesc};

/// One G-buffer layout: the pass that writes it, its images, the lighting that reads them.
pub struct Layout<'a, 'c> {
    pub pass: &'a GBufferPass,
    pub images: Vec<ImageRef>,
    pub lighting: &'a mut DeferredLighting<&'c Context>,
    pub hook_sets: HookSets,
}

/// What one frame is lit with.
pub struct Frame<'a> {
    pub cmd: vk::CommandBuffer,
    pub pool: vk::CommandPool,
    pub fence: vk::Fence,
    pub camera_set: vk::DescriptorSet,
    pub world: &'a World,
    pub view: &'a ViewDesc,
    pub lights: &'a [Light],
    pub plan: &'a FramePlan,
}

/// Times `rounds` frames of each layout in turn; returns each layout's lighting times in ms,
/// sorted. `targets` carries the shared depth-stencil and HDR images; its G-buffer is swapped
/// per layout.
///
/// # Safety
/// Everything in `frame` is live on `gpu`'s device; `frame.fence` is signalled and no other
/// work is pending on the queue; slot 0 of every lighting is free.
pub unsafe fn time(
    gpu: &Gpu,
    frame: &Frame,
    layouts: &mut [Layout],
    targets: &mut LightingTargets,
    rounds: usize,
) -> Vec<Vec<f64>> {
    let d = &gpu.device;
    let mut times = vec![Vec::new(); layouts.len()];
    for _ in 0..rounds {
        for (l, out) in layouts.iter_mut().zip(&mut times) {
            d.wait_for_fences(&[frame.fence], true, u64::MAX).unwrap();
            d.reset_fences(&[frame.fence]).unwrap();
            d.reset_command_pool(frame.pool, vk::CommandPoolResetFlags::empty())
                .unwrap();
            let begin = vk::CommandBufferBeginInfo::default()
                .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            d.begin_command_buffer(frame.cmd, &begin).unwrap();
            std::mem::swap(&mut targets.gbuffer, &mut l.images);
            l.pass.record(
                d,
                frame.cmd,
                frame.camera_set,
                frame.world,
                l.lighting.desc(),
                &mut targets.gbuffer,
                &mut targets.depth_stencil,
            );
            let lit = LightingFrame {
                slot: 0,
                view: frame.view,
                lights: frame.lights,
                plan: frame.plan,
                clear_hdr: true,
                timestamps: true,
                brdf_source: BrdfSource::Formula,
                tile_stats: false,
                hook_sets: l.hook_sets,
            };
            l.lighting
                .record(frame.cmd, &lit, targets)
                .expect("lighting recorded");
            std::mem::swap(&mut targets.gbuffer, &mut l.images);
            d.end_command_buffer(frame.cmd).unwrap();
            let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(frame.cmd)];
            let submit = vk::SubmitInfo2::default().command_buffer_infos(&cmds);
            d.queue_submit2(gpu.queue, &[submit], frame.fence).unwrap();
            d.wait_for_fences(&[frame.fence], true, u64::MAX).unwrap();
            l.lighting.slot_finished(0).unwrap();
            let steps = l.lighting.step_timings(0).unwrap().expect("a timed frame");
            out.push(steps.groups.iter().map(|g| g.1).sum::<f64>());
        }
    }
    for t in &mut times {
        t.sort_by(f64::total_cmp);
    }
    times
}

/// The median of sorted `v` and its 95 % distribution-free interval: the order statistics at
/// ranks n/2 -+ 0.98 sqrt(n) (the normal approximation to the binomial).
pub fn median_interval(v: &[f64]) -> (f64, f64, f64) {
    let n = v.len() as f64;
    let half = 0.98 * n.sqrt();
    let lo = ((n / 2.0 - half).floor().max(1.0) as usize) - 1;
    let hi = ((n / 2.0 + 1.0 + half).ceil() as usize).min(v.len()) - 1;
    let mid = v.len() / 2;
    let median = if v.len() % 2 == 1 {
        v[mid]
    } else {
        0.5 * (v[mid - 1] + v[mid])
    };
    (median, v[lo], v[hi])
}
