//! What an engine gets for breaking the frames-in-flight and image-usage rules: an error naming
//! the rule, never a crash or a flood of validation messages. Before these checks, a resize with
//! a frame in flight freed the hi-stencil buffers under it (four "in use" messages, then
//! SIGSEGV on lavapipe), a destroy in flight destroyed pipelines in use, a slot recorded twice
//! rewrote the buffers and stencil view a pending frame reads, and G-buffer images made without
//! `SAMPLED` drew 286 messages from histencil's own barriers. Each case here is refused before
//! anything is recorded, and the validation layer (synchronisation validation on) stays silent.

use ash::vk;
use histencil_tests::engine::{lighting_desc, plain_frame, stencil_plan, Engine, EngineTargets};
use histencil_vk::{
    Backend, Cause, Context, DeferredLighting, Error, HookSets, LightingFrame, MixedTiles,
    Renderer, TileClassify, TileSide, TiledFrame,
};

const SIZE: vk::Extent2D = vk::Extent2D {
    width: 48,
    height: 32,
};

/// What each case gets: the engine, a lighting made for `SIZE` on its lent device, a PS3-like
/// frame of `brdfs-3` (its plan writes hi-stencil) and a tiled frame, both in slot 0, and the
/// engine's targets. The case frees the lighting; the helper frees the rest and holds the
/// validation log empty.
struct Case<'a> {
    engine: &'a Engine,
    ctx: &'a Context,
    renderer: &'a Renderer<'a>,
    lighting: DeferredLighting<&'a Context>,
    frame: LightingFrame<'a>,
    tiled: TiledFrame<'a>,
    images: &'a EngineTargets,
}

fn on_a_lighting(case: impl FnOnce(Case)) {
    on_a_lighting_with(1, case);
}

/// [`on_a_lighting`] with `frames` frames in flight.
fn on_a_lighting_with(frames: u32, case: impl FnOnce(Case)) {
    let mut scene = histencil_scene::embedded("brdfs-3").unwrap();
    scene.normalise_lights();
    let engine = Engine::start();
    {
        // SAFETY: the engine's handles outlive the context; nothing else uses its queue.
        let ctx = unsafe { Context::from_raw(engine.lend(engine.queue_family)) }.expect("context");
        let ds_format = ctx.depth_stencil_format().vk();
        let renderer = Renderer::new(&ctx, scene.clone(), SIZE.width, SIZE.height).unwrap();
        let layout = *renderer.stencil_layout();
        let brdfs = renderer.brdfs().to_vec();
        let desc = histencil_vk::LightingDesc {
            frames_in_flight: frames,
            ..lighting_desc(layout, brdfs.clone(), SIZE, ds_format, scene.lights.len())
        };
        let lighting = DeferredLighting::new(&ctx, &desc).unwrap();
        let view = scene.camera.view_desc(1.5);
        let plan = stencil_plan(&scene, &layout, &brdfs, &view, Backend::Ps3);
        let images = engine.lighting_targets(SIZE, ds_format);
        case(Case {
            engine: &engine,
            ctx: &ctx,
            renderer: &renderer,
            lighting,
            frame: plain_frame(&view, &scene.lights, &plan, HookSets::default()),
            tiled: TiledFrame {
                slot: 0,
                view: &view,
                lights: &scene.lights,
                clear_hdr: true,
                side: TileSide::Sixteen,
                mixed: MixedTiles::PerBrdf,
                classify: TileClassify::for_context(&ctx),
                hook_sets: HookSets::default(),
            },
            images: &images,
        });
        images.free(&engine);
        drop(renderer);
        assert!(ctx.validation_log().is_empty(), "messages go to the engine");
    }
    engine.destroy().assert_clean();
}

/// Records `body` into `cmd` (begun here, ended here) and submits it with `fence`, reset first:
/// a frame the GPU may still be running when this returns.
fn submit(
    engine: &Engine,
    (cmd, fence): (vk::CommandBuffer, vk::Fence),
    body: impl FnOnce(vk::CommandBuffer),
) {
    let d = &engine.device;
    let begin =
        vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
    // SAFETY: the engine's device, queue, command buffer and fence, none in use (the fence is
    // unsignalled by its reset; the command buffer's last submission, if any, waited for).
    unsafe {
        let queue = d.get_device_queue(engine.queue_family, 0);
        d.reset_fences(&[fence]).unwrap();
        d.begin_command_buffer(cmd, &begin).unwrap();
        body(cmd);
        d.end_command_buffer(cmd).unwrap();
        let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
        let submit = vk::SubmitInfo2::default().command_buffer_infos(&cmds);
        d.queue_submit2(queue, &[submit], fence).unwrap();
    }
}

#[test]
fn a_slot_in_flight_is_not_recorded_resized_or_destroyed_until_declared_finished() {
    on_a_lighting(|case| {
        let Case {
            engine,
            renderer,
            mut lighting,
            frame,
            tiled,
            images,
            ..
        } = case;
        let mut targets = images.refs();
        let d = &engine.device;
        let slots = engine.frame_slots(2);
        let begin = vk::CommandBufferBeginInfo::default()
            .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
        let (_, first, fence) = slots[0];
        submit(engine, (first, fence), |cmd| unsafe {
            renderer.record_gbuffer(cmd, &mut targets).unwrap();
            lighting.record(cmd, &frame, &mut targets).unwrap();
        });
        assert!(lighting.in_flight());

        // The frame may still run: slot 0 again, a resize and a destroy are refused.
        let (_, second, _) = slots[1];
        unsafe {
            d.begin_command_buffer(second, &begin).unwrap();
            let again = lighting.record(second, &frame, &mut targets.clone());
            let m = match again {
                Err(e @ Error::InFlight(_)) => {
                    assert_eq!(e.cause(), Cause::Usage, "the caller's to prevent");
                    e.to_string()
                }
                other => panic!("slot 0 recorded again in flight: {other:?}"),
            };
            assert!(
                m.contains("slot 0") && m.contains("slot_finished(0)"),
                "{m}"
            );
            let again = lighting.record_tiled(second, &tiled, &mut targets.clone());
            assert!(matches!(again, Err(Error::InFlight(_))), "{again:?}");
            d.end_command_buffer(second).unwrap();
        }
        let bigger = vk::Extent2D {
            width: 96,
            height: 64,
        };
        match lighting.resize(bigger) {
            Err(Error::InFlight(m)) => assert!(m.starts_with("resize while slot 0"), "{m}"),
            other => panic!("a resize in flight: {other:?}"),
        }
        assert_eq!(
            lighting.desc().extent,
            SIZE,
            "a refused resize changes nothing"
        );
        let refused = lighting.destroy().expect_err("a destroy in flight");
        assert!(matches!(refused.error, Error::InFlight(_)), "{refused}");
        let mut lighting = refused.value;
        // A slot past frames_in_flight cannot be declared.
        let past = unsafe { lighting.slot_finished(1) };
        assert!(matches!(past, Err(Error::BadFrame(_))), "{past:?}");

        // Once the engine waited and said so, all three go through.
        unsafe {
            d.wait_for_fences(&[fence], true, u64::MAX).unwrap();
            lighting.slot_finished(0).unwrap();
        }
        assert!(!lighting.in_flight());
        lighting.resize(bigger).unwrap();
        lighting.destroy().unwrap();
        engine.free_frame_slots(&slots);
    });
}

/// An engine that records frame-in-flight 1 into the command buffer of frame 0, still pending,
/// would have slot 1's buffers read under frame 0's fence: refused, naming both slots, before
/// anything is recorded; into its own command buffer it goes through.
#[test]
fn a_slot_recorded_into_another_pending_slots_command_buffer_is_refused() {
    on_a_lighting_with(2, |case| {
        let Case {
            engine,
            renderer,
            mut lighting,
            frame,
            tiled,
            images,
            ..
        } = case;
        let mut targets = images.refs();
        let d = &engine.device;
        let slots = engine.frame_slots(2);
        let (_, first, fence) = slots[0];
        submit(engine, (first, fence), |cmd| unsafe {
            renderer.record_gbuffer(cmd, &mut targets).unwrap();
            lighting.record(cmd, &frame, &mut targets).unwrap();
        });
        let slot_1 = LightingFrame { slot: 1, ..frame };
        // Slot 1 into slot 0's command buffer (its frame pending): refused by either path. The
        // command buffer is not begun again: the check comes before anything is recorded.
        let wrong = unsafe { lighting.record(first, &slot_1, &mut targets.clone()) };
        match wrong {
            Err(Error::InFlight(m)) => assert!(
                m.contains("slot 1") && m.contains("slot 0's frame") && m.contains("fence"),
                "{m}"
            ),
            other => panic!("slot 1 into slot 0's command buffer: {other:?}"),
        }
        let tiled_1 = TiledFrame { slot: 1, ..tiled };
        let wrong = unsafe { lighting.record_tiled(first, &tiled_1, &mut targets.clone()) };
        assert!(matches!(wrong, Err(Error::InFlight(_))), "{wrong:?}");
        // Into its own command buffer, beside the pending slot 0: recorded and run.
        let (_, second, second_fence) = slots[1];
        submit(engine, (second, second_fence), |cmd| unsafe {
            lighting.record(cmd, &slot_1, &mut targets).unwrap();
        });
        unsafe {
            d.wait_for_fences(&[fence, second_fence], true, u64::MAX)
                .unwrap();
            lighting.slot_finished(0).unwrap();
            lighting.slot_finished(1).unwrap();
        }
        lighting.destroy().unwrap();
        engine.free_frame_slots(&slots);
    });
}

#[test]
fn targets_without_the_usage_their_recording_needs_are_refused_naming_it() {
    use vk::ImageUsageFlags as U;
    on_a_lighting(|case| {
        let Case {
            engine,
            mut lighting,
            frame,
            tiled,
            images,
            ..
        } = case;
        // Each case: the targets with one usage taken away, and the words the refusal names.
        let without = |pick: &dyn Fn(&mut histencil_vk::LightingTargets)| {
            let mut t = images.refs();
            pick(&mut t);
            t
        };
        let cases: [(&str, histencil_vk::LightingTargets, bool, &str); 4] = [
            (
                "G-buffer image 0 was made without SAMPLED",
                without(&|t| t.gbuffer[0].usage = U::COLOR_ATTACHMENT),
                false,
                "sample it",
            ),
            (
                "the depth-stencil target was made without SAMPLED",
                without(&|t| t.depth_stencil.usage = U::DEPTH_STENCIL_ATTACHMENT),
                false,
                "hi-stencil",
            ),
            (
                "the HDR target was made without COLOR_ATTACHMENT",
                without(&|t| t.hdr.usage = U::STORAGE),
                false,
                "add light",
            ),
            (
                "the HDR target was made without STORAGE",
                without(&|t| t.hdr.usage = U::COLOR_ATTACHMENT),
                true,
                "stores light",
            ),
        ];
        let (pool, cmd) = engine.command_buffer();
        let d = &engine.device;
        unsafe {
            d.begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default())
                .unwrap();
            for (expected, mut targets, is_tiled, why) in cases {
                let before = targets.clone();
                let result = if is_tiled {
                    lighting.record_tiled(cmd, &tiled, &mut targets)
                } else {
                    lighting.record(cmd, &frame, &mut targets)
                };
                match result {
                    Err(e @ Error::BadFrame(_)) => {
                        assert_eq!(e.cause(), Cause::Usage, "{e}");
                        let m = e.to_string();
                        assert!(m.contains(expected) && m.contains(why), "{m}")
                    }
                    other => panic!("{expected}: accepted: {other:?}"),
                }
                assert_eq!(
                    format!("{:?}", targets.hdr.state),
                    format!("{:?}", before.hdr.state),
                    "nothing recorded"
                );
            }
            d.end_command_buffer(cmd).unwrap();
            d.destroy_command_pool(pool, None);
        }
        assert!(
            !lighting.in_flight(),
            "a refused recording leaves no slot in flight"
        );
        lighting.destroy().unwrap();
    });
}

/// A resize past the device's limits is refused with `DeviceLimit` before anything is made, and
/// leaves the lighting as it was: past `maxImageDimension2D`, and (where the device's
/// `maxStorageBufferRange` is below its largest square image's pixel count) a hi-stencil
/// saved-stencil buffer past `maxStorageBufferRange`. Before, with no memory budget set, both
/// returned `Ok(())` with validation messages. The lighting then resizes and records as ever.
#[test]
fn a_resize_past_the_devices_limits_is_refused_before_anything_is_made() {
    on_a_lighting(|case| {
        let Case {
            engine,
            mut lighting,
            ..
        } = case;
        // SAFETY: the engine's instance and physical device are live.
        let limits = unsafe {
            engine
                .instance
                .get_physical_device_properties(engine.physical_device)
        }
        .limits;
        let max = limits.max_image_dimension2_d;
        let mut past = vec![vk::Extent2D {
            width: max + 1,
            height: 8,
        }];
        // One byte of saved stencil per pixel: the widest square past the storage range.
        let side = (f64::from(limits.max_storage_buffer_range).sqrt() as u32 + 1).min(max);
        if u64::from(side) * u64::from(side) > u64::from(limits.max_storage_buffer_range) {
            past.push(vk::Extent2D {
                width: side,
                height: side,
            });
        }
        for extent in past {
            println!("resize to {}x{}", extent.width, extent.height);
            match lighting.resize(extent) {
                Err(e @ Error::DeviceLimit(_)) => {
                    assert_eq!(e.cause(), Cause::Device);
                    let m = e.to_string();
                    assert!(
                        m.contains("maxImageDimension2D") || m.contains("maxStorageBufferRange"),
                        "{m}"
                    );
                }
                other => panic!("a resize to {extent:?}: {other:?}"),
            }
            assert_eq!(
                lighting.desc().extent,
                SIZE,
                "a refused resize changes nothing"
            );
        }
        let bigger = vk::Extent2D {
            width: 96,
            height: 64,
        };
        lighting.resize(bigger).unwrap();
        assert_eq!(lighting.desc().extent, bigger);
        lighting.destroy().unwrap();
    });
}

/// Records the G-buffer and `lighting`'s frame into the engine's command buffer of `slot`, ended
/// and not submitted.
fn record_unsubmitted(
    case: &mut Case,
    (cmd, fence): (vk::CommandBuffer, vk::Fence),
    targets: &mut histencil_vk::LightingTargets,
) {
    let d = &case.engine.device;
    let begin =
        vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
    // SAFETY: the engine's device, command buffer and fence, none in use.
    unsafe {
        d.reset_fences(&[fence]).unwrap();
        d.begin_command_buffer(cmd, &begin).unwrap();
        case.renderer.record_gbuffer(cmd, targets).unwrap();
        case.lighting.record(cmd, &case.frame, targets).unwrap();
        d.end_command_buffer(cmd).unwrap();
    }
}

/// Submits the recorded `cmd` with `fence` and waits for it.
fn submit_recorded(engine: &Engine, (cmd, fence): (vk::CommandBuffer, vk::Fence)) {
    let d = &engine.device;
    // SAFETY: the engine's queue, an ended command buffer and an unsignalled fence.
    unsafe {
        let queue = d.get_device_queue(engine.queue_family, 0);
        let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
        let submit = vk::SubmitInfo2::default().command_buffer_infos(&cmds);
        d.queue_submit2(queue, &[submit], fence).unwrap();
        d.wait_for_fences(&[fence], true, u64::MAX).unwrap();
    }
}

/// An outside engine recorded a frame, replaced its lighting before submitting (its `destroy`
/// refused, it dropped the value handed back, as the docs allow), then submitted: the frame read
/// freed objects (21 validation messages, then SIGSEGV on lavapipe). Dropped with a slot in
/// flight, the lighting now leaves its objects to the context: the frame runs clean, and
/// `free_retired` frees them once the engine's fence says it is done.
#[test]
fn a_lighting_dropped_between_recording_and_submitting_keeps_what_its_frame_reads() {
    on_a_lighting(|mut case| {
        let slots = case.engine.frame_slots(1);
        let (_, cmd, fence) = slots[0];
        let mut targets = case.images.refs();
        record_unsubmitted(&mut case, (cmd, fence), &mut targets);
        let Case {
            engine,
            ctx,
            lighting,
            ..
        } = case;
        let refused = lighting.destroy().expect_err("a destroy in flight");
        assert!(matches!(refused.error, Error::InFlight(_)), "{refused}");
        drop(refused);
        assert_eq!(ctx.retired_count(), 1, "the dropped lighting's objects");
        submit_recorded(engine, (cmd, fence));
        // SAFETY: the one frame recorded through the dropped lighting finished (its fence).
        unsafe { ctx.free_retired() };
        assert_eq!(ctx.retired_count(), 0);
        engine.free_frame_slots(&slots);
    });
}

/// As above, with the frame's objects left to the context's own drop (after the device is
/// idle), and a second lighting made and recorded meanwhile: nothing is freed early or twice.
#[test]
fn a_lighting_dropped_in_flight_is_freed_with_its_context() {
    on_a_lighting(|mut case| {
        let slots = case.engine.frame_slots(2);
        let mut targets = case.images.refs();
        record_unsubmitted(&mut case, (slots[0].1, slots[0].2), &mut targets);
        let desc = case.lighting.desc().clone();
        let replaced = DeferredLighting::new(case.ctx, &desc).unwrap();
        drop(std::mem::replace(&mut case.lighting, replaced));
        assert_eq!(case.ctx.retired_count(), 1);
        // The second frame takes the images as the first leaves them.
        record_unsubmitted(&mut case, (slots[1].1, slots[1].2), &mut targets);
        submit_recorded(case.engine, (slots[0].1, slots[0].2));
        submit_recorded(case.engine, (slots[1].1, slots[1].2));
        // SAFETY: both frames finished (their fences).
        unsafe { case.lighting.slot_finished(0).unwrap() };
        case.lighting.destroy().unwrap();
        case.engine.free_frame_slots(&slots);
        // The context, dropped by the helper, frees the first lighting's objects.
        assert_eq!(case.ctx.retired_count(), 1);
    });
}

/// A description with fewer BRDFs than its stencil layout has slots panicked at the first frame
/// ("index out of bounds: the len is 5 but the index is 5"); a plan edited by hand (its fields
/// are public) could index past the lighting's BRDFs or its own lights the same way. Each is
/// refused naming what it indexes, before anything is made or recorded.
#[test]
fn descriptions_and_plans_that_index_past_their_lists_are_refused_not_panicked_on() {
    use histencil_model::{PassKind, Shader, Step};
    on_a_lighting(|case| {
        let Case {
            engine,
            ctx,
            mut lighting,
            frame,
            images,
            ..
        } = case;
        let desc = lighting.desc().clone();
        let fewer = histencil_vk::LightingDesc {
            brdfs: desc.brdfs[..desc.brdfs.len() - 1].to_vec(),
            ..desc.clone()
        };
        match DeferredLighting::new(ctx, &fewer) {
            Err(Error::BadSetup(m)) => assert!(m.contains("BRDF slots"), "{m}"),
            Err(other) => panic!("fewer BRDFs than slots: {other}"),
            Ok(_) => panic!("fewer BRDFs than slots: accepted"),
        }
        let slots = desc.brdfs.len() as u32;
        let mut past_slot = frame.plan.clone();
        let shade = (past_slot.steps.iter_mut())
            .find_map(|s| match s {
                Step::Pass { pass, .. } if matches!(pass.kind, PassKind::Shade(_)) => Some(pass),
                _ => None,
            })
            .expect("the plan shades");
        shade.kind = PassKind::Shade(Shader::Brdf(slots));
        let mut past_light = frame.plan.clone();
        for step in &mut past_light.steps {
            if let Step::Pass { light, .. } = step {
                *light = 99;
            }
        }
        let (pool, cmd) = engine.command_buffer();
        let d = &engine.device;
        let cases = [(&past_slot, "BRDF slot"), (&past_light, "light 99")];
        // SAFETY: the engine's command buffer, recording; every case is refused before anything
        // is recorded.
        unsafe {
            d.begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default())
                .unwrap();
            for (plan, words) in cases {
                let bad = LightingFrame { plan, ..frame };
                match lighting.record(cmd, &bad, &mut images.refs()) {
                    Err(e @ Error::BadFrame(_)) => {
                        assert!(e.to_string().contains(words), "{e}")
                    }
                    other => panic!("a plan past its lists: {other:?}"),
                }
            }
            d.end_command_buffer(cmd).unwrap();
            d.destroy_command_pool(pool, None);
        }
        assert!(!lighting.in_flight());
        lighting.destroy().unwrap();
    });
}
