//! `include/histencil.h` is C99 and C++17 clean under the strictest warnings, and a C99 program
//! calling every function it declares (`tests/c/every_call.c`) links against the static library
//! and gets each refusal the header promises, under AddressSanitizer and UBSan.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The folder cargo put this package's libraries in (`target/debug`): this test's own
/// executable sits in its `deps/`.
fn library_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("the test's path");
    exe.parent()
        .and_then(Path::parent)
        .expect("target/<profile>/deps/")
        .to_owned()
}

fn run(command: &mut Command) -> String {
    let out = command
        .output()
        .unwrap_or_else(|e| panic!("{command:?}: {e}"));
    let text =
        String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{command:?} failed:\n{text}");
    text
}

#[test]
fn the_header_is_c99_and_cpp17_clean_and_every_call_refuses_as_it_says() {
    let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let include = crate_dir.join("include");
    let header = include.join("histencil.h");
    let strict = ["-pedantic", "-Wall", "-Wextra", "-Werror"];
    run(Command::new("cc")
        .args(["-std=c99", "-fsyntax-only", "-x", "c"])
        .args(strict)
        .arg(&header));
    run(Command::new("c++")
        .args(["-std=c++17", "-fsyntax-only", "-x", "c++"])
        .args(strict)
        .arg(&header));
    let exe = Path::new(env!("CARGO_TARGET_TMPDIR")).join("every_call");
    let library = library_dir().join("libhistencil_capi.a");
    assert!(library.exists(), "{} was not built", library.display());
    run(Command::new("cc")
        .args([
            "-std=c99",
            "-g",
            "-fsanitize=address,undefined",
            "-fno-sanitize-recover=all",
        ])
        .args(strict)
        .arg("-I")
        .arg(&include)
        .arg(crate_dir.join("tests/c/every_call.c"))
        .arg(&library)
        .args(["-lvulkan", "-lpthread", "-ldl", "-lm", "-o"])
        .arg(&exe));
    let said = run(Command::new(&exe).env("ASAN_OPTIONS", "detect_leaks=0"));
    assert!(
        said.contains("c99: 27 calls, every one answered as the header says"),
        "{said}"
    );
}
