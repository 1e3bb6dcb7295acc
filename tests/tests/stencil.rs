//! The stencil after lighting, read back pixel by pixel: the culling bit is 0 everywhere, the BRDF
//! bits hold exactly what the G-buffer pass wrote for the surface there, and the engine's
//! preserved pattern survives on the PS3-like and native backends. The 360-like backend zeroes
//! preserved bits where lights draw (the talk's price for its missing read mask) and never
//! changes them otherwise; with save / restore they survive there too.

use histencil_model::StencilBits;
use histencil_tests::with_validated_context;
use histencil_vk::{Backend, FlushPolicy, FrameDesc, Readback, Renderer, RendererDesc, Technique};

const SIZE: u32 = 128;
const PATTERN: u8 = 0xA0;

#[test]
fn culling_bit_clear_brdf_bits_intact_and_preserved_bits_as_the_backend_says() {
    let flush = FlushPolicy::Auto;
    let techniques = [
        ("deferred", Technique::DEFERRED),
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
            "branching-ps3",
            Technique::Branching {
                backend: Backend::Ps3,
                flush,
            },
        ),
        (
            "stencil-x360",
            Technique::Stencil {
                backend: Backend::X360 {
                    zero_preserved: true,
                    save_restore: false,
                },
                flush,
            },
        ),
        (
            "stencil-x360-save-restore",
            Technique::Stencil {
                backend: Backend::X360 {
                    zero_preserved: true,
                    save_restore: true,
                },
                flush,
            },
        ),
    ];
    for name in ["default", "brdfs-1", "brdfs-3", "brdfs-6", "near-far"] {
        let scene = histencil_scene::embedded(name).unwrap();
        with_validated_context(|ctx| {
            let mut renderer = Renderer::new(ctx, scene.clone(), SIZE, SIZE).expect("renderer");
            let layout = *renderer.stencil_layout();
            let brdfs = renderer.brdfs().to_vec();
            let preserved = layout.preserved_mask();
            for (label, technique) in techniques {
                let desc = FrameDesc {
                    preserved_pattern: PATTERN,
                    ..FrameDesc::new(technique, Readback::ALL)
                };
                let frame = renderer.render_frame(&desc).expect("frame");
                let stencil = frame.images.stencil.unwrap();
                let ids = frame.images.brdf_ids.unwrap();
                let mut seen_slots = std::collections::BTreeSet::new();
                let mut zeroed = 0;
                for (i, (value, id)) in stencil.as_raw().iter().zip(&ids).enumerate() {
                    let at = (i as u32 % SIZE, i as u32 / SIZE);
                    assert_eq!(
                        value & layout.culling_mask(),
                        0,
                        "{name} {label}: culling bit at {at:?}"
                    );
                    let (brdf, pattern) = match id {
                        Some(brdf) => {
                            let slot = brdfs.iter().position(|b| b == brdf).unwrap() as u32;
                            seen_slots.insert(slot);
                            (layout.brdf_reference(slot), PATTERN & preserved)
                        }
                        None => (0, 0),
                    };
                    assert_eq!(
                        value & layout.brdf_mask(),
                        brdf,
                        "{name} {label}: BRDF bits at {at:?}"
                    );
                    let kept = value & preserved;
                    if label == "stencil-x360" {
                        assert!(
                            kept == pattern || kept == 0,
                            "{name} {label}: preserved bits at {at:?}: {value:#04x}"
                        );
                        zeroed += usize::from(kept != pattern);
                    } else {
                        assert_eq!(kept, pattern, "{name} {label}: preserved bits at {at:?}");
                    }
                }
                assert_eq!(seen_slots.len(), brdfs.len(), "{name}: every BRDF visible");
                if label == "stencil-x360" {
                    assert!(zeroed > 0, "{name}: the 360-like backend zeroed nothing");
                }
            }
        });
    }
}

/// An engine's own bit positions: culling bit 6, the BRDF field from bit 3, the engine's data in
/// bits 0-2 and 7. Every backend lights the same image, bit for bit, as with the talk's layout,
/// keeps the engine's bits (360-like: with save / restore), and leaves the culling bit clear.
#[test]
fn engine_bit_positions_light_the_same_image_and_keep_the_engines_bits() {
    const ENGINE: u8 = 0x87;
    let bits = StencilBits {
        culling_bit: 6,
        brdf_shift: 3,
        engine_mask: ENGINE,
    };
    let flush = FlushPolicy::Auto;
    let techniques = [
        Technique::Stencil {
            backend: Backend::Native,
            flush,
        },
        Technique::Stencil {
            backend: Backend::Ps3,
            flush,
        },
        Technique::Branching {
            backend: Backend::Ps3,
            flush,
        },
        Technique::Stencil {
            backend: Backend::X360 {
                zero_preserved: true,
                save_restore: true,
            },
            flush,
        },
    ];
    for name in ["default", "brdfs-6", "near-far"] {
        let scene = histencil_scene::embedded(name).unwrap();
        with_validated_context(|ctx| {
            let mut talks = Renderer::new(ctx, scene.clone(), SIZE, SIZE).expect("renderer");
            let desc = RendererDesc {
                stencil_bits: Some(bits),
                ..RendererDesc::new(SIZE, SIZE)
            };
            let mut engine = Renderer::with_desc(ctx, scene.clone(), &desc)
                .expect("renderer at the engine's bits");
            let layout = *engine.stencil_layout();
            assert_eq!(
                (layout.culling_mask(), layout.engine_mask()),
                (0x40, ENGINE)
            );
            for technique in techniques {
                let expected = talks.render(technique, Readback::ALL).expect("frame");
                let desc = FrameDesc {
                    preserved_pattern: ENGINE,
                    ..FrameDesc::new(technique, Readback::ALL)
                };
                let frame = engine.render_frame(&desc).expect("frame");
                assert!(
                    frame.images.ldr == expected.images.ldr,
                    "{name} {technique:?}: another image at the engine's bit positions"
                );
                let stencil = frame.images.stencil.unwrap();
                let ids = frame.images.brdf_ids.unwrap();
                for (i, (value, id)) in stencil.as_raw().iter().zip(&ids).enumerate() {
                    let at = (i as u32 % SIZE, i as u32 / SIZE);
                    assert_eq!(
                        value & 0x40,
                        0,
                        "{name} {technique:?}: culling bit at {at:?}"
                    );
                    let engine_bits = if id.is_some() { ENGINE } else { 0 };
                    assert_eq!(
                        value & ENGINE,
                        engine_bits,
                        "{name} {technique:?}: engine bits at {at:?}: {value:#04x}"
                    );
                }
            }
        });
    }
}
