//! The GLSL spelling of every BRDF, run in a compute shader on the device under validation,
//! against the f64 reference: ordinary cases within 1e-3 relative (or 1e-5 absolute near zero),
//! hard cases finite and within 1e-2 (relative to max(1, |reference|)).

use histencil_brdf::cases::{hard_cases, ordinary_cases, ordinary_error, relative_error, Case};
use histencil_tests::with_validated_context;
use histencil_vk::BrdfEvaluator;

/// Worst error per model: (model, error, case label).
fn worst_on_gpu(cases: &[Case], error: fn(f64, f64) -> f64) -> Vec<(&'static str, f64, String)> {
    let values = with_validated_context(|ctx| {
        let mut evaluator = BrdfEvaluator::new(ctx).expect("BRDF evaluator");
        let input: Vec<_> = cases.iter().map(|c| (c.brdf, c.dirs_f32())).collect();
        let values = evaluator.evaluate(ctx, &input).expect("dispatch");
        evaluator.destroy(ctx);
        values
    });
    let mut out: Vec<(&'static str, f64, String)> = vec![];
    for (case, gpu) in cases.iter().zip(values) {
        let reference = case.brdf.reference(case.dirs);
        let channels = if case.brdf.is_rgb() { 3 } else { 1 };
        for k in 0..channels {
            let e = error(f64::from(gpu[k]), reference[k]);
            match out.iter_mut().find(|(m, ..)| *m == case.brdf.name()) {
                Some(entry) if e > entry.1 => *entry = (entry.0, e, case.label.clone()),
                Some(_) => {}
                None => out.push((case.brdf.name(), e, case.label.clone())),
            }
        }
    }
    for (model, e, label) in &out {
        println!("gpu {model:24} worst {e:.3e}  ({label})");
    }
    out
}

#[test]
fn glsl_matches_f64_on_ordinary_cases() {
    // Printed for the report: plain relative error, before the near-zero absolute allowance.
    worst_on_gpu(&ordinary_cases(), relative_error);
    for (model, e, label) in worst_on_gpu(&ordinary_cases(), ordinary_error) {
        assert!(e <= 1e-3, "{model}: {e:e} at {label}");
    }
}

#[test]
fn glsl_is_finite_and_close_on_hard_cases() {
    for (model, e, label) in worst_on_gpu(&hard_cases(), relative_error) {
        assert!(e <= 1e-2, "{model}: {e:e} at {label}");
    }
}
