//! Coverage-guided fuzz targets for every file histencil reads: glTF and GLB scenes (JSON and
//! binary chunks, buffers, images, accessors, extensions), material extras with `Brdf::parse`,
//! the `brdf-eval` case CSV and the costs JSON; and the plain data an engine plans its frames
//! from (`engine_plan`).
//!
//! Each target takes arbitrary bytes and must return, whatever they are: an error is an answer,
//! a panic, a hang or an abort is a defect. Where the input is accepted, the target also checks
//! what the rest of histencil relies on (an imported scene validates, a parsed BRDF evaluates to
//! finite values, a written file reads back), so the fuzzer finds wrong answers as well as
//! crashes.
//!
//! `tools/fuzz TARGET SECONDS` runs one under AFL++ (cargo-afl, stable Rust); built without the
//! `afl` feature a target runs the files named on its command line, to reproduce a crash. The
//! corpus seeds (`fuzz/corpus/TARGET`) and every crash found (`fuzz/regressions/TARGET`, each
//! fixed at its root) are replayed by this crate's test in every `cargo test`.

mod engine_plan;
pub use engine_plan::engine_plan;

use histencil_brdf::{cases, eval_csv, Brdf, V3};
use histencil_model::{CostModel, COST_FIELDS};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// A fuzz target: any bytes in, a panic on a defect.
pub type Target = fn(&[u8]);

/// The targets by name: the name is their corpus folder's and, prefixed `fuzz-`, their binary's.
pub const TARGETS: [(&str, Target); 5] = [
    ("gltf", gltf),
    ("material", material),
    ("brdf_csv", brdf_csv),
    ("costs", costs),
    ("engine_plan", engine_plan),
];

/// Runs `target` under AFL++ with the `afl` feature; otherwise once on each file named on the
/// command line.
pub fn run(target: Target) {
    #[cfg(feature = "afl")]
    afl::fuzz!(|data: &[u8]| target(data));
    #[cfg(not(feature = "afl"))]
    for path in std::env::args_os().skip(1) {
        let path = PathBuf::from(path);
        match std::fs::read(&path) {
            Ok(data) => {
                target(&data);
                println!("{}: no defect", path.display());
            }
            Err(e) => eprintln!("{}: {e}", path.display()),
        }
    }
}

/// The folder that relative URIs in fuzzed glTF files resolve against. It holds the buffer and
/// the image the seeds name, so that the fuzzer reaches external files, and the paths that leave
/// the folder.
pub fn assets_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("assets")
}

/// glTF or GLB bytes through the importer. An accepted scene must validate, and what the
/// renderer derives from it on the CPU before it touches a device must hold.
pub fn gltf(data: &[u8]) {
    let Ok(scene) = histencil_scene::import_gltf(data, Some(&assets_dir()), "fuzz") else {
        return;
    };
    if let Err(e) = scene.validate() {
        panic!("an imported scene does not validate: {e}");
    }
    let brdfs = scene.brdfs_in_use();
    assert_eq!(scene.brdf_bounds(&brdfs).len(), brdfs.len());
    for light in &scene.lights {
        let _ = light.shape();
        let _ = scene.brdfs_lit_by(light);
    }
    let objects = scene.objects.iter().map(|o| o.world_bounds());
    for (lo, hi) in objects.chain([scene.extent_bounds()]) {
        assert!(lo.is_finite() && hi.is_finite(), "bounds {lo} {hi}");
    }
    let _ = histencil_model::View::new(&scene.camera.view_desc(16.0 / 9.0));
}

/// Material extras (UTF-8 JSON) through `material_from_gltf`, which takes the BRDF from them
/// with `Brdf::parse`, at a dielectric's, a metal's and an in-between's factors. An accepted
/// material holds its BRDF's ranges, has a finite non-negative tint, and evaluates to finite,
/// non-negative values on the ordinary and the hard directions, in f64 and f32.
pub fn material(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    for (metallic, roughness) in [(0.0, 1.0), (1.0, 0.0), (0.3, 0.6)] {
        let base = [0.8, 0.5, 0.2, 1.0];
        let Ok(m) = histencil_scene::material_from_gltf(Some(text), base, metallic, roughness)
        else {
            continue;
        };
        if let Err(e) = m.brdf.check() {
            panic!("a parsed BRDF is out of its ranges: {e}");
        }
        assert!(
            m.tint.is_finite() && m.tint.min_element() >= 0.0,
            "tint {}",
            m.tint
        );
        evaluate(&m.brdf);
    }
}

fn directions() -> &'static [(String, [V3<f64>; 4])] {
    static DIRECTIONS: OnceLock<Vec<(String, [V3<f64>; 4])>> = OnceLock::new();
    DIRECTIONS.get_or_init(|| {
        let mut all = cases::ordinary_directions();
        all.extend(cases::hard_directions());
        all
    })
}

fn evaluate(brdf: &Brdf) {
    for (label, dirs) in directions() {
        let reference = brdf.reference(*dirs);
        let shipping = brdf.shipping(dirs.map(|d| d.map(|x| x as f32)));
        let good = reference.iter().all(|v| v.is_finite() && *v >= 0.0)
            && shipping.iter().all(|v| v.is_finite() && *v >= 0.0);
        assert!(
            good,
            "{brdf:?} at {label}: f64 {reference:?}, f32 {shipping:?}"
        );
    }
}

/// A `brdf-eval` case file: parsed, evaluated with the f64 reference (every value finite) and
/// written, in f64 and f32; the written file reads back with the same ids in the same order.
pub fn brdf_csv(data: &[u8]) {
    let Ok((rows, _errors)) = eval_csv::parse_cases(data) else {
        return;
    };
    let values = eval_csv::evaluate_cpu(&rows);
    for (row, value) in rows.iter().zip(&values) {
        assert!(
            value.iter().all(|v| v.is_finite()),
            "row `{}`: {value:?}",
            row.id
        );
    }
    for as_f32 in [false, true] {
        let mut out = Vec::new();
        eval_csv::write_results(&mut out, &rows, &values, as_f32).expect("writes to memory");
        let mut reader = csv_reader(&out);
        let ids: Vec<String> = reader
            .records()
            .map(|r| r.expect("our own CSV reads back")[0].to_owned())
            .collect();
        let expected: Vec<&str> = rows.iter().map(|r| r.id.as_str()).collect();
        assert_eq!(ids, expected);
    }
}

fn csv_reader(bytes: &[u8]) -> csv::Reader<&[u8]> {
    csv::ReaderBuilder::new().from_reader(bytes)
}

/// A costs file: an accepted one has finite, non-negative costs inside their intervals, the
/// adaptive technique can choose with it, and it reads back equal once written.
pub fn costs(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(costs) = CostModel::from_json(text) else {
        return;
    };
    assert!(costs.fields().iter().all(|c| c.is_finite() && *c >= 0.0));
    if let Some(coverage) = costs.crossover_coverage() {
        assert!(coverage.is_finite(), "crossover {coverage}");
    }
    for coverage in [0.0, 1e-3, 0.5, 1.0] {
        for brdfs in [1, 2, 7] {
            let _ = costs.choose(coverage, brdfs);
        }
    }
    let mut json = serde_json::Map::new();
    for (name, value) in COST_FIELDS.iter().zip(costs.fields()) {
        json.insert((*name).to_owned(), value.into());
    }
    if let Some(intervals) = costs.interval {
        let pairs = COST_FIELDS
            .iter()
            .zip(intervals)
            .map(|(name, (lo, hi))| ((*name).to_owned(), vec![lo, hi].into()))
            .collect();
        json.insert("intervals".into(), serde_json::Value::Object(pairs));
    }
    let written = serde_json::Value::Object(json).to_string();
    assert_eq!(CostModel::from_json(&written), Ok(costs), "{written}");
}
