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
        "unknown technique",
    );
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
    ]);
    assert!(ok, "{stdout}\n{stderr}");
    assert!(stdout.contains("frame time"), "{stdout}");
    let stencil = image::open(&stencil).unwrap().into_luma8();
    assert_eq!(stencil.dimensions(), (64, 48));
    assert!(
        stencil.pixels().all(|p| p.0[0] & 1 == 0),
        "culling bit left set"
    );
    assert!(
        stencil.pixels().any(|p| p.0[0] != 0),
        "no BRDF bits written"
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
