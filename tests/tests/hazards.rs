//! The hazard check can fail: each of histencil's buffer hand-overs left out
//! (`histencil_vk::omit_hand_over`), a frame that needs it is reported as a hazard naming the
//! buffer and both passes, where synchronisation validation and lavapipe's in-order execution
//! see nothing; with every hand-over in place the same frames are clean (every other test's
//! clean log holds that too). And a shader writing a buffer its pass did not declare is an
//! error naming the pass.

use histencil_tests::instance_turn;
use histencil_vk::{
    omit_hand_over, Backend, Context, ContextDesc, FlushPolicy, FrameDesc, HandOver, MixedTiles,
    Readback, Renderer, Technique, TileSide,
};

/// The messages of rendering two frames of `scene` with `technique` on a validated context
/// while `omitted` is left out (none: every hand-over recorded).
fn messages(scene: &str, technique: Technique, omitted: Option<HandOver>) -> Vec<String> {
    let _turn = instance_turn();
    let ctx = Context::new(ContextDesc::validated()).expect("a validated Vulkan 1.3 device");
    let log = ctx.validation_log();
    let scene = histencil_scene::embedded(scene).expect("scene");
    {
        let mut renderer = Renderer::new(&ctx, scene, 64, 64).expect("renderer");
        let _omitted = omitted.map(omit_hand_over);
        // Counted: the statistics draws are what the light passes' split orders.
        let desc = FrameDesc {
            tile_stats: true,
            ..FrameDesc::new(technique, Readback::NONE)
        };
        for _ in 0..2 {
            renderer.render_frame(&desc).expect("frame");
        }
    }
    drop(ctx);
    log.problems()
}

/// The validation layer's own synchronisation messages among `messages`.
fn layer_sync(messages: &[String]) -> Vec<&String> {
    messages
        .iter()
        .filter(|m| m.contains("SYNC-HAZARD"))
        .collect()
}

fn hazards(messages: &[String]) -> Vec<&String> {
    messages
        .iter()
        .filter(|m| m.contains("HISTENCIL-HAZARD"))
        .collect()
}

const STENCIL_PS3: Technique = Technique::Stencil {
    backend: Backend::Ps3,
    flush: FlushPolicy::Auto,
};
const TILED: Technique = Technique::Tiled {
    mixed: MixedTiles::Branching,
    side: TileSide::Sixteen,
};

#[test]
fn hazard_light_split_removed() {
    assert!(messages("brdfs-3", STENCIL_PS3, None).is_empty());
    let found = messages("brdfs-3", STENCIL_PS3, Some(HandOver::LightSplit));
    for m in hazards(&found) {
        eprintln!("{m}");
    }
    assert!(!hazards(&found).is_empty(), "{found:#?}");
    // The layer does not see the statistics draws' atomics unordered.
    assert!(layer_sync(&found).is_empty(), "{found:#?}");
}

#[test]
fn hazard_tile_lists_removed() {
    assert!(messages("brdfs-3", TILED, None).is_empty());
    let found = messages("brdfs-3", TILED, Some(HandOver::TileLists));
    for m in hazards(&found) {
        eprintln!("{m}");
    }
    assert!(!hazards(&found).is_empty(), "{found:#?}");
}

/// The messages of an engine's `frames` frames in two slots, both in flight before either is
/// waited for, alternating the depth-id technique (even frames) and the tiled one (odd), with
/// the hazard check told of every submission and wait, while `omitted` is left out.
fn engine_messages(frames: usize, omitted: Option<HandOver>) -> Vec<String> {
    use ash::vk;
    use histencil_tests::engine::{lights_at, Engine};
    use histencil_vk::{
        DeferredLighting, HookSets, LightHooks, LightingDesc, TileClassify, TiledFrame,
    };
    const SIZE: u32 = 64;
    const IN_FLIGHT: usize = 2;
    let scene = histencil_scene::embedded("brdfs-3").expect("scene");
    let engine = Engine::start();
    let extent = vk::Extent2D {
        width: SIZE,
        height: SIZE,
    };
    {
        // SAFETY: the engine's handles outlive the context; nothing else uses its queue.
        let ctx = unsafe { Context::from_raw(engine.lend(engine.queue_family)) }.expect("context");
        assert!(ctx.check_hazards(engine.log.clone()));
        let ds_format = ctx.depth_stencil_format().vk();
        let renderer = Renderer::new(&ctx, scene.clone(), SIZE, SIZE).expect("renderer");
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
        let mut lighting = DeferredLighting::new(&ctx, &desc).expect("lighting");
        let images = engine.lighting_targets(extent, ds_format);
        let mut targets = images.refs();
        let d = &engine.device;
        // SAFETY: the engine's queue family has queue 0.
        let queue = unsafe { d.get_device_queue(engine.queue_family, 0) };
        let slots = engine.frame_slots(IN_FLIGHT);
        let view = scene.camera.view_desc(1.0);
        let _omitted = omitted.map(omit_hand_over);
        for f in 0..frames {
            let (pool, cmd, fence) = slots[f % IN_FLIGHT];
            let lights = lights_at(&scene, f);
            // SAFETY: the slot's fence is waited for before its pool is reset; the command
            // buffer is recorded, submitted and told to the check in order.
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
                    side: TileSide::Sixteen,
                    mixed: MixedTiles::PerBrdf,
                    classify: TileClassify::for_context(&ctx),
                    hook_sets: HookSets::default(),
                };
                if f % 2 == 0 {
                    lighting.record_depth_id(cmd, &frame, &mut targets).unwrap();
                } else {
                    lighting.record_tiled(cmd, &frame, &mut targets).unwrap();
                }
                d.end_command_buffer(cmd).unwrap();
                let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
                let submit = vk::SubmitInfo2::default().command_buffer_infos(&cmds);
                d.queue_submit2(queue, &[submit], fence).unwrap();
                ctx.note_submit(&[cmd], fence);
            }
        }
        let fences: Vec<_> = slots.iter().map(|s| s.2).collect();
        // SAFETY: the fences are the engine's, each submitted with a frame.
        unsafe { d.wait_for_fences(&fences, true, u64::MAX) }.unwrap();
        for (slot, fence) in fences.iter().enumerate() {
            ctx.note_wait(*fence);
            // SAFETY: every slot's fence was waited for just above.
            unsafe { lighting.slot_finished(slot as u32) }.unwrap();
        }
        lighting.destroy().expect("no slot in flight");
        drop(renderer);
        engine.free_frame_slots(&slots);
        images.free(&engine);
    }
    engine.destroy().problems()
}

#[test]
fn hazard_tile_rewrite_removed_across_two_slots_submissions() {
    assert!(engine_messages(4, None).is_empty());
    let found = engine_messages(4, Some(HandOver::TileRewrite));
    for m in hazards(&found) {
        eprintln!("{m}");
    }
    assert!(!hazards(&found).is_empty(), "{found:#?}");
    // The layer does not see a hand-over missing across submissions.
    assert!(layer_sync(&found).is_empty(), "{found:#?}");
}

/// Check (a): a shader writing a buffer its pass did not declare is an error naming the pass,
/// the set and binding and the buffer, since no barrier can be derived for it.
#[test]
fn hazard_undeclared_shader_write() {
    let found = messages("brdfs-3", TILED, Some(HandOver::ClassifyDeclaration));
    let undeclared: Vec<_> = found
        .iter()
        .filter(|m| m.contains("HISTENCIL-UNDECLARED-WRITE"))
        .collect();
    assert!(
        undeclared
            .iter()
            .any(|m| m.contains("tile-classify: set 2 binding 1") && m.contains("`tiled-lists`")),
        "{found:#?}"
    );
}
