//! After the lighting pass every pixel's culling bit is 0 and its BRDF bits hold exactly what the
//! G-buffer pass wrote for the surface there.

use histencil_model::StencilLayout;
use histencil_tests::{render, with_validated_context};
use histencil_vk::{Readback, Technique};

#[test]
fn culling_bit_clear_and_brdf_bits_intact_after_lighting() {
    for name in histencil_scene::embedded_names() {
        let scene = histencil_scene::embedded(name).unwrap();
        let brdfs = scene.brdfs_in_use();
        let layout = StencilLayout::new(brdfs.len() as u32, 0).unwrap();
        assert!(layout.has_brdf_bits(), "{name}: test needs several BRDFs");
        with_validated_context(|ctx| {
            let frame = render(ctx, &scene, Technique::Deferred, 128, Readback::ALL);
            let stencil = frame.images.stencil.unwrap();
            let ids = frame.images.brdf_ids.unwrap();
            let mut seen_slots = std::collections::BTreeSet::new();
            for (i, (value, id)) in stencil.as_raw().iter().zip(&ids).enumerate() {
                let (x, y) = (i as u32 % 128, i as u32 / 128);
                assert_eq!(
                    value & layout.culling_mask(),
                    0,
                    "{name}: culling bit left set at ({x}, {y})"
                );
                let expected = match id {
                    Some(brdf) => {
                        let slot = brdfs.iter().position(|b| b == brdf).unwrap() as u32;
                        seen_slots.insert(slot);
                        layout.brdf_reference(slot)
                    }
                    None => 0,
                };
                assert_eq!(*value, expected, "{name}: stencil at ({x}, {y}) for {id:?}");
            }
            assert_eq!(seen_slots.len(), brdfs.len(), "{name}: every BRDF visible");
        });
    }
}
