//! The engine-facing parts never touch the engine's queue: an engine may submit from any thread
//! while histencil's lighting, lightmaps and LUT tables are made, and frees them without a
//! device-wide wait. The lent context gets a null queue, so any submission or queue wait
//! inside them would be an invalid-handle error for the validation layer (or a crash).

use ash::vk;
use histencil_brdf::lut::report_materials;
use histencil_brdf::BrdfId;
use histencil_model::StencilLayout;
use histencil_tests::engine::Engine;
use histencil_vk::{
    AlphaLightmaps, AlphaLightmapsDesc, BorrowedDevice, Context, DeferredLighting, LightHooks,
    LightingDesc, LutTables,
};

#[test]
fn making_and_freeing_the_engine_facing_parts_uses_no_queue() {
    let engine = Engine::start();
    {
        let lent = BorrowedDevice {
            queue: vk::Queue::null(),
            ..engine.lend(engine.queue_family)
        };
        // SAFETY: the engine's handles are valid; the null queue is the probe: nothing below
        // may use it.
        let ctx = unsafe { Context::from_raw(lent) }.expect("context");
        let held = ctx.memory_in_use();
        let brdfs = vec![BrdfId::Lambert, BrdfId::Ggx];
        let mut lighting = DeferredLighting::new(
            &ctx,
            &LightingDesc {
                layout: StencilLayout::new(brdfs.len() as u32, 0).unwrap(),
                brdfs,
                extent: vk::Extent2D {
                    width: 64,
                    height: 32,
                },
                depth_stencil_format: ctx.depth_stencil_format().vk(),
                hdr_format: vk::Format::R16G16B16A16_SFLOAT,
                frames_in_flight: 2,
                max_lights: 8,
                hi_stencil: true,
                hooks: LightHooks::Builtin,
            },
        )
        .expect("lighting");
        let lightmaps = AlphaLightmaps::new(
            &ctx,
            &AlphaLightmapsDesc {
                atlas_format: vk::Format::R16G16B16A16_SFLOAT,
                frames_in_flight: 2,
                direction_format: Some(vk::Format::R16G16B16A16_SFLOAT),
            },
        )
        .expect("lightmaps");
        let tables = LutTables::new(&ctx, &report_materials(), 4).expect("tables");
        // SAFETY: the tables outlive every frame of the lighting (none is recorded).
        unsafe { lighting.set_lut_tables(&tables) };
        assert!(ctx.memory_in_use() > held);
        // Nothing recorded: dropping waits for nothing. The tables (which any lighting may have
        // bound) are freed through `destroy`.
        drop(lighting);
        drop(lightmaps);
        // SAFETY: no command buffer was recorded with them.
        unsafe { tables.destroy() };
        assert_eq!(ctx.memory_in_use(), held, "everything freed");
        assert!(ctx.validation_log().is_empty(), "messages go to the engine");
    }
    engine.destroy().assert_clean();
}
