//! Two runs of the same scene give bit-identical PNG files.

use histencil_tests::{output_dir, render, with_validated_context};
use histencil_vk::{Readback, Shading, Technique};

fn png_bytes(label: &str, shading: Shading, run: u32) -> Vec<u8> {
    let scene = histencil_scene::embedded("default").unwrap();
    with_validated_context(|ctx| {
        let frame = render(ctx, &scene, shading, 192, Readback::ALL);
        let path = output_dir().join(format!("determinism-{label}-{run}.png"));
        histencil_vk::save_png(frame.images.ldr.as_ref().unwrap(), &path).unwrap();
        std::fs::read(path).unwrap()
    })
}

#[test]
fn two_runs_give_identical_pngs() {
    for (label, shading) in [
        ("deferred", Technique::DEFERRED.into()),
        ("forward", Shading::Forward),
    ] {
        let a = png_bytes(label, shading, 0);
        let b = png_bytes(label, shading, 1);
        assert!(a == b, "{label}: two runs differ");
    }
}
