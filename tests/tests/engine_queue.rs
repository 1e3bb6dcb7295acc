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
use std::sync::Arc;

/// A small lighting of two BRDFs, with the hi-stencil emulation.
fn lighting_desc(ctx: &Context) -> LightingDesc {
    let brdfs = vec![BrdfId::Lambert, BrdfId::Ggx];
    LightingDesc {
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
    }
}

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
        let mut lighting = DeferredLighting::new(&ctx, &lighting_desc(&ctx)).expect("lighting");
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

/// What an engine writes: its renderer struct owns the context (shared) and histencil's parts
/// beside it, with no lifetime tying them; the parts keep the context alive whatever order the
/// fields drop in, and free everything they made.
struct EngineRenderer {
    ctx: Arc<Context>,
    lighting: DeferredLighting<Arc<Context>>,
    lightmaps: AlphaLightmaps<Arc<Context>>,
    tables: LutTables<Arc<Context>>,
}

impl EngineRenderer {
    fn new(ctx: Context) -> Self {
        let ctx = Arc::new(ctx);
        let mut lighting =
            DeferredLighting::new(ctx.clone(), &lighting_desc(&ctx)).expect("lighting");
        let lightmaps = AlphaLightmaps::new(
            ctx.clone(),
            &AlphaLightmapsDesc {
                atlas_format: vk::Format::R16G16B16A16_SFLOAT,
                frames_in_flight: 2,
                direction_format: None,
            },
        )
        .expect("lightmaps");
        let tables = LutTables::new(ctx.clone(), &report_materials(), 4).expect("tables");
        // SAFETY: the tables live as long as the lighting, in the same struct.
        unsafe { lighting.set_lut_tables(&tables) };
        Self {
            ctx,
            lighting,
            lightmaps,
            tables,
        }
    }
}

#[test]
fn an_engine_struct_owns_the_parts_beside_its_context() {
    let engine = Engine::start();
    {
        // SAFETY: the engine's handles outlive the context, which the struct below owns.
        let ctx = unsafe { Context::from_raw(engine.lend(engine.queue_family)) }.expect("context");
        let held = ctx.memory_in_use();
        let renderer = EngineRenderer::new(ctx);
        assert!(renderer.ctx.memory_in_use() > held);
        assert_eq!(
            Arc::strong_count(&renderer.ctx),
            4,
            "each part holds the context"
        );
        assert_eq!(renderer.lighting.desc().brdfs.len(), 2);
        assert_eq!(renderer.tables.luts().len(), report_materials().len());
        let EngineRenderer {
            ctx,
            lighting,
            lightmaps,
            tables,
        } = renderer;
        // The struct's own handle goes first: the parts still hold the context.
        let weak = Arc::downgrade(&ctx);
        drop(ctx);
        drop(lighting);
        drop(lightmaps);
        let ctx = weak.upgrade().expect("the tables still hold the context");
        drop(tables);
        // Tables dropped without their `destroy` may still be bound by a frame not yet run:
        // the context keeps them until told the GPU is done (or until it drops).
        assert_eq!(ctx.retired_count(), 1, "the tables, retired");
        // SAFETY: no frame recorded with these parts was ever submitted.
        unsafe { ctx.free_retired() };
        assert_eq!(ctx.memory_in_use(), held, "everything freed");
        assert_eq!(Arc::strong_count(&ctx), 1);
    }
    engine.destroy().assert_clean();
}

/// An engine may keep the context and histencil's parts in a struct it shares or moves between
/// threads (submitting stays the engine's, from any one thread at a time).
#[allow(dead_code)]
fn the_parts_can_move_between_threads() {
    fn sendable<T: Send>() {}
    fn shared<T: Send + Sync>() {}
    shared::<Context>();
    sendable::<EngineRenderer>();
}

/// One PS3-like stencil frame of `brdfs-3`, tonemapped: what the two tests below compare.
fn stencil_frame(renderer: &mut histencil_vk::Renderer) -> image::RgbaImage {
    use histencil_vk::{Backend, FlushPolicy, Readback, Technique};
    let stencil = Technique::Stencil {
        backend: Backend::Ps3,
        flush: FlushPolicy::Auto,
    };
    let images = renderer.render(stencil, Readback::ALL).unwrap().images;
    images.ldr.unwrap()
}

/// Two renderers sharing one owned context render from two threads at once: histencil's submits
/// and device-wide waits take the context's queue lock (`Context::submit`), as Vulkan requires a
/// queue's host access to be externally synchronised (the validation layer's thread-safety
/// check reports two submits that meet: without the lock, one run in three here). Every frame
/// of each thread is the frame one renderer makes alone.
#[test]
fn two_renderers_on_one_context_render_from_two_threads() {
    use histencil_vk::Renderer;
    let scene = histencil_scene::embedded("brdfs-3").unwrap();
    let frame = stencil_frame;
    histencil_tests::with_validated_context(|ctx| {
        let alone = frame(&mut Renderer::new(ctx, scene.clone(), 48, 32).unwrap());
        std::thread::scope(|threads| {
            for _ in 0..2 {
                threads.spawn(|| {
                    let mut renderer = Renderer::new(ctx, scene.clone(), 48, 32).unwrap();
                    for _ in 0..20 {
                        assert!(frame(&mut renderer) == alone, "a frame differs");
                    }
                });
            }
        });
    });
}

/// An engine that lends no allocator (it allocates with VMA, or its own code) gets histencil's
/// private one on its device, beside the engine's own: the engine holds images of its own
/// allocator's while histencil's lighting, LUT tables and renderer allocate through the private
/// one, the frame is the one a context lent the engine's allocator renders, bit for bit, nothing
/// of histencil's lands in the engine's allocator, and everything is freed with the context
/// (the validation layer reports any memory left when the engine destroys its device).
#[test]
fn a_lent_device_without_an_allocator_gets_a_private_one() {
    use histencil_vk::Renderer;
    let scene = histencil_scene::embedded("brdfs-3").unwrap();
    let engine = Engine::start();
    let own = engine.image(
        "engine-own-image",
        vk::Format::R8G8B8A8_UNORM,
        vk::Extent2D {
            width: 64,
            height: 64,
        },
        vk::ImageUsageFlags::SAMPLED,
    );
    let engines_bytes = || {
        engine
            .allocator
            .lock()
            .unwrap()
            .generate_report()
            .total_allocated_bytes
    };
    let held = engines_bytes();
    let frame = |lent: BorrowedDevice| {
        // SAFETY: the engine's handles outlive the context; nothing else uses its queue.
        let ctx = unsafe { Context::from_raw(lent) }.expect("context");
        let lighting = DeferredLighting::new(&ctx, &lighting_desc(&ctx)).expect("lighting");
        let tables = LutTables::new(&ctx, &report_materials(), 4).expect("tables");
        let mut renderer = Renderer::new(&ctx, scene.clone(), 48, 32).unwrap();
        let image = stencil_frame(&mut renderer);
        assert!(ctx.memory_in_use() > 0);
        drop((renderer, lighting));
        // SAFETY: no command buffer was recorded with them.
        unsafe { tables.destroy() };
        assert!(ctx.validation_log().is_empty(), "messages go to the engine");
        image
    };
    let theirs = frame(engine.lend(engine.queue_family));
    let private = frame(BorrowedDevice {
        allocator: None,
        ..engine.lend(engine.queue_family)
    });
    assert!(private == theirs, "the frames differ");
    assert_eq!(
        engines_bytes(),
        held,
        "histencil left nothing in the engine's allocator"
    );
    engine.free_image(own);
    engine.destroy().assert_clean();
}
