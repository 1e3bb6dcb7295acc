//! Bad input gives a clear error, never a panic, and leaves the context validation-clean.

use histencil_tests::with_validated_context;
use histencil_vk::{Error, Renderer};

#[test]
fn zero_and_oversized_resolutions_are_errors() {
    let scene = histencil_scene::embedded("default").unwrap();
    with_validated_context(|ctx| {
        for (w, h) in [(0, 64), (64, 0), (1 << 20, 64)] {
            match Renderer::new(ctx, scene.clone(), w, h) {
                Err(e @ Error::BadResolution { .. }) => {
                    assert!(e.to_string().contains(&format!("{w}x{h}")))
                }
                Err(e) => panic!("{w}x{h}: wrong error {e}"),
                Ok(_) => panic!("{w}x{h} accepted"),
            }
        }
    });
}

#[test]
fn nan_and_zero_size_lights_are_errors() {
    let mut scene = histencil_scene::embedded("default").unwrap();
    scene.lights[3].color.y = f32::NAN;
    with_validated_context(|ctx| {
        let err = Renderer::new(ctx, scene.clone(), 32, 32)
            .err()
            .expect("NaN light rejected");
        assert!(err.to_string().contains("light 3"), "{err}");
        scene.lights[3].color.y = 1.0;
        scene.lights[5].radius = 0.0;
        let err = Renderer::new(ctx, scene.clone(), 32, 32)
            .err()
            .expect("zero-size light rejected");
        assert!(err.to_string().contains("light 5"), "{err}");
    });
}
