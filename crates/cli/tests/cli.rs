//! Bad command-line input gives a one-line error and a non-zero exit, never a panic.

use std::process::Command;

fn histencil(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_histencil"))
        .args(args)
        .output()
        .expect("run histencil");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn assert_one_line_error(args: &[&str], needle: &str) {
    let (ok, _, stderr) = histencil(args);
    assert!(!ok, "{args:?} succeeded");
    assert!(!stderr.contains("panicked"), "{args:?} panicked: {stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "{args:?}: {stderr}");
    assert!(
        stderr.contains(needle),
        "{args:?}: expected `{needle}` in {stderr}"
    );
}

#[test]
fn bad_arguments_are_one_line_errors() {
    let out = std::env::temp_dir().join("histencil-cli-test.png");
    let out = out.to_str().unwrap();
    assert_one_line_error(
        &["render", "--scene", "kitchen", "--out", out],
        "unknown scene `kitchen`",
    );
    assert_one_line_error(
        &["render", "--width", "0", "--height", "8", "--out", out],
        "bad resolution 0x8",
    );
    assert_one_line_error(
        &["render", "--width", "99999", "--height", "8", "--out", out],
        "bad resolution 99999x8",
    );
    assert_one_line_error(
        &["render", "--out", "/proc/histencil/x.png"],
        "/proc/histencil",
    );
    assert_one_line_error(
        &["render", "--technique", "magic", "--out", out],
        "invalid value 'magic'",
    );
    assert_one_line_error(&["brdf-report", "--lut-res", "1"], "LUT resolution 1");
    assert_one_line_error(
        &["render", "--preserved-pattern", "0x1FF", "--out", out],
        "not a byte",
    );
    assert_one_line_error(
        &["render", "--backend", "wii", "--out", out],
        "invalid value 'wii'",
    );
    assert_one_line_error(&["brdf-report", "--directions", "0"], "--directions");
    assert_one_line_error(
        &["render", "--technique", "forward", "--stats", "--out", out],
        "--stats needs a deferred technique",
    );
}

#[test]
fn brdf_report_prints_both_tables() {
    let (ok, stdout, stderr) =
        histencil(&["brdf-report", "--lut-res", "4,8", "--directions", "64"]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("| material | peak | res 4: max / mean | res 8: max / mean |"));
    assert!(stdout.contains("| penner_skin (0.9, 1.5) |"));
    assert!(stdout.contains("f32 normal, f16 params (histencil)"));
    assert!(stdout.contains("| worst normal error (degrees) |"));
}

#[test]
fn renders_and_dumps_stencil_under_validation() {
    let dir = std::env::temp_dir().join("histencil-cli-render");
    let png = dir.join("frame.png");
    let stencil = dir.join("stencil.png");
    let exr = dir.join("frame.exr");
    let (ok, stdout, stderr) = histencil(&[
        "render",
        "--validate",
        "--width",
        "64",
        "--height",
        "48",
        "--frames",
        "1",
        "--out",
        png.to_str().unwrap(),
        "--hdr",
        exr.to_str().unwrap(),
        "--dump-stencil",
        stencil.to_str().unwrap(),
        "--scene",
        "brdfs-6",
        "--technique",
        "stencil",
        "--backend",
        "ps3",
        "--preserved-pattern",
        "0xA0",
        "--timings",
        "--stats",
    ]);
    assert!(ok, "{stdout}\n{stderr}");
    assert!(stdout.contains("frame time"), "{stdout}");
    assert!(stdout.contains("simulator agrees"), "{stdout}");
    assert!(stdout.contains("lighting by pass group"), "{stdout}");
    assert!(stdout.contains("shade-kajiya_kay"), "{stdout}");
    let stencil = image::open(&stencil).unwrap().into_luma8();
    assert_eq!(stencil.dimensions(), (64, 48));
    assert!(
        stencil.pixels().all(|p| p.0[0] & 1 == 0),
        "culling bit left set"
    );
    assert!(
        stencil.pixels().any(|p| p.0[0] & 0x0E != 0),
        "no BRDF bits written"
    );
    // Six BRDFs take bits 1-3; the PS3-like backend keeps the engine's 0xA0 wherever the
    // G-buffer drew.
    assert!(
        stencil
            .pixels()
            .all(|p| p.0[0] & 0xF0 == 0xA0 || p.0[0] == 0),
        "preserved pattern changed"
    );
    let hdr = image::open(&exr).unwrap().into_rgba32f();
    assert!(hdr.pixels().all(|p| p.0.iter().all(|c| c.is_finite())));
}

#[test]
fn scenes_lists_every_embedded_scene() {
    let (ok, stdout, _) = histencil(&["scenes"]);
    assert!(ok);
    let lines: Vec<_> = stdout.lines().collect();
    assert_eq!(lines.len(), histencil_scene::EMBEDDED.len());
    for line in lines {
        assert_eq!(line.split('\t').count(), 5, "{line}");
    }
}

#[test]
fn brdf_eval_agrees_between_cpu_and_gpu_and_reports_bad_rows() {
    let dir = std::env::temp_dir().join(format!("histencil-brdf-eval-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cases = dir.join("cases.csv");
    std::fs::write(
        &cases,
        "id,brdf,params,N,T,V,L\n\
         a,ggx,\"{\"\"alpha\"\": 0.2}\",0;0;1,,0.2;0.1;1,-0.3;0;1\n\
         b,penner_skin,\"{\"\"rho\"\": 0.9, \"\"radius_mm\"\": 3}\",0;0;1,,,1;0;0.05\n\
         c,lambert,\"{\"\"albedo\"\": 1}\",0;0;1,,,0;0;1\n",
    )
    .unwrap();
    let mut outputs = vec![];
    for device in ["cpu", "gpu"] {
        let out = dir.join(format!("{device}.csv"));
        let args = [
            "brdf-eval",
            "--cases",
            cases.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--device",
            device,
            "--validate",
        ];
        let (ok, _, stderr) = histencil(&args);
        assert!(!ok, "a bad row makes the run fail");
        assert!(
            stderr.contains("row 3 (id `c`): lambert: unknown parameter `albedo`"),
            "{stderr}"
        );
        assert!(!stderr.contains("panicked"), "{stderr}");
        outputs.push(std::fs::read_to_string(out).unwrap());
    }
    let values = |text: &str| -> Vec<f64> {
        text.lines()
            .skip(1)
            .flat_map(|l| {
                l.split(',')
                    .nth(1)
                    .unwrap()
                    .split(';')
                    .map(|v| v.parse().unwrap())
                    .collect::<Vec<f64>>()
            })
            .collect()
    };
    let (cpu, gpu) = (values(&outputs[0]), values(&outputs[1]));
    assert_eq!(cpu.len(), 4, "one GGX value and three skin channels");
    for (c, g) in cpu.iter().zip(&gpu) {
        assert!((c - g).abs() <= 1e-3 * c.abs(), "cpu {c} vs gpu {g}");
    }
    std::fs::remove_dir_all(dir).unwrap();
}
