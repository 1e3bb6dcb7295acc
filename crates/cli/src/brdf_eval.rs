//! `histencil brdf-eval` on the GPU: the GLSL spelling of each case in a compute shader. The case
//! file itself ([`histencil_brdf::eval_csv`]) and the f64 reference are the BRDF crate's.

use anyhow::Result;
use histencil_brdf::eval_csv::Row;
use histencil_brdf::{normalize, V3};

/// The GLSL spelling of every row, on `ctx`'s device.
pub fn evaluate_gpu(ctx: &histencil_vk::Context, rows: &[Row]) -> Result<Vec<[f64; 3]>> {
    let mut evaluator = histencil_vk::BrdfEvaluator::new(ctx)?;
    // Directions are normalised in f64 first: a finite f64 vector (1e300, 1e-320) need not be
    // one in f32, and every model depends only on the directions.
    let unit = |d: V3<f64>| normalize(d).map_or([0.0; 3], |u| u.map(|x| x as f32));
    let input: Vec<_> = rows.iter().map(|r| (r.brdf, r.dirs.map(unit))).collect();
    let values = evaluator.evaluate(ctx, &input);
    evaluator.destroy(ctx);
    // The case file's value is a white surface's.
    Ok(values?
        .into_iter()
        .map(|v| v.at_white().map(f64::from))
        .collect())
}
