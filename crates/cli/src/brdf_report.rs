//! `histencil brdf-report`: what the approximations cost in accuracy. Two markdown tables:
//! the LUT error of each report material against table resolution, and the error the G-buffer
//! encodings add, both over fixed direction sets against the f64 reference.

use histencil_brdf::encoding::{encoding_directions, EncodingError, NormalEncoding, ParamEncoding};
use histencil_brdf::lut::{report_directions, report_materials, Lut, LutAccuracy, LutError};
use histencil_brdf::Brdf;
use std::fmt::Write as _;

/// A material as the report names it: the model and its parameters.
fn label(brdf: &Brdf) -> String {
    let params = brdf
        .packed_params()
        .iter()
        .take_while(|p| **p != 0.0)
        .map(|p| format!("{p}"))
        .collect::<Vec<_>>()
        .join(", ");
    format!("{} ({params})", brdf.name())
}

/// The LUT table: per material, `max / mean` absolute error at each resolution, and the peak
/// value the errors are read against.
pub fn lut_table(resolutions: &[u32], directions: usize) -> Result<String, LutError> {
    let dirs = report_directions(directions);
    let mut out = String::from("| material | peak |");
    for r in resolutions {
        write!(out, " res {r}: max / mean |").unwrap();
    }
    out.push_str("\n|---|---|");
    out.push_str(&"---|".repeat(resolutions.len()));
    out.push('\n');
    for brdf in report_materials() {
        let mut row = String::new();
        let mut peak = 0.0;
        for &r in resolutions {
            let accuracy = LutAccuracy::measure(&Lut::bake(brdf, r)?, &dirs);
            peak = accuracy.peak;
            write!(
                row,
                " {:.2e} / {:.2e} |",
                accuracy.max_abs, accuracy.mean_abs
            )
            .unwrap();
        }
        writeln!(out, "| {} | {peak:.3} |{row}", label(&brdf)).unwrap();
    }
    Ok(out)
}

/// The encodings compared: histencil's G-buffer first, then compact ones.
pub const ENCODINGS: [(&str, NormalEncoding, ParamEncoding); 4] = [
    (
        "f32 normal, f16 params (histencil)",
        NormalEncoding::Float32,
        ParamEncoding::Float16,
    ),
    (
        "oct 2x16 normal, unorm8 params",
        NormalEncoding::Octahedral { bits: 16 },
        ParamEncoding::Unorm8,
    ),
    (
        "oct 2x10 normal, unorm8 params",
        NormalEncoding::Octahedral { bits: 10 },
        ParamEncoding::Unorm8,
    ),
    (
        "oct 2x8 normal, unorm8 params",
        NormalEncoding::Octahedral { bits: 8 },
        ParamEncoding::Unorm8,
    ),
];

/// The encoding table: per material and encoding, the worst error as a fraction of the peak
/// value, and the mean absolute error.
pub fn encoding_table(directions: usize) -> String {
    let dirs = encoding_directions(directions);
    let mut out = String::from("| material |");
    for (name, ..) in ENCODINGS {
        write!(out, " {name}: max/peak, mean |").unwrap();
    }
    out.push_str("\n|---|");
    out.push_str(&"---|".repeat(ENCODINGS.len()));
    out.push('\n');
    let mut angles = vec![0.0; ENCODINGS.len()];
    for brdf in report_materials() {
        write!(out, "| {} |", label(&brdf)).unwrap();
        for (i, (_, normals, params)) in ENCODINGS.into_iter().enumerate() {
            let e = EncodingError::measure(brdf, normals, params, &dirs);
            angles[i] = e.max_normal_degrees;
            write!(out, " {:.2e}, {:.2e} |", e.max_relative(), e.mean_abs).unwrap();
        }
        out.push('\n');
    }
    out.push_str("| worst normal error (degrees) |");
    for a in angles {
        write!(out, " {a:.4} |").unwrap();
    }
    out.push('\n');
    out
}
