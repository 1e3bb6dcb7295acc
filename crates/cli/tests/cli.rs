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

/// `brdf-eval` of `cases` on the CPU and then the GPU (validated), writing into `dir`: each
/// run's success, stderr and output file.
fn brdf_eval_on_both_devices(
    dir: &std::path::Path,
    cases: &std::path::Path,
) -> Vec<(bool, String, String)> {
    ["cpu", "gpu"]
        .into_iter()
        .map(|device| {
            let out = dir.join(format!("{device}.csv"));
            let (ok, _, stderr) = histencil(&[
                "brdf-eval",
                "--cases",
                cases.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
                "--device",
                device,
                "--validate",
            ]);
            (ok, stderr, std::fs::read_to_string(out).unwrap_or_default())
        })
        .collect()
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

/// Every image a command writes is in the format its name says: an extension it cannot write is
/// refused before rendering, naming the path, and nothing is written; JPEG is written as JPEG.
#[test]
fn images_are_written_in_the_format_their_name_says_or_refused_before_rendering() {
    let dir = std::env::temp_dir().join(format!("histencil-cli-formats-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let at = |name: &str| dir.join(name).to_str().unwrap().to_owned();
    let small = ["--width", "32", "--height", "24", "--frames", "1"];
    let refused: [(&[&str], &str); 6] = [
        (
            &["render", "--out", &at("x.exr")],
            "name it .png, .jpg, .jpeg",
        ),
        (&["render", "--out", &at("x.tiff")], "`.tiff`"),
        (&["render", "--out", &at("x")], "has no extension"),
        (&["render", "--hdr", &at("x.png")], "name it .exr"),
        (
            &["render", "--dump-stencil", &at("s.jpg")],
            "JPEG would change them",
        ),
        (
            &["demo", "--out", &at("sheet.exr")],
            "name it .png, .jpg, .jpeg",
        ),
    ];
    for (args, needle) in refused {
        assert_one_line_error(&[args, &small].concat(), needle);
    }
    assert!(!dir.exists(), "a refused run created {}", dir.display());
    let jpeg = at("frame.JPG");
    let (ok, stdout, stderr) = histencil(&[&["render", "--out", &jpeg][..], &small].concat());
    assert!(ok, "{stdout}\n{stderr}");
    let bytes = std::fs::read(&jpeg).unwrap();
    assert_eq!(
        image::guess_format(&bytes).unwrap(),
        image::ImageFormat::Jpeg
    );
    assert_eq!(image::load_from_memory(&bytes).unwrap().width(), 32);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A scene named by its bare file name is read from the current folder, with its external
/// buffer and image (the fuzz seed that names them, beside them in a folder of its own).
#[test]
fn a_bare_scene_file_name_is_found_in_the_current_folder_and_unrendered_features_named() {
    let fuzz = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz");
    let dir = std::env::temp_dir().join(format!("histencil-bare-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for file in [
        "assets/tri.bin",
        "assets/px.png",
        "corpus/gltf/external.gltf",
    ] {
        let from = fuzz.join(file);
        std::fs::copy(&from, dir.join(from.file_name().unwrap())).unwrap();
    }
    let run = Command::new(env!("CARGO_BIN_EXE_histencil"))
        .current_dir(&dir)
        .args([
            "render",
            "--scene",
            "external.gltf",
            "--width",
            "32",
            "--height",
            "24",
        ])
        .args(["--frames", "1", "--out", "frame.png"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    assert!(dir.join("frame.png").is_file());
    assert!(!stderr.contains("not rendered"), "{stderr}");
    // What a file holds but histencil does not render is said once: an occlusion map.
    let gltf = dir.join("external.gltf");
    let text = std::fs::read_to_string(&gltf).unwrap().replacen(
        r#""materials":[{"#,
        r#""materials":[{"occlusionTexture":{"index":0},"#,
        1,
    );
    std::fs::write(&gltf, text).unwrap();
    let run = Command::new(env!("CARGO_BIN_EXE_histencil"))
        .current_dir(&dir)
        .args(["render", "--scene", "external.gltf", "--frames", "1"])
        .args(["--width", "32", "--height", "24", "--out", "frame.png"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    let note = "scene `external.gltf`: not rendered: occlusionTexture (1 material)";
    assert_eq!(stderr.matches(note).count(), 1, "{stderr}");
    std::fs::remove_dir_all(dir).unwrap();
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
    for (ok, stderr, output) in brdf_eval_on_both_devices(&dir, &cases) {
        assert!(!ok, "a bad row makes the run fail");
        assert!(
            stderr.contains("row 3 (id `c`): lambert: unknown parameter `albedo`"),
            "{stderr}"
        );
        assert!(!stderr.contains("panicked"), "{stderr}");
        outputs.push(output);
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

/// No segment of a one-line error (split at `: `) says the same thing twice.
fn assert_says_each_thing_once(stderr: &str) {
    let segments: Vec<&str> = stderr.trim().split(": ").filter(|s| s.len() > 8).collect();
    for (i, s) in segments.iter().enumerate() {
        assert!(
            !segments[i + 1..].contains(s),
            "`{s}` said twice in {stderr}"
        );
    }
}

/// Failing runs of every command that writes files leave nothing behind (no file, empty or
/// partial, no folder), and their one-line message names the cause once.
#[test]
fn failed_runs_leave_no_outputs_and_name_their_cause_once() {
    let root = std::env::temp_dir().join(format!("histencil-no-outputs-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    std::fs::create_dir_all(&root).unwrap();
    let at = |p: &str| root.join(p).to_str().unwrap().to_owned();
    let (png, exr, stencil, dir) = (at("a/x.png"), at("b/x.exr"), at("c/s.png"), at("report"));
    let costs = at("d/costs.json");
    let missing = at("missing.csv");
    let runs: Vec<(Vec<&str>, &str)> = vec![
        (
            vec![
                "render",
                "--width",
                "0",
                "--height",
                "8",
                "--out",
                &png,
                "--hdr",
                &exr,
                "--dump-stencil",
                &stencil,
            ],
            "bad resolution 0x8",
        ),
        (
            vec![
                "render",
                "--technique",
                "lut",
                "--lut-resolution",
                "0",
                "--width",
                "8",
                "--height",
                "8",
                "--out",
                &png,
                "--hdr",
                &exr,
            ],
            "LUT resolution 0 is out of range",
        ),
        (
            vec![
                "render",
                "--scene",
                "alpha",
                "--lightmap-resolution",
                "4095",
                "--width",
                "8",
                "--height",
                "8",
                "--out",
                &png,
            ],
            "lightmap resolution 4095 is out of range (2..=4094",
        ),
        (
            vec!["compare", "--width", "0", "--out", &dir],
            "bad resolution 0x720",
        ),
        (
            vec![
                "sweep", "--param", "lut-res", "--values", "1", "--width", "8", "--height", "8",
                "--frames", "1", "--out", &dir,
            ],
            "LUT resolution 1 is out of range",
        ),
        (
            vec!["calibrate", "--width", "0", "--out", &costs],
            "bad resolution 0x720",
        ),
        (
            vec!["brdf-eval", "--cases", &missing, "--out", &costs],
            "missing.csv",
        ),
    ];
    for (args, cause) in runs {
        let (ok, _, stderr) = histencil(&args);
        assert!(!ok, "{args:?} succeeded");
        assert!(
            stderr.contains(cause),
            "{args:?}: expected `{cause}` in {stderr}"
        );
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        assert_says_each_thing_once(&stderr);
        let left: Vec<_> = std::fs::read_dir(&root)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .filter(|n| n != "missing.csv")
            .collect();
        assert!(left.is_empty(), "{args:?} left {left:?}");
    }
    std::fs::remove_dir_all(&root).unwrap();
}

/// Directions of any finite length (1e300, 1e-320, both only finite in f64) evaluate on the GPU
/// as on the CPU: they are normalised in f64 before they become f32.
#[test]
fn brdf_eval_takes_directions_of_any_finite_length_on_both_devices() {
    let dir = std::env::temp_dir().join(format!("histencil-brdf-extreme-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cases = dir.join("cases.csv");
    let mut text = String::from("id,brdf,params,N,T,V,L\n");
    let models = [
        ("lambert", r#"{""rho"": 0.8}"#),
        ("ggx", r#"{""alpha"": 0.3}"#),
        ("oren_nayar_full", r#"{""rho"": 0.8, ""sigma"": 0.4}"#),
        ("kajiya_kay", r#"{""kd"": 0.5, ""ks"": 0.5, ""p"": 20}"#),
    ];
    for (m, (name, params)) in models.iter().enumerate() {
        for (s, scale) in ["1e300", "1e-320", "1e-39", "1e38", "1"].iter().enumerate() {
            // Each component written with the scale's exponent: "2" at "1e300" is "2e300".
            let comp = |x: &str| {
                if *scale == "1" {
                    x.to_owned()
                } else {
                    format!("{x}{}", &scale[1..])
                }
            };
            let (n, t, vv, l) = (
                format!("{};{};{}", comp("0"), comp("0"), comp("1")),
                format!("{};{};{}", comp("1"), comp("0"), comp("0")),
                format!("{};{};{}", comp("2"), comp("1"), comp("9")),
                format!("{};{};{}", comp("-3"), comp("1"), comp("8")),
            );
            text += &format!("m{m}s{s},{name},\"{params}\",{n},{t},{vv},{l}\n");
        }
    }
    std::fs::write(&cases, text).unwrap();
    let mut outputs = vec![];
    for (ok, stderr, output) in brdf_eval_on_both_devices(&dir, &cases) {
        assert!(ok, "{stderr}");
        outputs.push(output);
    }
    let values = |text: &str| -> Vec<(String, f64)> {
        text.lines()
            .skip(1)
            .map(|l| {
                let (id, v) = l.split_once(',').unwrap();
                (id.to_owned(), v.parse().unwrap())
            })
            .collect()
    };
    let (cpu, gpu) = (values(&outputs[0]), values(&outputs[1]));
    assert_eq!(cpu.len(), 20);
    for ((id, c), (_, g)) in cpu.iter().zip(&gpu) {
        assert!(c.is_finite() && *c > 0.0, "{id}: cpu {c}");
        assert!((c - g).abs() <= 1e-4 * c.abs(), "{id}: cpu {c} vs gpu {g}");
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// A reader that stops early (`histencil check --list | head -1`) ends the listing quietly, as
/// with any Unix filter: no panic on the closed pipe.
#[test]
fn a_closed_stdout_ends_a_listing_without_a_panic() {
    use std::io::{BufRead, BufReader};
    use std::process::Stdio;
    for args in [&["check", "--list"][..], &["scenes"][..]] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_histencil"))
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("run histencil");
        let mut first = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut first)
            .unwrap();
        // The reader is dropped here: the rest of the listing meets a closed pipe.
        let out = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!first.is_empty(), "{args:?}: nothing listed");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
}

/// A glTF without lights (most of the Khronos samples) is lit by the default rig, announced on
/// stderr and in `scenes`; `--no-default-lights` renders it black, with a warning.
#[test]
fn a_scene_without_lights_gets_the_default_rig() {
    let dir = std::env::temp_dir().join(format!("histencil-no-lights-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // One triangle: 3 positions (36 bytes) as a base64 data URI.
    let floats: Vec<u8> = [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]
        .iter()
        .flat_map(|f| f.to_le_bytes())
        .collect();
    const B64: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut uri = String::from("data:application/octet-stream;base64,");
    for chunk in floats.chunks(3) {
        let n = (u32::from(chunk[0]) << 16) | (u32::from(chunk[1]) << 8) | u32::from(chunk[2]);
        for k in (0..4).rev() {
            uri.push(B64[(n >> (6 * k) & 63) as usize] as char);
        }
    }
    let gltf = format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0]}}],
        "nodes": [{{"mesh": 0}}], "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}}}]}}],
        "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                        "min": [0, 0, 0], "max": [1, 1, 0]}}],
        "bufferViews": [{{"buffer": 0, "byteLength": 36}}],
        "buffers": [{{"byteLength": 36, "uri": "{uri}"}}]}}"#
    );
    let path = dir.join("dark.gltf");
    std::fs::write(&path, gltf).unwrap();
    let scene = path.to_str().unwrap();
    let render = |out: &std::path::Path, extra: &[&str]| {
        let mut args = vec!["render", "--scene", scene, "--width", "8", "--height", "8"];
        args.extend([
            "--frames",
            "1",
            "--validate",
            "--out",
            out.to_str().unwrap(),
        ]);
        args.extend(extra);
        let (ok, _, stderr) = histencil(&args);
        assert!(ok, "{stderr}");
        let lit = image::open(out).unwrap().into_rgba8();
        let brightest = lit
            .pixels()
            .map(|p| p.0[..3].iter().copied().max().unwrap())
            .max();
        (brightest.unwrap(), stderr)
    };
    // By default the rig lights it, and says so.
    let (brightest, stderr) = render(&dir.join("rig.png"), &[]);
    assert!(stderr.contains("lit by the default rig"), "{stderr}");
    assert!(brightest > 64, "the triangle is lit: {brightest}");
    // Without the rig it is black, with a warning.
    let (brightest, stderr) = render(&dir.join("dark.png"), &["--no-default-lights"]);
    assert!(stderr.contains("has no lights"), "{stderr}");
    assert_eq!(brightest, 0);
    // `scenes` lists the file with the rig's two lights and says where they come from.
    let (ok, stdout, stderr) = histencil(&["scenes", scene]);
    assert!(ok, "{stderr}");
    let row = stdout.lines().last().unwrap();
    let columns: Vec<&str> = row.split('\t').collect();
    assert_eq!(columns[..4], ["dark", "1", "2", "0"], "{row}");
    assert!(columns[4].ends_with("lit by the default rig"), "{row}");
    let (ok, stdout, _) = histencil(&["scenes", "--no-default-lights", scene]);
    assert!(
        ok && stdout.lines().last().unwrap().contains("\t0\t0\t"),
        "{stdout}"
    );
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn demo_prints_the_tour_and_writes_the_contact_sheet_under_validation() {
    let dir = std::env::temp_dir().join("histencil-cli-demo");
    let _ = std::fs::remove_dir_all(&dir);
    let sheet = dir.join("demo.png");
    let (ok, stdout, stderr) = histencil(&[
        "demo",
        "--width",
        "96",
        "--height",
        "64",
        "--frames",
        "1",
        "--validate",
        "--out",
        sheet.to_str().unwrap(),
    ]);
    assert!(ok, "{stdout}\n{stderr}");
    for row in [
        "forward (reference)",
        "branching, native",
        "stencil, PS3-like",
        "stencil, 360-like (zeroing)",
        "stencil, 360-like (save/restore)",
        "stencil, AMD GFX9-11 pretests (modelled)",
        "stencil, AMD GFX12 AND/OR (modelled)",
        "tiled, native",
        "depth-id (Bevy's), native",
    ] {
        assert!(stdout.contains(row), "{row}: {stdout}");
    }
    assert!(stdout.contains("flushes"), "{stdout}");
    assert!(stdout.contains("histencil check"), "{stdout}");
    // Four half-size tiles per row, three rows (the frames, then the three failures beside
    // their fixes), each under a caption band.
    let image = image::open(&sheet).expect("the contact sheet");
    assert_eq!(image.width(), 4 * (48 + 6) + 6);
    assert_eq!(image.height(), 3 * (32 + 30 + 6) + 6);
}

#[test]
fn scale_reports_the_town_under_validation() {
    let dir = std::env::temp_dir().join("histencil-cli-scale");
    let _ = std::fs::remove_dir_all(&dir);
    let report = dir.join("scale.md");
    let (ok, stdout, stderr) = histencil(&[
        "scale",
        "--width",
        "64",
        "--height",
        "36",
        "--frames",
        "2",
        "--validate",
        "--out",
        report.to_str().unwrap(),
    ]);
    assert!(ok, "{stdout}\n{stderr}");
    let written = std::fs::read_to_string(&report).expect("the report");
    assert!(stdout.contains(&written), "{stdout}");
    assert!(written.contains("247808 triangles"), "{written}");
    assert!(written.contains("25 materials, 256 lights"), "{written}");
    // Every technique is within one 8-bit step of forward.
    for row in ["stencil, native", "stencil, PS3-like", "branching, native"] {
        let line = written
            .lines()
            .find(|l| l.starts_with(&format!("| {row} |")))
            .unwrap_or_else(|| panic!("{row}: {written}"));
        let error = line.rsplit('|').nth(1).unwrap().trim();
        let max: f64 = error.split(" / ").next().unwrap().parse().unwrap();
        assert!(max <= 1.0, "{line}");
        // The emulated row gives the technique and the emulator's bookkeeping apart.
        let lighting = line.split('|').nth(3).unwrap();
        assert_eq!(lighting.contains(" + "), row.contains("PS3-like"), "{line}");
    }
    assert!(
        written.contains("Lighting time over branching's"),
        "{written}"
    );
    std::fs::remove_dir_all(dir).unwrap();
}

/// `todays-gpus` under validation: the table names every platform, the 360-like backend without
/// zeroing loses lights to the engine's bits (the talk's failure), no other platform does, and
/// the AMD models cull tiles while shading exactly what native shades.
#[test]
fn todays_gpus_asks_the_talks_questions_of_every_platform() {
    let dir = std::env::temp_dir().join(format!("histencil-todays-gpus-{}", std::process::id()));
    let out = dir.to_str().unwrap();
    let (ok, stdout, stderr) = histencil(&[
        "todays-gpus",
        "--scenes",
        "default",
        "--width",
        "96",
        "--height",
        "64",
        "--validate",
        "--out",
        out,
    ]);
    assert!(ok, "{stderr}");
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("todays-gpus.json")).unwrap()).unwrap();
    let platforms = json["platforms"].as_array().unwrap();
    assert_eq!(platforms.len(), 7, "{stdout}");
    let scene = |i: usize| &platforms[i]["scenes"][0];
    let needed = scene(6)["fragments_the_frame_needs"].as_u64().unwrap();
    for (i, p) in platforms.iter().enumerate() {
        let effect = scene(i)["engine_bits"].as_str().unwrap();
        let name = p["platform"].as_str().unwrap();
        assert_eq!(effect == "breaks", i == 0, "{name}: {effect}");
        if i > 0 {
            let shaded = scene(i)["with_engine_bits"]["fragments_shaded"].as_u64();
            assert_eq!(shaded, Some(needed), "{name}");
        }
    }
    // NVIDIA's ZCull criterion is assumed to cull as the PS3's: the same counts.
    assert_eq!(scene(3)["with_engine_bits"], scene(2)["with_engine_bits"]);
    for amd in [4, 5] {
        let culled = scene(amd)["with_engine_bits"]["tiles_culled"]
            .as_u64()
            .unwrap();
        assert!(culled > 0, "{}", platforms[amd]["platform"]);
    }
    assert!(stdout.contains("| amd-andor (GFX12) | no |"), "{stdout}");
    // The depth-id model: a pass per BRDF in the frame, every surface pixel shaded once.
    let depth_id = &json["depth_id"][0];
    assert!(depth_id["passes"].as_u64().unwrap() >= 1, "{depth_id}");
    let shaded = depth_id["stats"]["fragments_shaded"].as_u64().unwrap();
    assert!(shaded > 0 && shaded <= 96 * 64, "{depth_id}");
    // Every count was also taken on the GPU, with each hierarchy emulated there: the same.
    assert_eq!(json["gpu_disagreements"].as_array().unwrap().len(), 0);
    assert_eq!(depth_id["gpu_ids_stats"], depth_id["stats"]);
    assert!(stdout.contains("the GPU's counts equal"), "{stdout}");
    // Adreno's LRZ: the native plan's mask draws write stencil and lose its test; nothing
    // writes depth, so nothing leaves it invalid.
    let lrz = &json["adreno_lrz"][0];
    let draws = lrz["draws"].as_u64().unwrap();
    let without_test = lrz["without_lrz_test"].as_u64().unwrap();
    assert!(without_test > 0 && without_test < draws, "{lrz}");
    assert_eq!(lrz["leaving_lrz_invalid"], 0, "{lrz}");
    assert!(
        stdout.contains("## Adreno: what the mask passes cost LRZ"),
        "{stdout}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--brdfs DIR`: each bad folder, and each scene its set cannot shade, is refused before any
/// device work with a message naming the file (and line) at fault, and no output is left.
#[test]
fn a_bad_brdf_folder_is_refused_before_rendering_and_leaves_no_output() {
    let root = std::env::temp_dir().join(format!("histencil-cli-brdfs-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    let toon = "vec3 toon(vec4 p, vec3 N, vec3 T, vec3 V, vec3 L) { return vec3(p.x * max(dot(N, L), 0.0)); }\n";
    let manifest = "[[brdf]]\nname = \"toon\"\nglsl = \"toon.glsl\"\nparams = [{ name = \"rho\", min = 0, max = 1, default = 1 }]\n";
    let cases: &[(&str, &str, &str, &str)] = &[
        ("toml", "[[brdf]\n", toon, "brdfs.toml: not valid TOML"),
        (
            "missing",
            "[[brdf]]\nname = \"toon\"\nglsl = \"nope.glsl\"\n",
            toon,
            "brdfs.toml:3: BRDF `toon`: GLSL file",
        ),
        (
            "outside",
            "[[brdf]]\nname = \"toon\"\nglsl = \"../toon.glsl\"\n",
            toon,
            "must be a relative path inside the BRDF folder",
        ),
        (
            "twice",
            &format!("{manifest}{manifest}"),
            toon,
            "BRDF `toon` is named twice",
        ),
        (
            "builtin",
            "[[brdf]]\nname = \"ggx\"\nglsl = \"toon.glsl\"\n",
            toon,
            "has a built-in's name",
        ),
        (
            "glsl",
            manifest,
            "vec3 toon(vec4 p, vec3 N, vec3 T, vec3 V, vec3 L) {\n  return p.x;\n}\n",
            "toon.glsl:2: error",
        ),
        (
            "nan",
            manifest,
            "vec3 toon(vec4 p, vec3 N, vec3 T, vec3 V, vec3 L) { return vec3(p.x / dot(N, L)); }\n",
            "engine BRDF `toon` returns",
        ),
    ];
    let out = root.join("out.png");
    for (name, manifest, glsl, needle) in cases {
        let dir = root.join(name);
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("brdfs.toml"), manifest).unwrap();
        std::fs::write(dir.join("toon.glsl"), glsl).unwrap();
        let (ok, _, stderr) = histencil(&[
            "render",
            "--scene",
            "brdfs-1",
            "--brdfs",
            dir.to_str().unwrap(),
            "--width",
            "16",
            "--height",
            "9",
            "--validate",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(!ok, "{name}: succeeded");
        assert!(!stderr.contains("panicked"), "{name}: {stderr}");
        assert!(
            stderr.contains(needle),
            "{name}: expected `{needle}` in {stderr}"
        );
        assert!(!out.exists(), "{name}: left {}", out.display());
    }
    // A glTF material naming an engine BRDF without its folder, or a parameter out of range.
    let gltf = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/brdfs/own-brdfs.gltf");
    let gltf = gltf.to_str().unwrap();
    let args = |brdfs: Option<&str>| {
        let mut a = vec!["render", "--scene", gltf, "--width", "16", "--height", "9"];
        if let Some(dir) = brdfs {
            a.extend(["--brdfs", dir]);
        }
        a.extend(["--out", out.to_str().unwrap()]);
        a.into_iter().map(str::to_owned).collect::<Vec<_>>()
    };
    let run = |a: Vec<String>| histencil(&a.iter().map(String::as_str).collect::<Vec<_>>());
    let (ok, _, stderr) = run(args(None));
    assert!(
        !ok && stderr.contains("unknown BRDF") && stderr.contains("--brdfs DIR"),
        "{stderr}"
    );
    let narrow = root.join("narrow");
    std::fs::create_dir_all(&narrow).unwrap();
    let examples = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/brdfs");
    let text = std::fs::read_to_string(examples.join("brdfs.toml")).unwrap();
    // `bands` up to 3 only: the file's 4 is out of range.
    std::fs::write(
        narrow.join("brdfs.toml"),
        text.replace("max = 8, default = 3", "max = 3, default = 3"),
    )
    .unwrap();
    for f in ["toon.glsl", "sheen.glsl"] {
        std::fs::copy(examples.join(f), narrow.join(f)).unwrap();
    }
    let (ok, _, stderr) = run(args(Some(narrow.to_str().unwrap())));
    assert!(
        !ok && stderr.contains("toon: parameter `bands` must be a number in [1, 3], got 4"),
        "{stderr}"
    );
    assert!(!out.exists());
    // And the folder itself renders it.
    let (ok, _, stderr) = run(args(Some(examples.to_str().unwrap())));
    assert!(ok, "{stderr}");
    assert!(out.exists());
    let _ = std::fs::remove_dir_all(&root);
}
