//! The command line's own words, held to the copies the book shows: every command's `--help`
//! and a few usage errors (with their exit codes) equal the files under `docs/src/lab/help/`,
//! which `docs/src/lab/commands.md` includes. A change to an option fails here until the copies
//! are rewritten (`HISTENCIL_BLESS=1 cargo test -p histencil-cli --test help`), so the book
//! cannot describe options the binary no longer has.

use std::path::PathBuf;
use std::process::Command;

/// Each snapshot: its file name, and the arguments after `histencil`.
const HELP: &[(&str, &[&str])] = &[
    ("histencil", &["--help"]),
    ("render", &["render", "--help"]),
    ("demo", &["demo", "--help"]),
    ("scenes", &["scenes", "--help"]),
    ("compare", &["compare", "--help"]),
    ("compare-merge", &["compare", "merge", "--help"]),
    ("compare-pair", &["compare", "pair", "--help"]),
    ("todays-gpus", &["todays-gpus", "--help"]),
    ("scale", &["scale", "--help"]),
    ("sweep", &["sweep", "--help"]),
    ("calibrate", &["calibrate", "--help"]),
    ("check", &["check", "--help"]),
    ("check-merge", &["check", "merge", "--help"]),
    ("brdf-eval", &["brdf-eval", "--help"]),
    ("brdf-report", &["brdf-report", "--help"]),
    ("shaders", &["shaders", "--help"]),
];

/// Usage errors: one line each, and the exit code clap's errors take (2).
const USAGE_ERRORS: &[(&str, &[&str])] = &[
    (
        "error-unknown-technique",
        &["render", "--technique", "nope"],
    ),
    ("error-bad-shard", &["check", "--shard", "3/2"]),
    ("error-unknown-command", &["rendr"]),
];

fn snapshots() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../docs/src/lab/help")
}

/// `histencil args`: its exit code and what it printed (stdout, then stderr).
fn run(args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_histencil"))
        .args(args)
        .output()
        .expect("run histencil");
    let text =
        String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    (out.status.code().unwrap_or(-1), text)
}

/// Compares `text` with the snapshot `name`, or writes it when blessing. Returns a complaint.
fn held(name: &str, text: &str) -> Option<String> {
    let path = snapshots().join(format!("{name}.txt"));
    if std::env::var_os("HISTENCIL_BLESS").is_some() {
        std::fs::create_dir_all(snapshots()).unwrap();
        std::fs::write(&path, text).unwrap();
        return None;
    }
    match std::fs::read_to_string(&path) {
        Ok(kept) if kept == text => None,
        Ok(kept) => Some(format!(
            "{}: the binary now says\n{text}\nwhere the book shows\n{kept}",
            path.display()
        )),
        Err(e) => Some(format!("{}: {e}", path.display())),
    }
}

#[test]
fn every_commands_help_is_the_books() {
    let mut problems = Vec::new();
    for (name, args) in HELP {
        let (code, text) = run(args);
        assert_eq!(code, 0, "histencil {}: {text}", args.join(" "));
        problems.extend(held(name, &text));
    }
    assert!(
        problems.is_empty(),
        "{}\n(rewrite the copies: HISTENCIL_BLESS=1 cargo test -p histencil-cli --test help)",
        problems.join("\n")
    );
}

#[test]
fn usage_errors_are_one_line_with_exit_code_2() {
    let mut problems = Vec::new();
    for (name, args) in USAGE_ERRORS {
        let (code, text) = run(args);
        assert_eq!(code, 2, "histencil {}: {text}", args.join(" "));
        assert_eq!(text.trim_end().lines().count(), 1, "{text}");
        problems.extend(held(name, &text));
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}
