//! What a window resize costs an engine: `DeferredLighting::resize` (every pipeline kept, the
//! per-extent surfaces made anew) against what it had to do before it existed, dropping the
//! lighting and making a new one at the new size, whose light pipelines are then made again
//! (`prepare` with the frame's plan). Both from 320x180 to 640x360 and back, alternating, on the
//! `brdfs-3` scene's plan for the PS3-like backend (hi-stencil surface resized) and with the
//! tiled technique's pipelines made. Prints each way's median and range over the rounds and the
//! ratio of medians, with the device. `cargo bench -p histencil-tests --bench engine_resize`.

use ash::vk;
use histencil_tests::engine::{lighting_desc, stencil_plan, Engine};
use histencil_vk::{Backend, Context, DeferredLighting, LightingDesc};
use std::time::Instant;

const ROUNDS: usize = 9;

fn main() {
    let mut scene = histencil_scene::embedded("brdfs-3").unwrap();
    scene.normalise_lights();
    let engine = Engine::start();
    {
        // SAFETY: the engine's handles outlive the context; nothing else uses its queue.
        let ctx = unsafe { Context::from_raw(engine.lend(engine.queue_family)) }.expect("context");
        let brdfs = scene.brdfs_in_use();
        let layout = histencil_model::StencilLayout::new(brdfs.len() as u32, 0).unwrap();
        let extent = |(width, height)| vk::Extent2D { width, height };
        let ds_format = ctx.depth_stencil_format().vk();
        let lights = scene.lights.len();
        let desc = |size| LightingDesc {
            frames_in_flight: 2,
            ..lighting_desc(layout, brdfs.clone(), extent(size), ds_format, lights)
        };
        let view = scene.camera.view_desc(16.0 / 9.0);
        let plan = stencil_plan(&scene, &layout, &brdfs, &view, Backend::Ps3);
        let sizes = [(320, 180), (640, 360)];
        let mut lighting = DeferredLighting::new(&ctx, &desc(sizes[0])).unwrap();
        lighting.prepare(&plan).unwrap();
        let pipelines = lighting.pipeline_count();
        let (mut remade, mut resized) = (Vec::new(), Vec::new());
        for round in 0..ROUNDS {
            let size = sizes[(round + 1) % 2];
            // Before: a new lighting at the new size, its pipelines made again.
            let start = Instant::now();
            lighting.destroy().unwrap();
            lighting = DeferredLighting::new(&ctx, &desc(size)).unwrap();
            lighting.prepare(&plan).unwrap();
            remade.push(start.elapsed().as_secs_f64() * 1e3);
            // Now: the same lighting resized (back to the other size, so every round resizes).
            let start = Instant::now();
            lighting.resize(extent(sizes[round % 2])).unwrap();
            lighting.prepare(&plan).unwrap();
            resized.push(start.elapsed().as_secs_f64() * 1e3);
            assert_eq!(
                lighting.pipeline_count(),
                pipelines,
                "a resize made pipelines"
            );
        }
        lighting.destroy().unwrap();
        let summary = |v: &mut Vec<f64>| {
            v.sort_by(f64::total_cmp);
            (v[v.len() / 2], v[0], v[v.len() - 1])
        };
        let (r, n) = (summary(&mut remade), summary(&mut resized));
        println!(
            "engine resize on {} ({}), under the validation layer, {pipelines} light \
             pipelines, {ROUNDS} rounds:\n  \
             new lighting + prepare: median {:.2} ms [{:.2}, {:.2}]\n  \
             resize + prepare:       median {:.2} ms [{:.2}, {:.2}]\n  \
             ratio of medians: {:.4}",
            ctx.device_name(),
            ctx.driver(),
            r.0,
            r.1,
            r.2,
            n.0,
            n.1,
            n.2,
            n.0 / r.0
        );
        assert!(ctx.validation_log().is_empty());
    }
    engine.destroy().assert_clean();
}
