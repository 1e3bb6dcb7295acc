//! `include/histencil.h` is C99 and C++17 clean under the strictest warnings. (A C99 program
//! calling every function it declares, `examples/cpp/c99/every_call.c`, is built against the
//! installed static library by the C++ example's CMake, plainly and under the sanitizers, and
//! run by tools/test.)

use std::path::Path;
use std::process::Command;

fn run(command: &mut Command) {
    let out = command
        .output()
        .unwrap_or_else(|e| panic!("{command:?}: {e}"));
    let text =
        String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{command:?} failed:\n{text}");
}

#[test]
fn the_header_is_c99_and_cpp17_clean() {
    let header = Path::new(env!("CARGO_MANIFEST_DIR")).join("include/histencil.h");
    let strict = ["-pedantic", "-Wall", "-Wextra", "-Werror"];
    run(Command::new("cc")
        .args(["-std=c99", "-fsyntax-only", "-x", "c"])
        .args(strict)
        .arg(&header));
    run(Command::new("c++")
        .args(["-std=c++17", "-fsyntax-only", "-x", "c++"])
        .args(strict)
        .arg(&header));
}
