//! The large generated scene (`town`: about 250k triangles, 25 textured materials in 4 BRDFs,
//! 256 lights) renders under validation within 1/255 of forward at a small size with the
//! talk's technique on the native and PS3-like backends and with branching; the LUT technique
//! refuses its per-texel BRDF parameters with a clear error.

use histencil_scene::{embedded, TOWN_LIGHTS};
use histencil_tests::{assert_close, lit_fraction, with_validated_context};
use histencil_vk::{Backend, Error, FlushPolicy, Readback, Renderer, Shading, Technique};

const WIDTH: u32 = 128;
const HEIGHT: u32 = 72;

#[test]
fn town_matches_forward_within_one_step() {
    let scene = embedded("town").unwrap();
    assert_eq!(scene.lights.len(), TOWN_LIGHTS);
    with_validated_context(|ctx| {
        let mut renderer = Renderer::new(ctx, scene, WIDTH, HEIGHT).expect("renderer");
        let ldr = Readback {
            ldr: true,
            ..Readback::NONE
        };
        let mut frame = |technique| {
            renderer
                .render(technique, ldr)
                .expect("frame")
                .images
                .ldr
                .expect("asked for")
        };
        let forward = frame(Shading::Forward);
        assert!(lit_fraction(&forward) > 0.5, "the town is mostly lit");
        let flush = FlushPolicy::Auto;
        for (name, technique) in [
            (
                "stencil-native",
                Technique::Stencil {
                    backend: Backend::Native,
                    flush,
                },
            ),
            (
                "stencil-ps3",
                Technique::Stencil {
                    backend: Backend::Ps3,
                    flush,
                },
            ),
            (
                "branching",
                Technique::Branching {
                    backend: Backend::Native,
                    flush,
                },
            ),
        ] {
            assert_close(
                &format!("town-{name}"),
                &frame(technique.into()),
                &forward,
                1,
            );
        }
        // Its roughness maps vary the BRDF parameters per texel: the LUT technique, whose
        // tables are per material, says so instead of rendering the wrong lobes.
        let lut = Technique::Lut {
            backend: Backend::Native,
            flush,
        };
        match renderer.render(lut, ldr) {
            Err(Error::LutTexturedParameters { object, .. }) => assert!(object.starts_with("rock")),
            Err(e) => panic!("another error: {e}"),
            Ok(_) => panic!("the LUT technique rendered per-texel parameters"),
        }
    });
}
