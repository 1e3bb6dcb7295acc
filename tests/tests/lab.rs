//! The lab's runs end to end on lavapipe under the validation layer: `compare` at 64x64 with 2
//! frames writes a report whose every JSON number is finite, whose markdown has the talk's
//! columns, and whose plots are PNGs; sweeps write CSV, JSON and a Pareto PNG, and their error
//! falls as the setting grows; calibration gives finite costs that `--costs` reads back into
//! the adaptive technique.

use histencil_lab::compare::talk_verdicts;
use histencil_lab::stats::Sampling;
use histencil_lab::steady::ClockSettings;
use histencil_lab::{
    calibrate, light_size_scene, read_costs, run_compare, run_sweep, CompareSettings, SweepParam,
};
use histencil_tests::{assert_close, lit_fraction, output_dir, with_validated_context};
use histencil_vk::{
    Backend, MixedTiles, Readback, Renderer, RendererDesc, Shading, Technique, TileSide,
};
use serde_json::Value;
use std::path::Path;
use std::sync::{Mutex, MutexGuard};

/// Every test here times the device, and two of them make load on purpose (busy threads beside
/// the rounds, from a chosen round on): one test's rounds beside another's rendering or busy
/// threads move its clock, which can throw a canary off its reference or turn a verdict
/// undecided. CI once failed in both of the tests that load on purpose, run two at a time, where
/// each passes alone. So the tests hold this lock and run one at a
/// time under any runner; on two cores that costs nothing (113 s alone against 117 s two at a
/// time, measured on lavapipe), since each test keeps the cores busy by itself.
fn one_at_a_time() -> MutexGuard<'static, ()> {
    static TIMING: Mutex<()> = Mutex::new(());
    // A test that failed holding the lock poisons it; the next test still runs alone.
    TIMING.lock().unwrap_or_else(|e| e.into_inner())
}

/// Every number under `value` is finite; returns how many there are. Nulls are refused too.
fn count_finite_numbers(value: &Value, at: &str) -> usize {
    match value {
        Value::Number(n) => {
            let x = n.as_f64().unwrap_or(f64::NAN);
            assert!(x.is_finite(), "{at} = {x}");
            1
        }
        Value::Null => panic!("{at} is null"),
        Value::Array(items) => items
            .iter()
            .enumerate()
            .map(|(i, v)| count_finite_numbers(v, &format!("{at}[{i}]")))
            .sum(),
        Value::Object(map) => map
            .iter()
            .map(|(k, v)| count_finite_numbers(v, &format!("{at}.{k}")))
            .sum(),
        Value::String(_) | Value::Bool(_) => 0,
    }
}

fn assert_png(path: &Path) {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(
        bytes.starts_with(b"\x89PNG\r\n\x1a\n"),
        "{} is not a PNG",
        path.display()
    );
    let image = image::load_from_memory(&bytes).expect("a decodable PNG");
    assert!(image.width() > 100 && image.height() > 100);
}

fn read_json(path: &Path) -> Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).expect("valid JSON")
}

/// The light-size sweep times lit pixels: its forward reference lights about the area its lights
/// cover (400 discs of 0.1 % each, overlapping; one light reaching the whole wall, where the
/// Blinn-Phong stripes are dark away from its highlight). Lights in the wall's plane lit nothing.
/// The tiled technique lights it as forward does with both tile sides.
#[test]
fn the_light_size_wall_is_lit_and_tiled_lights_it_as_forward() {
    let _alone = one_at_a_time();
    with_validated_context(|ctx| {
        for (coverage, at_least) in [(0.001, 0.2), (0.1, 0.4), (1.0, 0.6)] {
            let scene = light_size_scene(coverage, 16.0 / 9.0);
            let mut renderer = Renderer::new(ctx, scene, 256, 144).unwrap();
            let frame = renderer.render(Shading::Forward, Readback::ALL).unwrap();
            let forward = frame.images.ldr.unwrap();
            let lit = lit_fraction(&forward);
            println!("coverage {coverage}: {lit:.3} lit");
            assert!(lit >= at_least, "coverage {coverage}: {lit:.3} lit");
            // Up to 400 lights: 13 words in each tile's light mask, most of them empty, which
            // the shade kernels skip (the embedded scenes fill two words at most).
            for side in [TileSide::Eight, TileSide::Sixteen] {
                let mixed = MixedTiles::PerBrdf;
                let tiled = Technique::Tiled { mixed, side };
                let frame = renderer.render(tiled, Readback::ALL).unwrap();
                let label = format!("wall-{coverage}-tiled-{}", side.pixels());
                assert_close(&label, &frame.images.ldr.unwrap(), &forward, 1);
            }
        }
    });
}

#[test]
fn compare_writes_a_finite_report_with_the_talks_columns_and_plots() {
    let _alone = one_at_a_time();
    let mut settings = CompareSettings::talk(64, 64, 2);
    // The lab's tests run beside each other on CI's two cores: a steady clock would retake
    // most rounds. Its own test is `the_steady_clock_sees_a_load_...`.
    settings.clock = None;
    // Fewer light sizes than the command's seven keep the test short; each is a full run.
    settings.light_sizes = vec![0.01, 0.1, 1.0];
    // The talk's own branching row, each column's BRDFs compiled in with glslc.
    settings.first_row = true;
    // A target no run reaches and no budget: sampling stops at the minimum, for the budget.
    settings.target_ci = Some(1e-9);
    settings.budget = std::time::Duration::ZERO;
    let (report, side) = with_validated_context(|ctx| {
        let side = TileSide::for_context(ctx).pixels();
        (run_compare(ctx, &settings, &mut |_| {}).unwrap(), side)
    });
    use histencil_lab::stats::Stop;
    assert_eq!(report.sampled.rounds, 2);
    assert!(matches!(report.sampled.stop, Stop::Budget | Stop::Target));
    for p in &report.sizes {
        assert_eq!(p.sampled.rounds, 2);
        assert!(p.samples.iter().all(|s| s.len() == 2));
    }
    let dir = output_dir().join("compare");
    let written = report.write(&dir).unwrap();
    assert_eq!(written.len(), 5);

    let json = read_json(&dir.join("report.json"));
    let numbers = count_finite_numbers(&json, "report");
    // 12 rows x 3 counts x (4 timing + 2 overhead + 3 error + 1) numbers at least.
    assert!(numbers > 12 * 3 * 10, "{numbers} numbers");
    let rows = json["rows"].as_array().unwrap();
    let names: Vec<&str> = rows
        .iter()
        .map(|r| r["technique"].as_str().unwrap())
        .collect();
    assert_eq!(
        names,
        [
            "branching",
            "stencil x360",
            "stencil ps3",
            "stencil native",
            "stencil amd-pretest",
            "stencil amd-andor",
            "lut",
            "adaptive",
            "tiled",
            "tiled, mixed branching",
            "tiled 8x8",
            "depth-id",
            "branching, first"
        ]
    );
    assert!(report.first_left_out.is_none());
    let md = std::fs::read_to_string(dir.join("report.md")).unwrap();
    assert!(md.contains("the talk's own branching measurement"), "{md}");
    for row in rows {
        let cells = row["cells"].as_array().unwrap();
        assert_eq!(cells.len(), 3);
        for cell in cells {
            assert!(cell["lighting"]["median_ms"].as_f64().unwrap() > 0.0);
        }
        assert_eq!(cells[0]["overhead_ms"].as_f64(), Some(0.0));
        // The emulated backends' bookkeeping is sampled apart, every round, wherever the plan
        // uses hi-stencil (with several BRDFs; one BRDF under lights that hold the camera needs
        // none); nothing else has any.
        let emulated = [
            "stencil x360",
            "stencil ps3",
            "stencil amd-pretest",
            "stencil amd-andor",
        ]
        .contains(&row["technique"].as_str().unwrap());
        for cell in cells {
            let bookkeeping = cell["bookkeeping_samples_ms"].as_array().unwrap();
            let several = cell["brdfs"].as_u64().unwrap() > 1;
            if !emulated || several {
                assert_eq!(bookkeeping.len(), if emulated { 2 } else { 0 }, "{row}");
            }
            assert!(bookkeeping.iter().all(|b| b.as_f64().unwrap() > 0.0));
        }
        // Every cell of several BRDFs against its BRDFs alone, paired by round (the talk's
        // branching row shades one BRDF only).
        let first = row["technique"] == "branching, first";
        for cell in cells.iter().filter(|_| !first) {
            let single = cell["single_brdf_samples_ms"].as_array().unwrap();
            if cell["brdfs"].as_u64().unwrap() == 1 {
                assert!(single.is_empty() && cell.get("over_single_brdf_ratio").is_none());
            } else {
                assert_eq!(single.len(), 2, "{row}");
                assert!(single.iter().all(|t| t.as_f64().unwrap() > 0.0));
                assert!(cell["over_single_brdf_ratio"]["median"].as_f64().unwrap() > 0.0);
                assert!(cell["verdict_against_single_brdf"].is_string());
            }
        }
    }
    for row in report
        .rows
        .iter()
        .filter(|r| r.name.starts_with("stencil "))
    {
        for cell in &row.cells {
            let whole = cell.with_bookkeeping();
            assert!(whole
                .iter()
                .zip(&cell.samples)
                .all(|(w, t)| w >= t && *t > 0.0));
        }
    }
    // The exact techniques stay within 1/255 of forward; the LUT within its stated tolerance.
    for (row, name) in rows.iter().zip(names) {
        let limit = if name == "lut" { 32.0 } else { 1.0 };
        for cell in row["cells"].as_array().unwrap() {
            let max = cell["error"]["max"].as_f64().unwrap();
            assert!(max <= limit, "{name}: error max {max}");
        }
    }
    let sizes = json["light_sizes"].as_array().unwrap();
    assert_eq!(sizes.len(), 3);
    for size in sizes {
        assert!(size["tiled"]["median_ms"].as_f64().unwrap() > 0.0);
        // The sweep's tiled technique takes the device's tiles (8x8 on lavapipe).
        assert_eq!(size["tiled_tile_side"].as_u64(), Some(u64::from(side)));
        assert_eq!(size["samples_ms"]["tiled"].as_array().unwrap().len(), 2);
        assert!(size["depth_id"]["median_ms"].as_f64().unwrap() > 0.0);
        assert_eq!(size["samples_ms"]["depth_id"].as_array().unwrap().len(), 2);
    }
    // The stencil rows' breakdowns: the consoles', native's and AMD's.
    assert_eq!(json["breakdown"].as_array().unwrap().len(), 5);
    assert!(json["device"].as_str().unwrap().contains("llvmpipe") || !json["device"].is_null());

    let md = std::fs::read_to_string(dir.join("report.md")).unwrap();
    for column in [
        "| technique | 1 BRDF | 2 BRDFs | 3 BRDFs |",
        "2 BRDFs branching",
        "3 BRDFs stencil",
    ] {
        assert!(md.contains(column), "report.md lacks `{column}`");
    }
    for part in [
        "setup",
        "mask",
        "render",
        "cleanup",
        "ms, +",
        "Light size",
        "tiled / best",
        "depth-id / tiled",
        "FLIP",
        "| backend | BRDFs | technique, ms | emulator bookkeeping, ms |",
        "| stencil ps3 | 3 |",
        "what its BRDFs cost alone",
    ] {
        assert!(md.contains(part), "report.md lacks `{part}`");
    }
    for plot in ["lighting.png", "light-size.png", "speed-vs-error.png"] {
        assert_png(&dir.join(plot));
    }
}

#[test]
fn sweeps_write_csv_json_and_a_pareto_plot_and_error_falls() {
    let _alone = one_at_a_time();
    let cases = [
        (SweepParam::LutRes, "default", vec![8, 32]),
        (SweepParam::LightmapRes, "alpha", vec![8, 64]),
        (SweepParam::Slices, "volume", vec![1, 8]),
        (SweepParam::TileSize, "default", vec![4, 16]),
    ];
    for (param, scene, values) in cases {
        let scene = histencil_scene::embedded(scene).unwrap();
        let report = with_validated_context(|ctx| {
            // The steady clock on the LUT sweep (its values' timings are its rounds), off on
            // the others: CI's two cores are shared with the test next door.
            let clock = (param == SweepParam::LutRes).then(ClockSettings::default);
            run_sweep(ctx, scene, param, &values, (96, 64), 1, clock, &mut |_| {}).unwrap()
        });
        // Each value's timing was a round of the clock where it ran: one kept canary each.
        match &report.stability {
            Some(s) => assert_eq!(s.sets[0].canary.len(), values.len(), "{s:?}"),
            None => assert_ne!(param, SweepParam::LutRes),
        }
        let dir = output_dir().join(format!("sweep-{}", param.name()));
        report.write(&dir).unwrap();
        let csv = std::fs::read_to_string(dir.join("sweep.csv")).unwrap();
        assert_eq!(csv.lines().count(), 1 + values.len(), "{csv}");
        let json = read_json(&dir.join("sweep.json"));
        count_finite_numbers(&json, "sweep");
        assert_png(&dir.join("pareto.png"));
        let p = &report.points;
        match param {
            // Finer tables and lightmaps, more slices: less error.
            SweepParam::LutRes | SweepParam::LightmapRes | SweepParam::Slices => {
                assert!(p[1].error.mean < p[0].error.mean, "{}: {p:?}", param.name());
            }
            // Smaller tiles: more tile tests, fewer pixels left for the per-pixel test.
            SweepParam::TileSize => {
                assert!(p[0].speed.median_ms > p[1].speed.median_ms, "{p:?}");
                assert!(p[0].error.mean < p[1].error.mean, "{p:?}");
            }
        }
    }
}

#[test]
fn calibrated_costs_are_finite_and_feed_the_adaptive_technique() {
    let _alone = one_at_a_time();
    let calibration = with_validated_context(|ctx| {
        calibrate(ctx, 96, 64, &Sampling::rounds(2), &mut |_| {}).unwrap()
    });
    let c = calibration.costs;
    for x in [
        c.pass_overhead_ms,
        c.stencil_per_brdf_ms,
        c.branch_tax_per_brdf_ms,
        c.shade_ms,
    ] {
        assert!(x.is_finite() && x >= 0.0, "{c:?}");
    }
    assert!(c.shade_ms > 0.0, "{c:?}");
    assert_eq!(calibration.sampled.rounds, 2);
    // `calibrate` keeps its rounds by the steady clock: one set, warmed up, a canary time after
    // each of the two kept rounds, and the record in the costs file.
    let stability = calibration
        .stability
        .as_ref()
        .expect("the steady clock ran");
    let set = &stability.sets[0];
    assert_eq!(set.set, "the calibration");
    assert!(
        !set.warm_ups.is_empty(),
        "the first canary sets no reference: {set:?}"
    );
    assert_eq!(set.canary.len(), 2, "{set:?}");
    assert!(calibration.json()["stability"]["sets"].is_array());
    let costs = [
        c.pass_overhead_ms,
        c.stencil_per_brdf_ms,
        c.branch_tax_per_brdf_ms,
        c.shade_ms,
    ];
    let intervals = c.interval.expect("measured costs carry intervals");
    for (x, (lo, hi)) in costs.iter().zip(intervals) {
        assert!(lo <= *x && *x <= hi, "{c:?}");
    }
    // The tiled technique's costs are measured too, with their intervals.
    let tiled = c
        .tiled
        .expect("calibrated costs carry the tiled technique's");
    let tiled_intervals = tiled.interval.expect("measured");
    for (x, (lo, hi)) in tiled.fields().iter().zip(tiled_intervals) {
        assert!(x.is_finite() && lo <= *x && *x <= hi, "{tiled:?}");
    }
    assert!(tiled.classify_ms > 0.0 && tiled.shade_ms > 0.0, "{tiled:?}");
    // And the depth-id technique's, which the adaptive technique may take instead of tiled.
    let ids = tiled.depth_id.expect("calibrated costs carry depth-id's");
    let ids_intervals = ids.interval.expect("measured");
    for (x, (lo, hi)) in ids.fields().iter().zip(ids_intervals) {
        assert!(x.is_finite() && lo <= *x && *x <= hi, "{ids:?}");
    }
    assert!(ids.shade_ms > 0.0, "{ids:?}");
    let path = output_dir().join("costs.json");
    calibration.write(&path).unwrap();
    let read = read_costs(&path).unwrap();
    assert_eq!(read, c);
    with_validated_context(|ctx| {
        let scene = histencil_scene::embedded("brdfs-3").unwrap();
        let talks = Renderer::new(ctx, scene.clone(), 32, 32).unwrap();
        assert_ne!(talks.cost_model(Backend::Native), read);
        let desc = RendererDesc {
            cost_model: Some(read),
            ..RendererDesc::new(32, 32)
        };
        let calibrated = Renderer::with_desc(ctx, scene, &desc).unwrap();
        assert_eq!(calibrated.cost_model(Backend::Native), read);
    });
}

/// Verdicts do not reverse between repeats, and a load is a finding. A small compare runs twice
/// quietly and once beside one busy thread per core (`CompareSettings::beside_load`). The two
/// quiet runs never decide a cell or a talk's verdict "faster" in one and "slower" in the other:
/// the rounds interleave every configuration, a verdict needs the paired ratio's interval beyond
/// ±5 % of a tie and both halves of the rounds on its side, so noise cannot turn one round. The
/// loaded run may: on lavapipe a load on the cores changes the techniques' ratios themselves
/// (the talk's stencil on the AMD pretest platform over branching at 3 BRDFs read 1.11 quiet and
/// 0.86 loaded in one CI run), so its differences are printed as findings. All three go through
/// `compare merge` as the lab's users run it: it judges the repeat, and lists the load's.
#[test]
fn compare_verdicts_do_not_reverse_between_repeats_and_a_load_is_a_finding() {
    let _alone = one_at_a_time();
    use histencil_lab::compare::merge::{DeviceReport, Merged};
    let mut settings = CompareSettings::talk(64, 64, 15);
    // One light size: the sweep's verdicts pair by round as the table's do (CI's time).
    settings.light_sizes = vec![1.0];
    // Pairing by round is what this test holds, without the steady clock's retakes (which
    // the busy threads would multiply).
    settings.clock = None;
    let run = |settings: &CompareSettings| {
        with_validated_context(|ctx| run_compare(ctx, settings, &mut |_| {}).unwrap())
    };
    let (quiet, again) = (run(&settings), run(&settings));
    settings.beside_load = std::thread::available_parallelism().map_or(2, |n| n.get());
    let loaded = run(&settings);
    for ((a, b), c) in quiet.rows.iter().zip(&again.rows).zip(&loaded.rows) {
        for i in 1..a.cells.len() {
            let [(ra, va), (rb, vb), (rc, vc)] = [a, b, c].map(|r| r.overhead_ratio(i));
            println!(
                "{} cell {i}: quiet {:.3} [{:.3}, {:.3}] {}, again {:.3} {}, loaded {:.3} {}",
                a.name,
                ra.median,
                ra.lo,
                ra.hi,
                va.word(),
                rb.median,
                vb.word(),
                rc.median,
                vc.word()
            );
            assert!(
                !va.reverses(vb),
                "{} cell {i}: the verdict reversed between two quiet runs",
                a.name
            );
        }
    }
    // The talk's own verdicts (each stencil row against branching, paired by round) hold too,
    // and report.json carries them: five platforms at 2 and 3 BRDFs.
    let talk = [&quiet, &again, &loaded].map(|r| talk_verdicts(&r.rows));
    assert_eq!(talk[0].len(), 10);
    for ((a, b), c) in talk[0].iter().zip(&talk[1]).zip(&talk[2]) {
        println!(
            "{} at {} BRDFs over branching: quiet {:.3} {}, again {:.3} {}, loaded {:.3} {}{}",
            a.technique,
            a.brdfs,
            a.ratio.median,
            a.words(),
            b.ratio.median,
            b.words(),
            c.ratio.median,
            c.words(),
            if a.verdict.reverses(c.verdict) {
                " (the load reversed it: a finding)"
            } else {
                ""
            }
        );
        assert!(!a.verdict.reverses(b.verdict), "{}: reversed", a.technique);
    }
    assert_eq!(quiet.json()["talk_verdicts"].as_array().unwrap().len(), 10);
    let dirs = [("quiet", &quiet), ("again", &again), ("loaded", &loaded)].map(|(name, report)| {
        let dir = output_dir().join(format!("compare-{name}"));
        std::fs::create_dir_all(&dir).unwrap();
        report.write(&dir).unwrap();
        dir
    });
    let merged = Merged::new(
        dirs.iter()
            .map(|d| DeviceReport::read(d).unwrap())
            .collect(),
    )
    .unwrap();
    print!("{}", merged.markdown());
    assert!(
        merged.same_device_reversals().is_empty(),
        "{:?}",
        merged.same_device_reversals()
    );
    // `compare pair` reads the same reports: the quiet run against its repeat, one pair, gives
    // every cell a ratio and decides none (a verdict needs 10 pairs); the loaded run is another
    // workload's conditions and is refused.
    use histencil_lab::compare::pair::Paired;
    let read = |d: &std::path::PathBuf| vec![DeviceReport::read(d).unwrap()];
    let names = || ("quiet".to_string(), "again".to_string());
    let paired = Paired::new(read(&dirs[0]), read(&dirs[1]), names(), 0.02, &[]).unwrap();
    assert_eq!(paired.cells.len(), 36, "{}", paired.markdown());
    assert!(paired.left_out.is_empty());
    assert_eq!(paired.tally(), [0, 0, 0, 36]);
    assert!(paired.cells.iter().all(|c| c.ratio.median > 0.0));
    let refused = Paired::new(read(&dirs[0]), read(&dirs[2]), names(), 0.02, &[]).unwrap_err();
    assert!(
        refused.to_string().contains("beside_load_threads"),
        "{refused}"
    );
}

/// The demo's contact sheet shows the talk's failures: each failure frame visibly differs from
/// its fix (mean over the tile above 5/255), and each fix is within 1/255 of forward. The first
/// failure once equalled its fix because the demo rendered it without engine bits to mis-test.
/// With histencil's BRDFs, and with an engine's (`demo --brdfs examples/brdfs`).
#[test]
fn the_demo_shows_each_failure_next_to_a_fix_that_matches_forward() {
    let _alone = one_at_a_time();
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/brdfs");
    let set = histencil_brdf::BrdfSet::load(&dir).unwrap();
    let engine = histencil_vk::compile_brdf_set(&set).unwrap();
    for brdfs in [histencil_vk::BrdfModules::builtin(), engine] {
        let mut scene = histencil_scene::embedded("default").unwrap();
        histencil_scene::retarget_brdfs(&mut scene, &brdfs.set);
        demo_holds(histencil_lab::DemoSettings {
            scene,
            width: 320,
            height: 180,
            frames: 1,
            brdfs,
        });
    }
}

fn demo_holds(settings: histencil_lab::DemoSettings) {
    let report =
        with_validated_context(|ctx| histencil_lab::run_demo(ctx, settings, &mut |_| {}).unwrap());
    assert_eq!(report.failures.len(), 3);
    // Each row's technique time, and the emulator's apart on the emulated backends only.
    for row in &report.rows {
        let emulated = ["PS3-like", "360-like", "AMD"]
            .iter()
            .any(|p| row.label.contains(p));
        assert_eq!(row.bookkeeping.is_some(), emulated, "{}", row.label);
        assert!(row.time.median_ms > 0.0, "{}", row.label);
    }
    assert!(report.table().contains("emulator ms"));
    for pair in &report.failures {
        let ((failure_caption, failure), (fix_caption, fix)) = (&pair.failure, &pair.fix);
        let shown = histencil_lab::image_error(failure, fix);
        assert!(
            shown.mean > 5.0,
            "`{failure_caption}` differs from `{fix_caption}` by a mean of only {:.2}/255",
            shown.mean
        );
        let fixed = histencil_lab::image_error(fix, &report.forward);
        assert!(
            fixed.max <= 1.0,
            "`{fix_caption}` is {}/255 from forward",
            fixed.max
        );
    }
}

/// By default `compare` samples until the talk's cells are decided, within a budget a 10-round
/// pilot predicts: the run says what the pilot predicted, stops when the cells are decided or
/// the predicted budget is spent, never before the pilot, and the report carries both.
#[test]
fn compare_samples_until_the_talks_cells_are_decided_within_a_predicted_budget() {
    let _alone = one_at_a_time();
    let mut settings = CompareSettings::talk(48, 27, 2);
    settings.light_sizes = vec![1.0];
    settings.clock = None;
    settings.until_decided = true;
    settings.predict_budget = true;
    // The cap: a run that cannot decide stops here at the latest (short: the talk's verdicts
    // are 18 cells, and a pilot on lavapipe predicts more than a test should spend; the pilot
    // itself takes about 6 s alone, twice that beside another test).
    settings.budget = std::time::Duration::from_secs(14);
    let report = with_validated_context(|ctx| run_compare(ctx, &settings, &mut |_| {}).unwrap());
    use histencil_lab::stats::{Stop, MIN_VERDICT_ROUNDS};
    let t = report.sampled;
    let p = t.prediction.expect("a pilot's prediction");
    assert_eq!(p.pilot_rounds, MIN_VERDICT_ROUNDS);
    assert!(t.rounds >= MIN_VERDICT_ROUNDS, "{t:?}");
    assert!(p.budget_seconds <= 14.0, "{p:?}");
    match t.stop {
        Stop::Decided => assert_eq!(t.open, 0, "{t:?}"),
        Stop::Budget | Stop::MaxRounds => assert!(t.open > 0, "{t:?}"),
        other => panic!("stopped by {other:?}"),
    }
    let dir = output_dir().join("compare-decided");
    report.write(&dir).unwrap();
    let md = std::fs::read_to_string(dir.join("report.md")).unwrap();
    assert!(md.contains("Budget: a pilot of 10 rounds"), "{md}");
    let json = read_json(&dir.join("report.json"));
    assert_eq!(json["table_sampling"]["prediction"]["pilot_rounds"], 10);
    assert_eq!(json["table_sampling"]["undecided"], t.open);
}

/// The steady clock sees conditions change part way: busy threads, two per core, start as the
/// table's fourth round begins. From that round on (that one, or the next where the threads
/// took the cores only after its canary: one CI run saw it so) a canary strays beyond the
/// tolerance, the round is thrown away and retaken, and after the stated strays in a row the
/// canary is warmed up again on a reference the load slowed; the report carries the record. (On llvmpipe the "clock" is
/// the CPU's share, which the busy threads take; on a GPU it is the GPU's clock.)
#[test]
fn the_steady_clock_sees_a_load_that_starts_part_way_and_retakes_the_round() {
    let _alone = one_at_a_time();
    let mut settings = CompareSettings::talk(160, 90, 6);
    settings.brdf_counts = vec![1];
    settings.light_sizes = Vec::new();
    settings.beside_load = 2 * std::thread::available_parallelism().map_or(2, |n| n.get());
    settings.load_from_round = Some(3);
    // Under the load the canary hardly settles: short warm-ups keep the test short.
    let clock = ClockSettings {
        max_warm_up: std::time::Duration::from_secs(2),
        ..ClockSettings::default()
    };
    settings.clock = Some(clock);
    let tolerance = clock.tolerance;
    let report = with_validated_context(|ctx| run_compare(ctx, &settings, &mut |_| {}).unwrap());
    let stability = report
        .stability
        .as_ref()
        .expect("a steady clock by default");
    print!("{}", stability.markdown());
    let table = &stability.sets[0];
    assert_eq!(table.set, "the table");
    assert_eq!(
        report.sampled.rounds, 6,
        "retaken rounds are not extra rounds"
    );
    let first = table
        .retaken
        .iter()
        .find(|r| r.round >= 3)
        .expect("a round from the one the load began in was retaken");
    assert!(
        first.canary_ms > first.reference_ms * (1.0 + tolerance),
        "{first:?}"
    );
    let again = table
        .warm_ups
        .iter()
        .find(|w| w.before_round >= 3)
        .expect("the canary warmed up again once the load began");
    assert!(
        again.reference_ms > first.reference_ms * (1.0 + tolerance),
        "the new reference {} ms is the loaded clock's, against {} ms",
        again.reference_ms,
        first.reference_ms
    );
    let json = report.json();
    assert_eq!(json["settings"]["beside_load_from_round"], 3);
    let sets = json["stability"]["sets"].as_array().unwrap();
    assert!(sets[0]["retaken"].as_array().unwrap().len() >= 3);
    count_finite_numbers(&json["stability"], "stability");
}
