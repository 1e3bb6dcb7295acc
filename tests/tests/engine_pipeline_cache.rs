//! An engine's pipeline cache (`BorrowedDevice::pipeline_cache`) is the cache of every pipeline
//! histencil makes on the lent device: two lightings, each with its light-volume and tiled
//! pipelines, record under the validation layer with it, and the cache stays the engine's (its
//! data a valid cache the driver wrote; histencil destroys nothing of it). Whether a warm cache
//! spares compilation is the driver's business: both lavapipe builds here keep no pipeline data
//! (the 32-byte header alone after 17 pipelines), so it is not measured here.

use ash::vk;
use histencil_tests::engine::{copy_to_buffer, lighting_desc, Engine};
use histencil_vk::{
    BorrowedDevice, Context, DeferredLighting, HookSets, MixedTiles, Renderer, TileClassify,
    TileSide, TiledFrame,
};

#[test]
fn an_engines_pipeline_cache_serves_every_lighting_on_its_device() {
    let mut scene = histencil_scene::embedded("brdfs-3").unwrap();
    scene.normalise_lights();
    let engine = Engine::start();
    let d = &engine.device;
    let info = vk::PipelineCacheCreateInfo::default();
    // SAFETY: a cache on the engine's live device, destroyed below after everything using it.
    let cache = unsafe { d.create_pipeline_cache(&info, None) }.unwrap();
    let (width, height) = (48, 32);
    {
        let lent = BorrowedDevice {
            pipeline_cache: Some(cache),
            ..engine.lend(engine.queue_family)
        };
        // SAFETY: the engine's handles outlive the context; nothing else uses its queue.
        let ctx = unsafe { Context::from_raw(lent) }.expect("context");
        assert_eq!(ctx.pipeline_cache(), cache);
        let ds_format = ctx.depth_stencil_format().vk();
        let renderer = Renderer::new(&ctx, scene.clone(), width, height).unwrap();
        let desc = lighting_desc(
            *renderer.stencil_layout(),
            renderer.brdfs().to_vec(),
            vk::Extent2D { width, height },
            ds_format,
            scene.lights.len(),
        );
        let view = scene.camera.view_desc(1.5);
        for _ in 0..2 {
            let mut lighting = DeferredLighting::new(&ctx, &desc).unwrap();
            let images = engine.lighting_targets(desc.extent, ds_format);
            let readback = engine.readback_buffer(u64::from(width * height) * 8);
            let mut targets = images.refs();
            let (pool, cmd) = engine.command_buffer();
            unsafe {
                d.begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default())
                    .unwrap();
                renderer.record_gbuffer(cmd, &mut targets).unwrap();
                let frame = TiledFrame {
                    slot: 0,
                    view: &view,
                    lights: &scene.lights,
                    clear_hdr: true,
                    side: TileSide::Sixteen,
                    mixed: MixedTiles::PerBrdf,
                    classify: TileClassify::for_context(&ctx),
                    hook_sets: HookSets::default(),
                };
                lighting.record_tiled(cmd, &frame, &mut targets).unwrap();
                copy_to_buffer(d, cmd, &mut targets.hdr, readback.buffer);
                engine.submit_and_wait(pool, cmd);
                lighting.slot_finished(0).unwrap();
            }
            assert!(lighting.tiled_pipeline_count() > 0);
            // Its frame was waited for and declared finished.
            lighting.destroy().unwrap();
            images.free(&engine);
            engine.free_buffer(readback);
        }
        drop(renderer);
        assert!(ctx.validation_log().is_empty(), "messages go to the engine");
    }
    // The cache is still the engine's, and holds a valid header (VkPipelineCacheHeaderVersionOne:
    // its own length, 32, then version 1).
    let data = unsafe { d.get_pipeline_cache_data(cache) }.unwrap();
    assert!(data.len() >= 32, "{} bytes", data.len());
    assert_eq!(u32::from_le_bytes(data[0..4].try_into().unwrap()), 32);
    assert_eq!(u32::from_le_bytes(data[4..8].try_into().unwrap()), 1);
    unsafe { d.destroy_pipeline_cache(cache, None) };
    engine.destroy().assert_clean();
}
