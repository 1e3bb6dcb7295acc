//! The tiled technique recorded into an engine's frames through `DeferredLighting::record_tiled`,
//! and the depth-id technique through `record_depth_id`: the engine's own device, images and
//! fences, two frames in flight, lights moving every frame, both tile sides, both ways of shading
//! mixed tiles, both shapes of the classification, and both techniques. Each of its last six
//! frames (every side with every mixed-tile mode and with depth ids; each side classified both
//! ways) must equal histencil's Renderer lighting the same state with the same technique
//! (classified as the device prefers), bit for bit, and the validation layer with
//! synchronisation validation must see nothing, nor histencil's hazard check, told of each
//! submission and wait. A lighting whose HDR format the
//! kernels cannot store to is refused before anything is recorded.

use ash::vk;
use histencil_tests::engine::{assert_same_hdr, copy_to_buffer, hdr_floats, lights_at, Engine};
use histencil_vk::{
    Context, DeferredLighting, Error, HookSets, LightHooks, LightingDesc, MixedTiles, Readback,
    Renderer, Technique, TileClassify, TileSide, TiledFrame,
};

const WIDTH: u32 = 96;
const HEIGHT: u32 = 64;
const FRAMES: usize = 7;
const IN_FLIGHT: usize = 2;

/// The classification's shape in frame `f`: each side comes round in both within four frames.
fn shape(f: usize) -> TileClassify {
    if matches!(f % 4, 1 | 2) {
        TileClassify::Workgroup
    } else {
        TileClassify::PerInvocation
    }
}

/// The technique of frame `f`: tiled with each mixed-tile mode, or depth ids (`None`), each with
/// both sides, within six frames.
fn tiling(f: usize) -> (TileSide, Option<MixedTiles>) {
    let side = if f.is_multiple_of(2) {
        TileSide::Eight
    } else {
        TileSide::Sixteen
    };
    let mixed = match f % 6 {
        0 | 1 => Some(MixedTiles::PerBrdf),
        2 | 3 => Some(MixedTiles::Branching),
        _ => None,
    };
    (side, mixed)
}

#[test]
fn an_engine_records_the_tiled_technique_into_its_frames() {
    let scene = histencil_scene::embedded("brdfs-3").unwrap();
    assert!(scene.brdfs_in_use().len() >= 3);
    let engine = Engine::start();
    let extent = vk::Extent2D {
        width: WIDTH,
        height: HEIGHT,
    };
    {
        // SAFETY: the engine's handles outlive the context; nothing else uses its queue.
        let ctx = unsafe { Context::from_raw(engine.lend(engine.queue_family)) }.expect("context");
        // histencil's hazard check over the engine's submissions (`note_*` below).
        assert!(ctx.check_hazards(engine.log.clone()));
        let ds_format = ctx.depth_stencil_format().vk();
        let renderer = Renderer::new(&ctx, scene.clone(), WIDTH, HEIGHT).unwrap();
        let desc = LightingDesc {
            layout: *renderer.stencil_layout(),
            brdfs: renderer.brdfs().to_vec(),
            extent,
            depth_stencil_format: ds_format,
            hdr_format: vk::Format::R16G16B16A16_SFLOAT,
            frames_in_flight: IN_FLIGHT as u32,
            max_lights: scene.lights.len() as u32,
            hi_stencil: false,
            hooks: LightHooks::Builtin,
        };
        let mut lighting = DeferredLighting::new(&ctx, &desc).unwrap();
        let images = engine.lighting_targets(extent, ds_format);
        // The last six frames' HDR images, one readback each (two frames may be in flight).
        let captured = FRAMES - 6..FRAMES;
        let readbacks: Vec<_> = captured
            .clone()
            .map(|_| engine.readback_buffer(u64::from(WIDTH * HEIGHT) * 8))
            .collect();
        let mut targets = images.refs();
        let d = &engine.device;
        let queue = unsafe { d.get_device_queue(engine.queue_family, 0) };
        let slots = engine.frame_slots(IN_FLIGHT);
        let view = scene.camera.view_desc(WIDTH as f32 / HEIGHT as f32);
        for f in 0..FRAMES {
            let (pool, cmd, fence) = slots[f % IN_FLIGHT];
            let lights = lights_at(&scene, f);
            let (side, mixed) = tiling(f);
            unsafe {
                d.wait_for_fences(&[fence], true, u64::MAX).unwrap();
                ctx.note_wait(fence);
                lighting.slot_finished((f % IN_FLIGHT) as u32).unwrap();
                d.reset_fences(&[fence]).unwrap();
                d.reset_command_pool(pool, vk::CommandPoolResetFlags::empty())
                    .unwrap();
                let begin = vk::CommandBufferBeginInfo::default()
                    .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
                d.begin_command_buffer(cmd, &begin).unwrap();
                ctx.note_begin(cmd);
                renderer.record_gbuffer(cmd, &mut targets).unwrap();
                let frame = TiledFrame {
                    slot: (f % IN_FLIGHT) as u32,
                    view: &view,
                    lights: &lights,
                    clear_hdr: true,
                    side,
                    mixed: mixed.unwrap_or(MixedTiles::PerBrdf),
                    classify: shape(f),
                    hook_sets: HookSets::default(),
                };
                match mixed {
                    Some(_) => lighting.record_tiled(cmd, &frame, &mut targets).unwrap(),
                    None => lighting.record_depth_id(cmd, &frame, &mut targets).unwrap(),
                }
                if captured.contains(&f) {
                    let readback = &readbacks[f - captured.start];
                    copy_to_buffer(d, cmd, &mut targets.hdr, readback.buffer);
                }
                d.end_command_buffer(cmd).unwrap();
                let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
                let submit = vk::SubmitInfo2::default().command_buffer_infos(&cmds);
                d.queue_submit2(queue, &[submit], fence).unwrap();
                ctx.note_submit(&[cmd], fence);
            }
        }
        let fences: Vec<_> = slots.iter().map(|s| s.2).collect();
        unsafe { d.wait_for_fences(&fences, true, u64::MAX) }.unwrap();
        fences.iter().for_each(|f| ctx.note_wait(*f));
        for slot in 0..IN_FLIGHT as u32 {
            // SAFETY: every slot's fence was waited for just above.
            unsafe { lighting.slot_finished(slot) }.unwrap();
        }
        // histencil's renderer lighting each captured frame's state with the same tiling.
        let readback_hdr = Readback {
            hdr: true,
            ..Readback::NONE
        };
        for (f, readback) in captured.clone().zip(&readbacks) {
            let mut lit = scene.clone();
            lit.lights = lights_at(&scene, f);
            let mut reference = Renderer::new(&ctx, lit, WIDTH, HEIGHT).unwrap();
            let technique = match tiling(f) {
                (side, Some(mixed)) => Technique::Tiled { mixed, side },
                (side, None) => Technique::DepthId { side },
            };
            let expected = reference.render(technique, readback_hdr).unwrap();
            let engine_hdr = hdr_floats(readback.bytes());
            assert_same_hdr(&expected.images.hdr.unwrap().into_raw(), &engine_hdr);
        }

        // The kernels store rgba16f: another HDR format is refused, with nothing recorded.
        let packed = LightingDesc {
            hdr_format: vk::Format::B10G11R11_UFLOAT_PACK32,
            ..desc.clone()
        };
        let mut other = DeferredLighting::new(&ctx, &packed).unwrap();
        let (pool, cmd, _) = slots[0];
        unsafe {
            d.reset_command_pool(pool, vk::CommandPoolResetFlags::empty())
                .unwrap();
            d.begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default())
                .unwrap();
            let lights = lights_at(&scene, 0);
            let frame = TiledFrame {
                slot: 0,
                view: &view,
                lights: &lights,
                clear_hdr: true,
                side: TileSide::Sixteen,
                mixed: MixedTiles::PerBrdf,
                classify: TileClassify::for_context(&ctx),
                hook_sets: HookSets::default(),
            };
            let mut refs = images.refs();
            refs.hdr.format = packed.hdr_format;
            match other.record_tiled(cmd, &frame, &mut refs) {
                Err(Error::BadFrame(m)) => assert!(m.contains("rgba16f"), "{m}"),
                other => panic!("a packed HDR target was not refused: {other:?}"),
            }
            match other.record_depth_id(cmd, &frame, &mut refs) {
                Err(Error::BadFrame(m)) => assert!(m.contains("rgba16f"), "{m}"),
                other => panic!("a packed HDR target was not refused by depth-id: {other:?}"),
            }
            // Depth ids give each BRDF a pass of its own: no kernel branches over mixed tiles.
            let branching = TiledFrame {
                mixed: MixedTiles::Branching,
                ..frame
            };
            match lighting.record_depth_id(cmd, &branching, &mut images.refs()) {
                Err(Error::BadFrame(m)) => assert!(m.contains("a pass of its own"), "{m}"),
                other => panic!("depth-id with branching mixed tiles was accepted: {other:?}"),
            }
            // A light or a view made NaN (after its frame was built, say): refused by both
            // techniques, which plan nothing, as plan_frame refuses them, not shaded as nothing
            // (an outside trial found a NaN view lit black, and SUCCESS said).
            let mut broken = lights.clone();
            broken[0].position.x = f32::NAN;
            let mut bad_view = *frame.view;
            bad_view.world_to_view[3][0] = f32::NAN;
            let nan_light = TiledFrame {
                lights: &broken,
                ..frame
            };
            let nan_view = TiledFrame {
                view: &bad_view,
                ..frame
            };
            for (what, nan, said) in [
                ("light", nan_light, "light 0: "),
                ("view", nan_view, "the view: "),
            ] {
                for (technique, refused) in [
                    (
                        "tiled",
                        lighting.record_tiled(cmd, &nan, &mut images.refs()),
                    ),
                    (
                        "depth-id",
                        lighting.record_depth_id(cmd, &nan, &mut images.refs()),
                    ),
                ] {
                    match refused {
                        Err(Error::BadFrame(m)) => assert!(m.contains(said), "{m}"),
                        other => panic!("a NaN {what} was accepted by {technique}: {other:?}"),
                    }
                }
            }
            d.end_command_buffer(cmd).unwrap();
        }
        drop(other);

        // Every slot's fence was waited for and declared finished above.
        lighting.destroy().unwrap();
        drop(renderer);
        engine.free_frame_slots(&slots);
        images.free(&engine);
        for readback in readbacks {
            engine.free_buffer(readback);
        }
        assert!(ctx.validation_log().is_empty(), "messages go to the engine");
    }
    engine.destroy().assert_clean();
}
