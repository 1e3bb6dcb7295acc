//! Two runs of the same scene give bit-identical PNG files.

use histencil_tests::{output_dir, render, with_validated_context};
use histencil_vk::{Readback, Technique};

fn png_bytes(technique: Technique, run: u32) -> Vec<u8> {
    let scene = histencil_scene::embedded("default").unwrap();
    with_validated_context(|ctx| {
        let frame = render(ctx, &scene, technique, 192, Readback::ALL);
        let path = output_dir().join(format!("determinism-{technique:?}-{run}.png"));
        histencil_vk::save_png(frame.images.ldr.as_ref().unwrap(), &path).unwrap();
        std::fs::read(path).unwrap()
    })
}

#[test]
fn two_runs_give_identical_pngs() {
    for technique in [Technique::DEFERRED, Technique::Forward] {
        let a = png_bytes(technique, 0);
        let b = png_bytes(technique, 1);
        assert!(a == b, "{technique:?}: two runs differ");
    }
}
