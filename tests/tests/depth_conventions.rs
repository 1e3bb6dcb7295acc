//! The renderer in the depth conventions engines use: reversed Z and an infinite far plane, each
//! alone and together. The G-buffer, forward and alpha passes, the lighting plan (every depth
//! compare mirrored, full-screen passes at the far depth) and the lighting shaders all follow
//! the frame's convention, so every technique must give the standard frame's image within 1/255
//! and the same stencil, on scenes with lights around the camera and across the near and far
//! planes.

use histencil_model::DepthConvention;
use histencil_tests::{diff, with_validated_context};
use histencil_vk::{Backend, FlushPolicy, FrameDesc, Readback, Renderer, Shading, Technique};

const WIDTH: u32 = 96;
const HEIGHT: u32 = 64;

#[test]
fn reversed_z_and_infinite_far_light_what_standard_depth_lights() {
    let techniques = [
        Shading::Forward,
        Technique::Stencil {
            backend: Backend::Ps3,
            flush: FlushPolicy::Auto,
        }
        .into(),
        Technique::Stencil {
            backend: Backend::Native,
            flush: FlushPolicy::Auto,
        }
        .into(),
        Technique::Stencil {
            backend: Backend::X360 {
                zero_preserved: true,
                save_restore: true,
            },
            flush: FlushPolicy::Auto,
        }
        .into(),
        Technique::Branching {
            backend: Backend::Native,
            flush: FlushPolicy::Auto,
        }
        .into(),
    ];
    with_validated_context(|ctx| {
        for name in ["brdfs-3", "near-far", "inside", "alpha"] {
            let scene = histencil_scene::embedded(name).unwrap();
            let mut renderer = Renderer::new(ctx, scene, WIDTH, HEIGHT).unwrap();
            for technique in techniques {
                let readback = Readback {
                    ldr: true,
                    stencil: true,
                    ..Readback::NONE
                };
                let mut render = |depth, infinite_far| {
                    let desc = FrameDesc {
                        depth,
                        infinite_far,
                        preserved_pattern: 0xA0,
                        ..FrameDesc::new(technique, readback)
                    };
                    renderer.render_frame(&desc).unwrap().images
                };
                let standard = render(DepthConvention::Standard, false);
                let lit = standard.ldr.as_ref().unwrap();
                assert!(
                    histencil_tests::lit_fraction(lit) > 0.2,
                    "{name} {technique:?}: too dark to tell"
                );
                let infinite = render(DepthConvention::Standard, true);
                let reversed = render(DepthConvention::Reversed, false);
                let reversed_infinite = render(DepthConvention::Reversed, true);
                let mut pairs = vec![
                    ("reversed", &standard, &reversed),
                    ("reversed, infinite far", &infinite, &reversed_infinite),
                ];
                // Only near-far has geometry beyond the camera's far plane, which an infinite
                // far plane rightly shows.
                if name != "near-far" {
                    pairs.push(("infinite far", &standard, &infinite));
                }
                for (what, expected, frame) in &pairs {
                    let d = diff(expected.ldr.as_ref().unwrap(), frame.ldr.as_ref().unwrap());
                    let what = format!("{name} {technique:?} {what}");
                    assert!(d.max <= 1, "{what}: {d:?}");
                    if technique != Shading::Forward {
                        assert!(frame.stencil == expected.stencil, "{what}: stencil differs");
                    }
                }
            }
        }
    });
}
