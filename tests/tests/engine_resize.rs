//! An engine resizes its window: `DeferredLighting::resize` keeps every pipeline (light volumes
//! and the tiled kernels) and makes only the per-extent surfaces anew, and the resized lighting
//! lights the new size exactly as histencil's Renderer made at that size does, bit for bit, on
//! the PS3-like backend (its hi-stencil surface resized) and with the tiled technique (its tile
//! buffers resized), under the validation layer with synchronisation validation.

use ash::vk;
use histencil_model::FlushPolicy;
use histencil_tests::engine::{
    assert_same_hdr, copy_to_buffer, hdr_floats, lighting_desc, plain_frame, stencil_plan, Engine,
};
use histencil_vk::{
    Backend, Context, DeferredLighting, HookSets, MixedTiles, Readback, Renderer, Technique,
    TileClassify, TileSide, TiledFrame,
};

#[test]
fn a_resize_keeps_every_pipeline_and_lights_the_new_size_exactly() {
    let mut scene = histencil_scene::embedded("brdfs-3").unwrap();
    // The lights as the renderer's scene validation leaves them, so that both light the same.
    scene.normalise_lights();
    let engine = Engine::start();
    // One aspect for both sizes: one view, one plan, the same pipelines needed.
    let (small, large) = ((48, 32), (96, 64));
    let extent = |(width, height)| vk::Extent2D { width, height };
    {
        // SAFETY: the engine's handles outlive the context; nothing else uses its queue.
        let ctx = unsafe { Context::from_raw(engine.lend(engine.queue_family)) }.expect("context");
        let ds_format = ctx.depth_stencil_format().vk();
        let renderers = [small, large].map(|(w, h)| Renderer::new(&ctx, scene.clone(), w, h));
        let [small_renderer, large_renderer] = renderers.map(Result::unwrap);
        let layout = *small_renderer.stencil_layout();
        let brdfs = small_renderer.brdfs().to_vec();
        let mut lighting = DeferredLighting::new(
            &ctx,
            &lighting_desc(
                layout,
                brdfs.clone(),
                extent(small),
                ds_format,
                scene.lights.len(),
            ),
        )
        .unwrap();
        let view = scene.camera.view_desc(1.5);
        let plan = stencil_plan(&scene, &layout, &brdfs, &view, Backend::Ps3);
        let (side, mixed) = (TileSide::Sixteen, MixedTiles::PerBrdf);
        let d = &engine.device;
        // One frame at `size`: the renderer's G-buffer, then the lighting (tiled or the plan),
        // submitted and waited for; its HDR image as floats.
        let frame = |lighting: &mut DeferredLighting<&Context>,
                     renderer: &Renderer,
                     size: (u32, u32),
                     tiled: bool| {
            let images = engine.lighting_targets(extent(size), ds_format);
            let readback = engine.readback_buffer(u64::from(size.0 * size.1) * 8);
            let mut targets = images.refs();
            let (pool, cmd) = engine.command_buffer();
            unsafe {
                d.begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default())
                    .unwrap();
                renderer.record_gbuffer(cmd, &mut targets).unwrap();
                if tiled {
                    let frame = TiledFrame {
                        slot: 0,
                        view: &view,
                        lights: &scene.lights,
                        clear_hdr: true,
                        side,
                        mixed,
                        classify: TileClassify::for_context(&ctx),
                        hook_sets: HookSets::default(),
                    };
                    lighting.record_tiled(cmd, &frame, &mut targets).unwrap();
                } else {
                    let frame = plain_frame(&view, &scene.lights, &plan, HookSets::default());
                    lighting.record(cmd, &frame, &mut targets).unwrap();
                }
                copy_to_buffer(d, cmd, &mut targets.hdr, readback.buffer);
                engine.submit_and_wait(pool, cmd);
                lighting.slot_finished(0).unwrap();
            }
            let hdr = hdr_floats(readback.bytes());
            images.free(&engine);
            engine.free_buffer(readback);
            hdr
        };
        // Both techniques at the first size: every pipeline they need is made.
        frame(&mut lighting, &small_renderer, small, false);
        frame(&mut lighting, &small_renderer, small, true);
        let made = (lighting.pipeline_count(), lighting.tiled_pipeline_count());
        assert!(made.0 > 0 && made.1 > 0, "{made:?}");

        // Every frame above was waited for and declared finished.
        let refused = lighting.resize(extent((0, 64)));
        assert!(
            matches!(refused, Err(histencil_vk::Error::BadSetup(_))),
            "{refused:?}"
        );
        lighting.resize(extent(large)).unwrap();
        let stencil_hdr = frame(&mut lighting, &large_renderer, large, false);
        let tiled_hdr = frame(&mut lighting, &large_renderer, large, true);
        assert_eq!(
            (lighting.pipeline_count(), lighting.tiled_pipeline_count()),
            made,
            "a resize made pipelines again"
        );

        // histencil's own renderer at the new size: the same pixels, bit for bit.
        drop(small_renderer);
        let mut reference = large_renderer;
        let readback_hdr = Readback {
            hdr: true,
            ..Readback::NONE
        };
        let stencil = Technique::Stencil {
            backend: Backend::Ps3,
            flush: FlushPolicy::Auto,
        };
        for (technique, engine_hdr) in [
            (stencil, stencil_hdr),
            (Technique::Tiled { mixed, side }, tiled_hdr),
        ] {
            let expected = reference.render(technique, readback_hdr).unwrap();
            assert_same_hdr(&expected.images.hdr.unwrap().into_raw(), &engine_hdr);
        }
        drop(reference);
        lighting.destroy().unwrap();
        assert!(ctx.validation_log().is_empty(), "messages go to the engine");
    }
    engine.destroy().assert_clean();
}
