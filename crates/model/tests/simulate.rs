//! Property tests of the plans, run on the CPU simulator against an independent oracle: a pixel
//! is lit by a light exactly when its surface lies strictly between the volume's faces
//! ([`Span::contains`]). Layouts put the culling bit and the BRDF field anywhere in the byte;
//! the same frames mirrored into reversed depth must give the same result bit for bit.

mod common;

use common::{backend, frame, Backend, Frame};
use histencil_model::{
    insert_flushes, write_test_dependencies, DepthConvention, FlushPolicy, FramePlan, SimResult,
    Step, NOT_SHADED,
};
use proptest::prelude::*;

/// Every pixel inside a light is shaded exactly once, with its own BRDF; no other pixel is.
fn assert_shaded_exactly_inside(frame: &Frame, result: &SimResult) -> Result<(), TestCaseError> {
    for (l, light) in frame.lights.iter().enumerate() {
        let fp = &light.footprint;
        let shading = &result.lights[l];
        for y in fp.y0..fp.y0 + fp.height {
            for x in fp.x0..fp.x0 + fp.width {
                let i = frame.target.index(x, y);
                let local = ((y - fp.y0) * fp.width + (x - fp.x0)) as usize;
                let inside = fp.shades(x, y, frame.target.depth[i]);
                prop_assert_eq!(
                    shading.count[local],
                    u8::from(inside),
                    "light {} pixel ({}, {}) case {:?}",
                    l,
                    x,
                    y,
                    fp.case()
                );
                let expected_brdf = if inside {
                    frame.slot(i) as u8
                } else {
                    NOT_SHADED
                };
                prop_assert_eq!(shading.brdf[local], expected_brdf);
            }
        }
    }
    prop_assert!(
        result.culling_bit_left.iter().all(|left| !left),
        "culling bit left set"
    );
    Ok(())
}

/// Pixels where some light with passes covers the screen: where the 360-like scheme writes.
fn touched_by_lights(frame: &Frame) -> Vec<bool> {
    let mut touched = vec![false; frame.target.stencil.len()];
    for (l, light) in frame.lights.iter().enumerate() {
        if frame.affected(l).is_empty() {
            continue;
        }
        let fp = &light.footprint;
        for y in fp.y0..fp.y0 + fp.height {
            for x in fp.x0..fp.x0 + fp.width {
                if fp.span(x, y).is_some() {
                    touched[frame.target.index(x, y)] = true;
                }
            }
        }
    }
    touched
}

fn strip_hi_stencil(plan: &FramePlan) -> FramePlan {
    let mut plan = plan.clone();
    plan.steps.retain(|s| !matches!(s, Step::FlushHiStencil));
    for step in &mut plan.steps {
        if let Step::Pass { pass, .. } = step {
            pass.state.hi_stencil = None;
        }
    }
    plan
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]

    #[test]
    fn correct_flushes_light_exactly_the_pixels_inside(
        frame in frame(),
        backend in backend(),
        tile_size in 1u32..=16,
        always in any::<bool>(),
    ) {
        let policy = if always { FlushPolicy::Always } else { FlushPolicy::Auto };
        let plan = frame.plan(&backend, policy);
        let (result, stencil) = frame.simulate(&plan, tile_size);
        assert_shaded_exactly_inside(&frame, &result)?;

        // Hi-stencil with correct flushes is pure culling: the result equals the per-pixel one.
        let (fine, fine_stencil) = frame.simulate(&strip_hi_stencil(&plan), tile_size);
        for (coarse, fine) in result.lights.iter().zip(&fine.lights) {
            prop_assert!(coarse.count == fine.count && coarse.brdf == fine.brdf, "hi-stencil changed the result");
        }
        prop_assert!(stencil == fine_stencil, "hi-stencil changed the stencil");

        // What lighting may zero where a light volume is drawn: nothing (PS3-like, native),
        // the free bits (360-like saving and restoring the engine's), every preserved bit.
        let preserved = frame.layout.preserved_mask();
        let zeroed = match backend {
            Backend::Native | Backend::Ps3 => 0,
            Backend::X360 { save_restore: true, .. } => preserved & !frame.layout.engine_mask(),
            Backend::X360 { save_restore: false, .. } => preserved,
        };
        let touched = touched_by_lights(&frame);
        for (i, (&after, &before)) in stencil.iter().zip(&frame.target.stencil).enumerate() {
            let expected = if touched[i] { before & !zeroed } else { before };
            prop_assert_eq!(after, expected, "pixel {} layout {:?}", i, frame.layout);
        }
    }

    #[test]
    fn reversed_depth_lights_the_same_pixels_bit_for_bit(
        frame in frame(),
        backend in backend(),
        tile_size in 1u32..=16,
    ) {
        let standard = frame.in_convention(DepthConvention::Standard);
        let reversed = frame.in_convention(DepthConvention::Reversed);
        let plan = reversed.plan(&backend, FlushPolicy::Auto);
        let (result, stencil) = reversed.simulate(&plan, tile_size);
        assert_shaded_exactly_inside(&reversed, &result)?;
        let (expected, expected_stencil) =
            standard.simulate(&standard.plan(&backend, FlushPolicy::Auto), tile_size);
        prop_assert!(result == expected, "reversed depth shaded other pixels");
        prop_assert!(stencil == expected_stencil, "reversed depth left another stencil");
    }

    #[test]
    fn auto_inserts_one_flush_per_write_test_dependency(
        frame in frame(),
        backend in backend(),
    ) {
        let unflushed = frame.plan(&backend, FlushPolicy::Never);
        prop_assert_eq!(unflushed.flushes(), 0);
        let auto = frame.plan(&backend, FlushPolicy::Auto);
        let always = frame.plan(&backend, FlushPolicy::Always);
        let dependencies = write_test_dependencies(&unflushed.steps);
        prop_assert_eq!(auto.flushes(), dependencies);
        prop_assert!(always.flushes() >= auto.flushes());
        prop_assert_eq!(
            insert_flushes(unflushed.steps.clone(), FlushPolicy::Auto),
            auto.steps
        );
    }
}
