//! `histencil check` end to end: a clean slice of the matrix passes (its known-wrong cases fail
//! as expected), a broken renderer makes it fail with a JUnit failure and the three images, and
//! usage errors exit 2 having written nothing.

use std::path::{Path, PathBuf};
use std::process::Command;

/// Runs `histencil check` on lavapipe (unless told otherwise): exit code, stdout, stderr.
fn check(args: &[&str]) -> (Option<i32>, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_histencil"))
        .arg("check")
        .args(args)
        .env(
            "HISTENCIL_DEVICE",
            std::env::var("HISTENCIL_DEVICE").unwrap_or_else(|_| "llvmpipe".into()),
        )
        .output()
        .expect("run histencil");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn fresh_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("histencil-check-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn text(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn a_clean_slice_passes_and_its_known_wrong_cases_fail_as_expected() {
    let dir = fresh_dir("clean");
    let (junit, json) = (dir.join("junit.xml"), dir.join("check.json"));
    let (code, stdout, stderr) = check(&[
        "--quick",
        "--scene",
        "brdfs-3",
        "--filter",
        "d32s8-257x129",
        "--junit",
        junit.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
        "--out",
        dir.join("cases").to_str().unwrap(),
    ]);
    assert_eq!(code, Some(0), "{stdout}\n{stderr}");
    // Not a terminal: no progress bar in the log.
    assert!(!stderr.contains('\u{1b}'), "{stderr}");
    // The slice's 69 cases, and the worker's canary and teardown apart.
    assert!(
        stdout.contains(" 69 cases on llvmpipe ")
            && stdout.contains(": 69 Pass; device checks (canaries, teardowns): 2 Pass\n"),
        "{stdout}"
    );
    assert!(stdout.contains("driver: llvmpipe (Mesa "), "{stdout}");
    assert!(
        stdout.contains("known-wrong cases: 4 failed as expected"),
        "{stdout}"
    );
    let xml = text(&junit);
    assert!(xml.contains("<testsuite name=\"brdfs-3\""), "{xml}");
    assert!(xml.contains("failures=\"0\""), "{xml}");
    assert!(
        xml.contains("<property name=\"driver\" value=\"llvmpipe (Mesa "),
        "{xml}"
    );
    assert_eq!(xml.matches("failed as expected").count(), 4, "{xml}");
    let report: serde_json::Value = serde_json::from_str(&text(&json)).unwrap();
    let cases = report["cases"].as_array().unwrap();
    // The reference, 2 patterns x 32 lighting configurations (tiled, depth-id and stencil on
    // the two AMD platforms among them), 4 known-wrong, and the D32S8 context's canary and
    // teardown (one row each, whichever workers made them).
    assert_eq!(cases.len(), 1 + 2 * 32 + 4 + 2);
    assert!(cases.iter().all(|c| c["status"] == "Pass"));
    let stencil_ps3 = cases
        .iter()
        .find(|c| c["name"] == "stencil-ps3-auto-pA0-lightmap-d32s8-257x129")
        .expect("the case ran");
    assert!(stencil_ps3["data"]["image"]["max"].as_u64().unwrap() <= 1);
    assert!(
        !dir.join("cases").join("brdfs-3").exists(),
        "nothing failed, no images written"
    );
    let results = text(&dir.join("cases").join("results.csv"));
    assert_eq!(
        results.lines().filter(|l| l.contains(",Pass,")).count(),
        71,
        "{results}"
    );
}

#[test]
fn a_broken_renderer_fails_the_check_with_junit_failures_and_images() {
    let dir = fresh_dir("broken");
    let (junit_path, out_path) = (dir.join("junit.xml"), dir.join("cases"));
    let case = "stencil-ps3-auto-p00-lightmap-d32s8-257x129";
    let (junit, out) = (junit_path.to_str().unwrap(), out_path.to_str().unwrap());
    let one_case = [
        "--quick", "--scene", "default", "--filter", case, "--out", out,
    ];
    let broken = [
        &one_case[..],
        &["--inject-fault", "drop-flushes", "--junit", junit],
    ]
    .concat();
    let (code, stdout, stderr) = check(&broken);
    assert_eq!(code, Some(1), "{stdout}\n{stderr}");
    assert!(
        stderr.contains(&format!("Fail default/{case}: image: max")),
        "{stderr}"
    );
    let xml = text(&junit_path);
    assert!(xml.contains("failures=\"1\""), "{xml}");
    assert!(xml.contains("type=\"image\""), "{xml}");
    for suffix in ["actual", "expected", "difference", "stencil"] {
        let png = out_path
            .join("default")
            .join(format!("{case}-{suffix}.png"));
        let image = image::open(&png).unwrap_or_else(|e| panic!("{}: {e}", png.display()));
        assert_eq!((image.width(), image.height()), (257, 129));
    }
    // The same case without the fault passes: the failure was the fault's.
    let (code, stdout, stderr) = check(&one_case);
    assert_eq!(code, Some(0), "{stdout}\n{stderr}");
}

#[test]
fn usage_errors_exit_2_and_write_nothing() {
    let dir = fresh_dir("usage");
    let junit = dir.join("junit.xml");
    let junit = junit.to_str().unwrap();
    for (args, needle) in [
        (
            vec!["--scene", "kitchen", "--junit", junit],
            "unknown scene `kitchen`",
        ),
        (
            vec!["--scene", "default", "--junit", "/proc/histencil/junit.xml"],
            "/proc/histencil",
        ),
        (
            vec!["--scene", "default", "--resolution", "8"],
            "--resolution",
        ),
        (
            vec!["--scene", "/nonexistent/scene.gltf", "--junit", junit],
            "/nonexistent/scene.gltf",
        ),
    ] {
        let (code, stdout, stderr) = check(&args);
        assert_eq!(code, Some(2), "{args:?}: {stdout}\n{stderr}");
        assert!(stderr.contains(needle), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
    assert!(!dir.exists(), "a usage error wrote {}", dir.display());
}

#[test]
fn list_prints_the_matrix_without_a_device() {
    let (code, quick, stderr) = check(&["--list", "--quick", "--scene", "default"]);
    assert_eq!(code, Some(0), "{stderr}");
    // The count goes to stderr: stdout is a case list as it stands.
    assert!(stderr.contains("cases (1 scenes"), "{stderr}");
    assert!(quick.lines().all(|l| l.starts_with("default/")), "{quick}");
    let (_, full, _) = check(&["--list", "--scene", "default"]);
    let count = |listing: &str| listing.lines().count();
    // Per format and resolution: the reference and 64 lighting cases (32 per pattern, tiled,
    // depth-id and the AMD platforms among them), plus 4 known-wrong cases on D32S8 at 64x64
    // and up.
    assert_eq!(count(&quick), 2 * 3 * 65 + 4);
    assert_eq!(count(&full), 2 * 4 * 65 + 2 * 4);
    let (_, table, _) = check(&[
        "--list",
        "--list-format",
        "table",
        "--quick",
        "--scene",
        "default",
    ]);
    assert!(table.contains("default\tstencil-x360-no-zeroing-auto-pA0-lightmap-d32s8-257x129\tWrong(PreservedBitsNotZeroed)"), "{table}");
    assert!(full.contains("d24s8-1280x720"));
}
