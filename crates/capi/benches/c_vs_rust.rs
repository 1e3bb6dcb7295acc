//! What the C API costs a frame: the CPU time of planning and recording one frame of lighting
//! through `histencil_lighting_record` against the same through the Rust API (`plan_frame`,
//! then `DeferredLighting::record`), with 64 and 256 lights on `brdfs-3` for the talk's stencil
//! technique on the PS3-like platform, into a command buffer that is recorded and never
//! submitted (nothing runs on the GPU; lavapipe's recording is the driver's CPU work alike for
//! both). No validation layer (its own work would swamp both). The two ways alternate frame by
//! frame; printed: each way's median per frame, and the median of the paired ratios C / Rust
//! with its 95 % interval (order statistics of the pairs), device and driver named.
//! `cargo bench -p histencil-capi --bench c_vs_rust`.

#[path = "../tests/common/mod.rs"]
mod common;

use ash::vk;
use common::{c_boxes, c_targets_of, device_desc, World};
use histencil::{Backend, Context, DeferredLighting, HookSets, Light};
use histencil_capi::*;
use histencil_tests::engine::{lighting_desc, plain_frame, stencil_plan, Engine};
use std::ffi::c_char;
use std::ptr::null_mut;
use std::time::Instant;

const PAIRS: usize = 201;
const SIZE: vk::Extent2D = vk::Extent2D {
    width: 320,
    height: 180,
};

/// `count` lights: the scene's, copied and moved about it (a fixed sequence), so every run plans
/// the same frame.
fn lights(scene: &histencil::scene::Scene, count: usize) -> Vec<Light> {
    let mut state = 0x2545_f491_u32;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        (state as f32 / u32::MAX as f32) * 2.0 - 1.0
    };
    (0..count)
        .map(|i| {
            let mut l = scene.lights[i % scene.lights.len()];
            l.position += glam::Vec3::new(next(), next() * 0.5, next()) * 2.0;
            l
        })
        .collect()
}

/// The median of `v` and its distribution-free 95 % interval (ranks n/2 -+ 0.98 sqrt(n)).
fn median_interval(v: &mut [f64]) -> (f64, f64, f64) {
    v.sort_by(f64::total_cmp);
    let n = v.len() as f64;
    let half = 0.98 * n.sqrt();
    let lo = ((n / 2.0 - half).floor().max(0.0)) as usize;
    let hi = ((n / 2.0 + half).ceil() as usize).min(v.len() - 1);
    (v[v.len() / 2], v[lo], v[hi])
}

fn main() {
    let mut scene = histencil::scene::embedded("brdfs-3").unwrap();
    scene.normalise_lights();
    let engine = Engine::start_unvalidated();
    let d = &engine.device;
    {
        // Lent as the C API lends it (histencil's private allocator), so both ways record on
        // the same kind of context.
        let lent = histencil::BorrowedDevice {
            allocator: None,
            ..engine.lend(engine.queue_family)
        };
        // SAFETY: the engine's handles outlive the context; nothing else uses its queue.
        let ctx = unsafe { Context::from_raw(lent) }.unwrap();
        let driver = ctx.driver();
        println!(
            "device: {}; driver {} {}",
            ctx.device_name(),
            driver.name,
            driver.info
        );
        let brdfs = scene.brdfs_in_use();
        let layout = histencil::StencilLayout::new(brdfs.len() as u32, 0).unwrap();
        let ds = ctx.depth_stencil_format().vk();
        let images = engine.lighting_targets(SIZE, ds);
        let mut c_ctx = null_mut();
        // SAFETY: the engine's live handles; a writable out pointer.
        let made = unsafe { histencil_context_create(&device_desc(&engine), &mut c_ctx) };
        assert_eq!(made, HistencilResult::Success);
        for count in [64, 256] {
            let frame_lights = lights(&scene, count);
            let mut lit = scene.clone();
            lit.lights = frame_lights.clone();
            let world = World {
                view: scene
                    .camera
                    .view_desc(SIZE.width as f32 / SIZE.height as f32),
                names: brdfs
                    .iter()
                    .map(|b| std::ffi::CString::new(b.name()).unwrap())
                    .collect(),
                scene: lit,
            };
            let names: Vec<*const c_char> = world.names.iter().map(|n| n.as_ptr()).collect();
            let desc = lighting_desc(layout, brdfs.clone(), SIZE, ds, count);
            let mut rust = DeferredLighting::new(&ctx, &desc).unwrap();
            let c_desc = HistencilLightingDesc {
                size: size_of::<HistencilLightingDesc>() as u32,
                brdf_count: names.len() as u32,
                brdf_names: names.as_ptr(),
                shaders: std::ptr::null(),
                engine_stencil_bits: 0,
                width: SIZE.width,
                height: SIZE.height,
                depth_stencil_format: ds,
                hdr_format: desc.hdr_format,
                frames_in_flight: 1,
                max_lights: count as u32,
                hi_stencil: 1,
                hooks: std::ptr::null(),
            };
            let mut c_lighting = null_mut();
            // SAFETY: a live context and description.
            let made = unsafe { histencil_lighting_create(c_ctx, &c_desc, &mut c_lighting) };
            assert_eq!(made, HistencilResult::Success);
            let c_lights = world.c_lights();
            let boxes = c_boxes(&world.scene.brdf_bounds(&brdfs));
            let bounds: Vec<HistencilBrdfBounds> = (boxes.iter())
                .map(|b| HistencilBrdfBounds {
                    boxes: b.as_ptr(),
                    box_count: b.len() as u32,
                })
                .collect();
            let c_frame = HistencilFrame {
                size: size_of::<HistencilFrame>() as u32,
                slot: 0,
                technique: HISTENCIL_TECHNIQUE_STENCIL,
                platform: HISTENCIL_PLATFORM_PS3,
                view: world.c_view(),
                light_count: c_lights.len() as u32,
                lights: c_lights.as_ptr(),
                brdf_bounds_count: bounds.len() as u32,
                brdf_bounds: bounds.as_ptr(),
                clear_hdr: 1,
                decode_set: vk::DescriptorSet::null(),
                visibility_set: vk::DescriptorSet::null(),
                timestamps: 0,
            };
            let (pool, cmd) = engine.command_buffer();
            // One frame recorded one way, timed; the command buffer reset after, untimed.
            let once = |way: &mut dyn FnMut()| -> f64 {
                // SAFETY: the engine's command buffer, never submitted; its pool reset after.
                unsafe {
                    d.begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default())
                        .unwrap();
                    let start = Instant::now();
                    way();
                    let us = start.elapsed().as_secs_f64() * 1e6;
                    d.end_command_buffer(cmd).unwrap();
                    d.reset_command_pool(pool, vk::CommandPoolResetFlags::empty())
                        .unwrap();
                    us
                }
            };
            let mut through_c = || {
                let mut gbuffer = Vec::new();
                let mut targets = c_targets_of(&images.refs(), &mut gbuffer);
                // SAFETY: a recording command buffer; live structs. Never submitted, so the
                // slot is finished at once (slot_finished's rule for such a buffer).
                unsafe {
                    let r = histencil_lighting_record(c_lighting, cmd, &c_frame, &mut targets);
                    assert_eq!(r, HistencilResult::Success);
                    histencil_lighting_slot_finished(c_lighting, 0);
                }
            };
            let mut through_rust = || {
                let plan = stencil_plan(&world.scene, &layout, &brdfs, &world.view, Backend::Ps3);
                let frame =
                    plain_frame(&world.view, &world.scene.lights, &plan, HookSets::default());
                // SAFETY: as above.
                unsafe {
                    rust.record(cmd, &frame, &mut images.refs()).unwrap();
                    rust.slot_finished(0).unwrap();
                }
            };
            // Warm-up: pipelines made, caches filled.
            for _ in 0..5 {
                once(&mut through_c);
                once(&mut through_rust);
            }
            let (mut c, mut r, mut ratios) = (Vec::new(), Vec::new(), Vec::new());
            for pair in 0..PAIRS {
                // Alternate which goes first, so neither always follows the other.
                let (a, b) = if pair % 2 == 0 {
                    let a = once(&mut through_c);
                    (a, once(&mut through_rust))
                } else {
                    let b = once(&mut through_rust);
                    (once(&mut through_c), b)
                };
                c.push(a);
                r.push(b);
                ratios.push(a / b);
            }
            let (cm, clo, chi) = median_interval(&mut c);
            let (rm, rlo, rhi) = median_interval(&mut r);
            let (q, qlo, qhi) = median_interval(&mut ratios);
            println!(
                "{count} lights, stencil PS3-like, {PAIRS} frame pairs: plan + record per frame \
                 through C {cm:.0} us [{clo:.0}, {chi:.0}], through Rust {rm:.0} us \
                 [{rlo:.0}, {rhi:.0}]; C / Rust {q:.3} [{qlo:.3}, {qhi:.3}] (medians, 95 % \
                 intervals)"
            );
            // SAFETY: the pool's buffer was never submitted.
            unsafe { d.destroy_command_pool(pool, None) };
            // SAFETY: no slot in flight.
            let freed = unsafe { histencil_lighting_destroy(c_lighting) };
            assert_eq!(freed, HistencilResult::Success);
            rust.destroy().unwrap();
        }
        images.free(&engine);
        // SAFETY: every lighting on it is gone.
        unsafe { histencil_context_destroy(c_ctx) };
    }
    engine.destroy();
}
