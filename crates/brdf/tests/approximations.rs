//! The approximations' error, held to bounds: BRDF look-up tables against resolution and the
//! G-buffer encodings (`histencil brdf-report` prints the full tables).

use histencil_brdf::encoding::{encoding_directions, EncodingError, NormalEncoding, ParamEncoding};
use histencil_brdf::lut::{report_directions, report_materials, Lut, LutAccuracy};
use histencil_brdf::Brdf;

#[test]
fn lut_error_falls_as_resolution_rises() {
    let dirs = report_directions(2048);
    for brdf in report_materials() {
        let errors: Vec<LutAccuracy> = [8, 16, 32]
            .into_iter()
            .map(|r| LutAccuracy::measure(&Lut::bake(brdf, r).unwrap(), &dirs))
            .collect();
        println!("{brdf:?}: {errors:?}");
        if matches!(brdf, Brdf::Lambert { .. }) {
            // Linear in N.L: exact at any resolution.
            assert!(errors.iter().all(|e| e.max_abs < 1e-6));
            continue;
        }
        for pair in errors.windows(2) {
            assert!(
                pair[1].mean_abs < pair[0].mean_abs * 0.8,
                "{brdf:?}: {pair:?}"
            );
        }
        // The worst case falls too, except where the grid straddles GGX's grazing mirror
        // spike (D * Vis grows like 1 / alpha^3 there): a finer grid samples closer to it.
        let sharp = matches!(brdf, Brdf::Ggx { alpha, .. } if alpha < 0.1);
        if !sharp {
            assert!(
                errors[2].max_abs < errors[0].max_abs,
                "{brdf:?}: {errors:?}"
            );
        }
        // At 32 points per axis the mean error is a few percent of the peak or better.
        assert!(
            errors[2].mean_abs < 1e-2 * errors[2].peak,
            "{brdf:?}: {:?}",
            errors[2]
        );
    }
}

#[test]
fn skin_table_covers_every_curvature() {
    // One table serves all curvatures: flat, ordinary and huge all look up within 1e-2.
    let dirs = report_directions(1024);
    for curvature_per_mm in [0.0, 0.05, 0.3, 1.5, 20.0, 1e5] {
        let lut = Lut::bake(
            Brdf::PennerSkin {
                rho: 1.0,
                curvature_per_mm,
            },
            32,
        )
        .unwrap();
        let e = LutAccuracy::measure(&lut, &dirs);
        assert!(e.max_abs < 1e-2, "curvature {curvature_per_mm}: {e:?}");
    }
}

#[test]
fn histencil_gbuffer_adds_little_and_compact_encodings_are_bounded() {
    let dirs = encoding_directions(4096);
    for brdf in report_materials() {
        let measure = |normals, params| EncodingError::measure(brdf, normals, params, &dirs);
        // The float G-buffer: f16 parameters are the only rounding.
        let ours = measure(NormalEncoding::Float32, ParamEncoding::Float16);
        assert!(ours.max_relative() < 1e-3, "{brdf:?}: {ours:?}");
        // Octahedral 2x16 normals with 8-bit parameters: within 2 % of the peak.
        let compact = measure(
            NormalEncoding::Octahedral { bits: 16 },
            ParamEncoding::Unorm8,
        );
        assert!(compact.max_relative() < 2e-2, "{brdf:?}: {compact:?}");
        assert!(compact.max_normal_degrees < 0.01);
        // 2x8 normals: the mean error stays small; the worst case can flip the N.V >= 0 gate
        // at grazing view, which is why the report lists it.
        let tiny = measure(
            NormalEncoding::Octahedral { bits: 8 },
            ParamEncoding::Unorm8,
        );
        assert!(tiny.mean_abs < 1e-2 * tiny.peak, "{brdf:?}: {tiny:?}");
        assert!(tiny.max_normal_degrees < 1.0);
    }
}
