//! The GLSL spelling of every BRDF, run in a compute shader on the device under validation,
//! against the f64 reference: ordinary cases within 1e-3 relative (or 1e-5 absolute near zero),
//! hard cases finite and within 1e-2 (relative to max(1, |reference|)).

use histencil_brdf::cases::{
    hard_cases, ordinary_cases, ordinary_error, relative_error, worst_per_model, Case,
};
use histencil_tests::with_validated_context;
use histencil_vk::BrdfEvaluator;

/// Every case evaluated by the GLSL spelling, under validation, in parts (tinted RGB, white).
fn on_gpu(cases: &[Case]) -> Vec<[f64; 4]> {
    let values = with_validated_context(|ctx| {
        let mut evaluator = BrdfEvaluator::new(ctx).expect("BRDF evaluator");
        let input: Vec<_> = cases.iter().map(|c| (c.brdf, c.dirs_f32())).collect();
        let values = evaluator.evaluate(ctx, &input).expect("dispatch");
        evaluator.destroy(ctx);
        values
    });
    values
        .into_iter()
        .map(|v| v.channels().map(f64::from))
        .collect()
}

#[test]
fn glsl_matches_f64_on_ordinary_cases() {
    let cases = ordinary_cases();
    let values = on_gpu(&cases);
    // Printed for the report: plain relative error, before the near-zero absolute allowance.
    worst_per_model("gpu", &cases, &values, relative_error);
    for (model, e, label) in worst_per_model("gpu", &cases, &values, ordinary_error) {
        assert!(e <= 1e-3, "{model}: {e:e} at {label}");
    }
}

#[test]
fn glsl_is_finite_and_close_on_hard_cases() {
    let cases = hard_cases();
    let values = on_gpu(&cases);
    for (model, e, label) in worst_per_model("gpu", &cases, &values, relative_error) {
        assert!(e <= 1e-2, "{model}: {e:e} at {label}");
    }
}
