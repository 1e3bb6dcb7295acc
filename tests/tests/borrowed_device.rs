//! histencil on an engine's own device: the test plays the engine (its own instance with the
//! validation layer and synchronisation validation, its own messenger, device and gpu-allocator
//! allocator, created from `histencil_vk::REQUIREMENTS`), lends them through
//! `Context::from_raw`, renders, and destroys everything itself afterwards. The frames must equal
//! an owned context's bit for bit, nothing of the engine's may be destroyed by histencil, and the
//! engine's messenger must see no message, leak reports at its `vkDestroyDevice` included.

use histencil_tests::engine::Engine;
use histencil_tests::{render, with_validated_context};
use histencil_vk::{Backend, Context, FlushPolicy, Readback, Shading, Technique};

const SIZE: u32 = 96;

#[test]
fn an_engines_device_renders_what_histencils_own_renders() {
    let scene = histencil_scene::embedded("default").unwrap();
    let techniques = [
        Shading::Forward,
        Technique::Stencil {
            backend: Backend::Ps3,
            flush: FlushPolicy::Auto,
        }
        .into(),
    ];
    let owned: Vec<_> = with_validated_context(|ctx| {
        assert!(ctx.owns_device());
        techniques
            .iter()
            .map(|&t| {
                render(ctx, &scene, t, SIZE, Readback::ALL)
                    .images
                    .ldr
                    .unwrap()
            })
            .collect()
    });

    let engine = Engine::start();
    {
        // SAFETY: the engine's handles outlive the context, its device has REQUIREMENTS'
        // features and nothing else uses its queue meanwhile.
        let ctx = unsafe { Context::from_raw(engine.lend(engine.queue_family)) }.expect("context");
        assert!(!ctx.owns_device());
        for (technique, expected) in techniques.iter().zip(&owned) {
            let frame = render(&ctx, &scene, *technique, SIZE, Readback::ALL);
            assert!(
                frame.images.ldr.as_ref() == Some(expected),
                "{technique:?}: the lent device rendered another image"
            );
        }
        assert!(ctx.validation_log().is_empty(), "messages go to the engine");
    }
    // The engine's device still works after histencil is gone.
    unsafe { engine.device.device_wait_idle() }.expect("the engine's device is alive");
    engine.destroy().assert_clean();
}

#[test]
fn a_lent_queue_family_that_does_not_exist_is_refused() {
    let engine = Engine::start();
    let err = unsafe { Context::from_raw(engine.lend(1000)) }
        .err()
        .expect("an error");
    assert!(err.to_string().contains("queue family 1000"), "{err}");
    engine.destroy().assert_clean();
}
