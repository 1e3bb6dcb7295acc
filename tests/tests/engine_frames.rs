//! histencil's lighting recorded into an engine's frames: the test plays the engine (its own
//! device, allocator, images, command pools and fences, two frames in flight), moves the lights
//! every frame, plans each frame on plain data and records `DeferredLighting` into its own
//! command buffers, against its own images handed in with their current state. Its last frame
//! must equal histencil's Renderer lighting the same state, and the validation layer with
//! synchronisation validation must see nothing, leak reports included.

use ash::vk;
use histencil_model::{plan_frame, FlushPolicy, PlanInputs, PlanSettings, TechniqueChoice, View};
use histencil_tests::engine::{
    assert_same_hdr, barrier, copy_to_buffer, hdr_floats, lighting_desc, lights_at, Engine,
};
use histencil_vk::{
    Backend, BrdfSource, Context, DeferredLighting, HookSets, ImageState, LightHooks, LightingDesc,
    LightingFrame, LightingTargets, Readback, Renderer, Technique,
};

const WIDTH: u32 = 96;
const HEIGHT: u32 = 64;
const FRAMES: usize = 7;
const IN_FLIGHT: usize = 2;

/// One frame slot of the engine: its pool, command buffer and fence.
struct Slot {
    pool: vk::CommandPool,
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
}

#[test]
fn an_engine_lights_its_own_images_with_two_frames_in_flight() {
    let mut scene = histencil_scene::embedded("brdfs-3").unwrap();
    assert!(scene.lights.len() >= 4 && scene.brdfs_in_use().len() >= 3);
    let engine = Engine::start();
    let extent = vk::Extent2D {
        width: WIDTH,
        height: HEIGHT,
    };
    let engine_hdr_last;
    {
        // SAFETY: the engine's handles outlive the context; nothing else uses its queue.
        let ctx = unsafe { Context::from_raw(engine.lend(engine.queue_family)) }.expect("context");
        let ds_format = ctx.depth_stencil_format().vk();
        let renderer = Renderer::new(&ctx, scene.clone(), WIDTH, HEIGHT).unwrap();
        let layout = *renderer.stencil_layout();
        let brdfs = renderer.brdfs().to_vec();
        let mut lighting = DeferredLighting::new(
            &ctx,
            &LightingDesc {
                layout,
                brdfs: brdfs.clone(),
                extent,
                depth_stencil_format: ds_format,
                hdr_format: vk::Format::R16G16B16A16_SFLOAT,
                frames_in_flight: IN_FLIGHT as u32,
                max_lights: scene.lights.len() as u32,
                hi_stencil: true,
                hooks: LightHooks::Builtin,
            },
        )
        .unwrap();

        // The engine's images: its own usages (a superset of the contract's).
        let images = engine.lighting_targets(extent, ds_format);
        let readback = engine.readback_buffer(u64::from(WIDTH * HEIGHT) * 8);
        let mut targets = images.refs();

        let d = &engine.device;
        let queue = unsafe { d.get_device_queue(engine.queue_family, 0) };
        let slots: Vec<Slot> = (0..IN_FLIGHT)
            .map(|_| {
                let (pool, cmd) = engine.command_buffer();
                let signalled =
                    vk::FenceCreateInfo::default().flags(vk::FenceCreateFlags::SIGNALED);
                let fence = unsafe { d.create_fence(&signalled, None) }.unwrap();
                Slot { pool, cmd, fence }
            })
            .collect();

        let view = scene.camera.view_desc(WIDTH as f32 / HEIGHT as f32);
        let checked_view = View::new(&view).unwrap();
        let brdf_bounds = scene.brdf_bounds(&brdfs);
        let settings = PlanSettings {
            technique: TechniqueChoice::Stencil,
            caps: Backend::Ps3.platform().caps(),
            flush: FlushPolicy::Auto,
        };
        let mut plans_differ = false;
        let mut last_plan = None;
        for f in 0..FRAMES {
            let slot = &slots[f % IN_FLIGHT];
            let lights = lights_at(&scene, f);
            let shapes: Vec<_> = lights.iter().map(|l| l.shape()).collect();
            let inputs = PlanInputs {
                lights: &shapes,
                brdf_bounds: &brdf_bounds,
                view: &checked_view,
            };
            let plan = plan_frame(&layout, &inputs, &settings).unwrap();
            plans_differ |= last_plan.as_ref().is_some_and(|p| *p != plan);
            unsafe {
                // The engine waits for the frame that last used this slot, nothing more, and
                // says so.
                d.wait_for_fences(&[slot.fence], true, u64::MAX).unwrap();
                lighting.slot_finished((f % IN_FLIGHT) as u32).unwrap();
                d.reset_fences(&[slot.fence]).unwrap();
                d.reset_command_pool(slot.pool, vk::CommandPoolResetFlags::empty())
                    .unwrap();
                d.begin_command_buffer(
                    slot.cmd,
                    &vk::CommandBufferBeginInfo::default()
                        .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
                )
                .unwrap();
                renderer.record_gbuffer(slot.cmd, &mut targets).unwrap();
                // Odd frames: the engine clears HDR itself and lighting adds onto it, from a
                // layout histencil did not choose.
                let clear_hdr = f % 2 == 0;
                if !clear_hdr {
                    clear_color(d, slot.cmd, &mut targets.hdr);
                }
                let frame = LightingFrame {
                    slot: (f % IN_FLIGHT) as u32,
                    view: &view,
                    lights: &lights,
                    plan: &plan,
                    clear_hdr,
                    // The last frame is timed, and an earlier frame in the other slot, whose
                    // later untimed frame must not report its times.
                    timestamps: f == FRAMES - 1 || f == FRAMES - 4,
                    brdf_source: BrdfSource::Formula,
                    tile_stats: false,
                    hook_sets: HookSets::default(),
                };
                lighting.record(slot.cmd, &frame, &mut targets).unwrap();
                if f == FRAMES - 1 {
                    copy_to_buffer(d, slot.cmd, &mut targets.hdr, readback.buffer);
                }
                d.end_command_buffer(slot.cmd).unwrap();
                let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(slot.cmd)];
                let submit = vk::SubmitInfo2::default().command_buffer_infos(&cmds);
                d.queue_submit2(queue, &[submit], slot.fence).unwrap();
            }
            last_plan = Some(plan);
        }
        assert!(plans_differ, "the moving lights never changed the plan");
        let fences: Vec<_> = slots.iter().map(|s| s.fence).collect();
        unsafe { d.wait_for_fences(&fences, true, u64::MAX) }.unwrap();
        for slot in 0..IN_FLIGHT as u32 {
            // SAFETY: every slot's fence was waited for just above.
            unsafe { lighting.slot_finished(slot) }.unwrap();
        }
        engine_hdr_last = hdr_floats(readback.bytes());
        let timings = lighting
            .step_timings(((FRAMES - 1) % IN_FLIGHT) as u32)
            .unwrap()
            .expect("the last frame was timed");
        assert!(
            timings.groups.iter().any(|(g, _)| g.starts_with("shade-")),
            "{:?}",
            timings.groups
        );
        assert!(
            lighting
                .step_timings((FRAMES % IN_FLIGHT) as u32)
                .unwrap()
                .is_none(),
            "the other slot's last frame asked for no timestamps"
        );

        // histencil's own renderer, lighting the last frame's state: the same pixels, bit for
        // bit.
        scene.lights = lights_at(&scene, FRAMES - 1);
        let mut reference = Renderer::new(&ctx, scene.clone(), WIDTH, HEIGHT).unwrap();
        let technique = Technique::Stencil {
            backend: Backend::Ps3,
            flush: FlushPolicy::Auto,
        };
        let readback_hdr = Readback {
            hdr: true,
            ..Readback::NONE
        };
        let expected = reference.render(technique, readback_hdr).unwrap();
        assert_same_hdr(&expected.images.hdr.unwrap().into_raw(), &engine_hdr_last);

        drop(reference);
        // Every slot's fence was waited for and declared above: the engine frees the lighting
        // without a device-wide wait (the validation layer would see objects destroyed in use).
        lighting.destroy().unwrap();
        drop(renderer);
        unsafe {
            for s in &slots {
                d.destroy_fence(s.fence, None);
                d.destroy_command_pool(s.pool, None);
            }
        }
        images.free(&engine);
        engine.free_buffer(readback);
        assert!(ctx.validation_log().is_empty(), "messages go to the engine");
    }
    engine.destroy().assert_clean();
}

/// The engine's own clear of its HDR image, tracked in the image's state.
unsafe fn clear_color(d: &ash::Device, cmd: vk::CommandBuffer, image: &mut histencil_vk::ImageRef) {
    let state = ImageState {
        layout: vk::ImageLayout::TRANSFER_DST_OPTIMAL,
        stage: vk::PipelineStageFlags2::CLEAR,
        access: vk::AccessFlags2::TRANSFER_WRITE,
    };
    barrier(d, cmd, image, state, true);
    let range = color_range();
    let black = vk::ClearColorValue { float32: [0.0; 4] };
    d.cmd_clear_color_image(cmd, image.image, state.layout, &black, &[range]);
}

fn color_range() -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange::default()
        .aspect_mask(vk::ImageAspectFlags::COLOR)
        .level_count(1)
        .layer_count(1)
}

/// Every description and frame that does not fit is refused with `BadFrame` before anything is
/// recorded (the command buffer ends empty and valid), one case per class of mistake.
#[test]
fn frames_that_do_not_fit_are_refused_before_recording() {
    let scene = histencil_scene::embedded("brdfs-3").unwrap();
    let engine = Engine::start();
    let extent = vk::Extent2D {
        width: 32,
        height: 16,
    };
    {
        // SAFETY: as in the frames-in-flight test.
        let ctx = unsafe { Context::from_raw(engine.lend(engine.queue_family)) }.expect("context");
        let ds_format = ctx.depth_stencil_format().vk();
        let renderer = Renderer::new(&ctx, scene.clone(), extent.width, extent.height).unwrap();
        let layout = *renderer.stencil_layout();
        let desc = LightingDesc {
            layout,
            brdfs: renderer.brdfs().to_vec(),
            extent,
            depth_stencil_format: ds_format,
            hdr_format: vk::Format::R16G16B16A16_SFLOAT,
            frames_in_flight: 2,
            max_lights: scene.lights.len() as u32,
            hi_stencil: true,
            hooks: LightHooks::Builtin,
        };
        let bad_descs = [
            LightingDesc {
                extent: vk::Extent2D {
                    width: 0,
                    height: 16,
                },
                ..desc.clone()
            },
            LightingDesc {
                depth_stencil_format: vk::Format::D32_SFLOAT,
                ..desc.clone()
            },
            LightingDesc {
                frames_in_flight: 0,
                ..desc.clone()
            },
            LightingDesc {
                brdfs: [desc.brdfs.clone(), desc.brdfs.clone()].concat(),
                ..desc.clone()
            },
        ];
        for bad in &bad_descs {
            let err = DeferredLighting::new(&ctx, bad).err().expect("refused");
            assert!(matches!(err, histencil_vk::Error::BadSetup(_)), "{err}");
        }

        let mut lighting = DeferredLighting::new(&ctx, &desc).unwrap();
        let images = engine.lighting_targets(extent, ds_format);
        let small = engine.image(
            "s",
            vk::Format::R16G16B16A16_SFLOAT,
            vk::Extent2D {
                width: 8,
                height: 8,
            },
            vk::ImageUsageFlags::COLOR_ATTACHMENT,
        );
        let targets = images.refs();
        let view = scene.camera.view_desc(2.0);
        let shapes: Vec<_> = scene.lights.iter().map(|l| l.shape()).collect();
        let bounds = scene.brdf_bounds(renderer.brdfs());
        let plan = plan_frame(
            &layout,
            &PlanInputs {
                lights: &shapes,
                brdf_bounds: &bounds,
                view: &View::new(&view).unwrap(),
            },
            &PlanSettings {
                technique: TechniqueChoice::Stencil,
                caps: Backend::Native.platform().caps(),
                flush: FlushPolicy::Auto,
            },
        )
        .unwrap();
        let frame = LightingFrame {
            slot: 0,
            view: &view,
            lights: &scene.lights,
            plan: &plan,
            clear_hdr: true,
            timestamps: false,
            brdf_source: BrdfSource::Formula,
            tile_stats: false,
            hook_sets: HookSets::default(),
        };
        let reversed = histencil_model::ViewDesc {
            depth: histencil_model::DepthConvention::Reversed,
            ..view
        };
        let mut orthographic = view;
        orthographic.view_to_clip[2][3] = 0.0;
        orthographic.view_to_clip[3][3] = 1.0;
        // Planned for the orthographic view itself, so that the projection check speaks.
        let orthographic_plan = plan_frame(
            &layout,
            &PlanInputs {
                lights: &shapes,
                brdf_bounds: &bounds,
                view: &View::new(&orthographic).unwrap(),
            },
            &PlanSettings {
                technique: TechniqueChoice::Stencil,
                caps: Backend::Native.platform().caps(),
                flush: FlushPolicy::Auto,
            },
        )
        .unwrap();
        // Confined by the depth bounds test, which an engine's device is not known to have.
        let bounded_plan = plan.clone().with_depth_bounds();
        assert!(bounded_plan.uses_depth_bounds());
        let few_lights = &scene.lights[..2];
        // A plan made before the camera moved, the projection changed or a light moved: each
        // recorded without an error and lit the frame wrong (the case: the camera moved
        // inside a spot light's volume, its light missing from most of the floor).
        let mut moved_camera = view;
        moved_camera.world_to_view[3][0] += 0.25;
        let mut zoomed = view;
        zoomed.view_to_clip[0][0] *= 1.1;
        let mut moved_lights = scene.lights.clone();
        moved_lights[1].position.y += 0.5;
        let cases: Vec<(&str, LightingFrame, LightingTargets)> = vec![
            ("slot", LightingFrame { slot: 2, ..frame }, targets.clone()),
            (
                "no depth bounds test",
                LightingFrame {
                    plan: &bounded_plan,
                    ..frame
                },
                targets.clone(),
            ),
            (
                "plan lights input",
                LightingFrame {
                    lights: few_lights,
                    ..frame
                },
                targets.clone(),
            ),
            (
                "depth",
                LightingFrame {
                    view: &reversed,
                    ..frame
                },
                targets.clone(),
            ),
            (
                "perspective",
                LightingFrame {
                    view: &orthographic,
                    plan: &orthographic_plan,
                    ..frame
                },
                targets.clone(),
            ),
            (
                "another camera position or orientation",
                LightingFrame {
                    view: &moved_camera,
                    ..frame
                },
                targets.clone(),
            ),
            (
                "another projection",
                LightingFrame {
                    view: &zoomed,
                    ..frame
                },
                targets.clone(),
            ),
            (
                "light 1 moved or changed shape",
                LightingFrame {
                    lights: &moved_lights,
                    ..frame
                },
                targets.clone(),
            ),
            (
                "is 8x8",
                frame,
                LightingTargets {
                    hdr: small.as_ref(ImageState::UNDEFINED),
                    ..targets.clone()
                },
            ),
            (
                "built-in hooks",
                LightingFrame {
                    hook_sets: HookSets {
                        decode: Some(vk::DescriptorSet::null()),
                        visibility: None,
                    },
                    ..frame
                },
                targets.clone(),
            ),
            (
                "histencil's G-buffer has 3",
                frame,
                LightingTargets {
                    gbuffer: targets.gbuffer[..2].to_vec(),
                    ..targets.clone()
                },
            ),
            (
                "expects",
                frame,
                LightingTargets {
                    gbuffer: vec![targets.gbuffer[1], targets.gbuffer[0], targets.gbuffer[2]],
                    ..targets.clone()
                },
            ),
        ];
        let d = &engine.device;
        unsafe {
            let (pool, cmd) = engine.command_buffer();
            d.begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default())
                .unwrap();
            for (expected, frame, mut targets) in cases {
                let before = targets.clone();
                let err = lighting
                    .record(cmd, &frame, &mut targets)
                    .expect_err(expected);
                assert!(
                    matches!(err, histencil_vk::Error::BadFrame(_))
                        && err.to_string().contains(expected),
                    "{expected}: {err}"
                );
                assert_eq!(
                    targets.hdr.state, before.hdr.state,
                    "{expected}: state changed"
                );
            }
            d.end_command_buffer(cmd).unwrap();
            d.destroy_command_pool(pool, None);
        }

        // Without the hi-stencil emulation: a PS3-like plan is refused, a native one records
        // and runs (on a one-tile surface) with nothing for the validation layer to report.
        let mut native_only = DeferredLighting::new(
            &ctx,
            &LightingDesc {
                hi_stencil: false,
                hooks: LightHooks::Builtin,
                ..desc.clone()
            },
        )
        .unwrap();
        let ps3_plan = plan_frame(
            &layout,
            &PlanInputs {
                lights: &shapes,
                brdf_bounds: &bounds,
                view: &View::new(&view).unwrap(),
            },
            &PlanSettings {
                technique: TechniqueChoice::Stencil,
                caps: Backend::Ps3.platform().caps(),
                flush: FlushPolicy::Auto,
            },
        )
        .unwrap();
        unsafe {
            let (pool, cmd) = engine.command_buffer();
            d.begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default())
                .unwrap();
            let mut t = targets;
            let ps3 = LightingFrame {
                plan: &ps3_plan,
                ..frame
            };
            let err = native_only.record(cmd, &ps3, &mut t).expect_err("refused");
            assert!(err.to_string().contains("hi-stencil"), "{err}");
            // Statistics need the emulation.
            let stats = LightingFrame {
                tile_stats: true,
                hook_sets: HookSets::default(),
                ..frame
            };
            let err = native_only
                .record(cmd, &stats, &mut t)
                .expect_err("statistics");
            assert!(
                matches!(err, histencil_vk::Error::Unsupported(_)),
                "statistics: {err}"
            );
            // The LUT technique before its tables is a call out of order: a bad frame, naming
            // what to call first (an outside trial read "not supported yet").
            let tables = LightingFrame {
                brdf_source: BrdfSource::Table,
                ..frame
            };
            match native_only.record(cmd, &tables, &mut t) {
                Err(histencil_vk::Error::BadFrame(m)) => {
                    assert!(m.contains("set_lut_tables"), "{m}")
                }
                other => panic!("the LUT technique before its tables: {other:?}"),
            }
            native_only
                .record(cmd, &frame, &mut t)
                .expect("a native plan");
            engine.submit_and_wait(pool, cmd);
        }
        // No emulation, no counters: no statistics rather than zeros.
        assert_eq!(native_only.tile_stats(frame.plan), None);
        drop(native_only);
        drop(lighting);
        drop(renderer);
        images.free(&engine);
        engine.free_image(small);
    }
    engine.destroy().assert_clean();
}

/// The LUT technique and the hi-stencil statistics through the engine-facing recording: the
/// engine lends the renderer's tables, records a PS3-like LUT frame that counts tiles into its
/// own images, and gets the renderer's frame bit for bit and its statistics exactly.
#[test]
fn an_engine_records_the_lut_technique_and_counts_tiles() {
    let scene = histencil_scene::embedded("brdfs-3").unwrap();
    let engine = Engine::start();
    let extent = vk::Extent2D {
        width: WIDTH,
        height: HEIGHT,
    };
    {
        // SAFETY: as in the frames-in-flight test.
        let ctx = unsafe { Context::from_raw(engine.lend(engine.queue_family)) }.expect("context");
        let ds_format = ctx.depth_stencil_format().vk();
        let mut renderer = Renderer::new(&ctx, scene.clone(), WIDTH, HEIGHT).unwrap();
        let technique = Technique::Lut {
            backend: Backend::Ps3,
            flush: FlushPolicy::Auto,
        };
        let plan = renderer.plan(technique).unwrap();
        let mut lighting = DeferredLighting::new(
            &ctx,
            &lighting_desc(
                *renderer.stencil_layout(),
                renderer.brdfs().to_vec(),
                extent,
                ds_format,
                scene.lights.len(),
            ),
        )
        .unwrap();
        // SAFETY: the renderer's tables outlive the one frame below, which is waited for.
        unsafe { lighting.set_lut_tables(renderer.lut_tables().unwrap()) };
        let images = engine.lighting_targets(extent, ds_format);
        let readback = engine.readback_buffer(u64::from(WIDTH * HEIGHT) * 8);
        let mut targets = images.refs();
        let view = scene.camera.view_desc(WIDTH as f32 / HEIGHT as f32);
        // The lights as the renderer validated them (directions unit, ranges capped).
        let lights = renderer.scene().lights.clone();
        let frame = LightingFrame {
            slot: 0,
            view: &view,
            lights: &lights,
            plan: &plan,
            clear_hdr: true,
            timestamps: false,
            brdf_source: BrdfSource::Table,
            tile_stats: true,
            hook_sets: HookSets::default(),
        };
        let d = &engine.device;
        unsafe {
            let (pool, cmd) = engine.command_buffer();
            d.begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default())
                .unwrap();
            renderer.record_gbuffer(cmd, &mut targets).unwrap();
            lighting.record(cmd, &frame, &mut targets).unwrap();
            copy_to_buffer(d, cmd, &mut targets.hdr, readback.buffer);
            engine.submit_and_wait(pool, cmd);
        }
        let ours = hdr_floats(readback.bytes());
        let stats = lighting.tile_stats(&plan).expect("made with hi-stencil");

        let expected = renderer
            .render_frame(&histencil_vk::FrameDesc {
                tile_stats: true,
                ..histencil_vk::FrameDesc::new(
                    technique,
                    Readback {
                        hdr: true,
                        ..Readback::NONE
                    },
                )
            })
            .unwrap();
        let reference = expected.images.hdr.unwrap().into_raw();
        let differing = reference
            .iter()
            .zip(&ours)
            .filter(|(e, a)| e.to_bits() != a.to_bits())
            .count();
        let examples: Vec<_> = reference
            .iter()
            .zip(&ours)
            .enumerate()
            .filter(|(_, (e, a))| e.to_bits() != a.to_bits())
            .take(4)
            .collect();
        assert_eq!(
            differing, 0,
            "channels differ from the renderer's LUT frame: {examples:?}"
        );
        assert!(ours.iter().any(|v| *v > 0.0), "the frame is dark");
        assert_eq!(Some(stats), expected.tile_stats);
        assert!(
            stats.tiles_culled > 0 && stats.fragments_shaded > 0,
            "{stats:?}"
        );

        drop(lighting);
        drop(renderer);
        images.free(&engine);
        engine.free_buffer(readback);
        assert!(ctx.validation_log().is_empty(), "messages go to the engine");
    }
    engine.destroy().assert_clean();
}

/// The depth-stencil format is named once: a context lent one (`BorrowedDevice::depth_stencil`)
/// refuses a lighting described in another, naming both, before it makes anything; a context
/// lent none takes the lighting's.
#[test]
fn a_lighting_in_another_depth_format_than_the_context_was_lent_is_refused() {
    let scene = histencil_scene::embedded("brdfs-3").unwrap();
    let engine = Engine::start();
    {
        let lent = histencil_vk::BorrowedDevice {
            depth_stencil: Some(histencil_vk::DepthStencilFormat::D32S8),
            ..engine.lend(engine.queue_family)
        };
        // SAFETY: as in the frames-in-flight test.
        let ctx = unsafe { Context::from_raw(lent) }.expect("context");
        let renderer = Renderer::new(&ctx, scene.clone(), 32, 16).unwrap();
        let desc = LightingDesc {
            layout: *renderer.stencil_layout(),
            brdfs: renderer.brdfs().to_vec(),
            extent: vk::Extent2D {
                width: 32,
                height: 16,
            },
            depth_stencil_format: vk::Format::D24_UNORM_S8_UINT,
            hdr_format: vk::Format::R16G16B16A16_SFLOAT,
            frames_in_flight: 1,
            max_lights: scene.lights.len() as u32,
            hi_stencil: false,
            hooks: LightHooks::Builtin,
        };
        let in_use = ctx.memory_in_use();
        let err = DeferredLighting::new(&ctx, &desc).err().expect("refused");
        let text = err.to_string();
        assert!(
            text.contains("D24_UNORM_S8_UINT") && text.contains("D32_SFLOAT_S8_UINT"),
            "{text}"
        );
        // A creation mistake, said as one (it read "bad lighting frame" before).
        assert!(matches!(err, histencil_vk::Error::BadSetup(_)), "{err}");
        assert!(text.starts_with("bad lighting setup: "), "{text}");
        assert_eq!(ctx.memory_in_use(), in_use);
        let named = LightingDesc {
            depth_stencil_format: vk::Format::D32_SFLOAT_S8_UINT,
            ..desc
        };
        drop(DeferredLighting::new(&ctx, &named).expect("the lent format"));
    }
    assert!(engine.destroy().problems().is_empty());
}
