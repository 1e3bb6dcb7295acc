//! `histencil` as the `bin` of a deqp-runner suite entry (`[[gtest]]` in Mesa's suite TOML).
//! deqp-runner's suite mode starts a gtest binary with no arguments of its own
//! (`BIN --gtest_list_tests`, then `BIN --gtest_filter=A:B...`), so histencil, started with a
//! googletest flag first, runs `histencil check` in its gtest face with the settings a CI job
//! gives it through the environment, `HISTENCIL_CHECK_*` ([`VARIABLES`]).
//!
//! deqp-runner 0.24.0 gives a `[[gtest]]` entry's `env` table to no process (its gtest command,
//! unlike its dEQP and piglit ones, never applies it), so the variables come from the job's own
//! environment, which deqp-runner passes on; an entry selects among the cases with `include`.
//! Pure: the arguments and a lookup in, the `check` command line out.

use std::ffi::OsString;

/// How a variable becomes arguments of `histencil check`.
#[derive(Clone, Copy)]
enum Form {
    /// `1`/`true` adds the flag, `0`/`false`/empty adds nothing.
    Flag,
    /// The value, as one argument.
    Value,
    /// A comma-separated list, one argument each.
    List,
}

/// Every variable the gtest face reads: its name, the `check` option it sets, how, and what
/// it is for (`check --help` prints these).
const VARIABLES: [(&str, &str, Form, &str); 9] = [
    (
        "HISTENCIL_CHECK_QUICK",
        "--quick",
        Form::Flag,
        "1: the quick matrix (1x1, 7x5, 257x129)",
    ),
    (
        "HISTENCIL_CHECK_SCENES",
        "--scene",
        Form::List,
        "embedded scenes or glTF files, comma-separated (default: every embedded scene)",
    ),
    (
        "HISTENCIL_CHECK_BRDFS",
        "--brdfs",
        Form::Value,
        "a folder of the engine's own BRDFs",
    ),
    (
        "HISTENCIL_CHECK_FILTER",
        "--filter",
        Form::Value,
        "only the cases whose scene/case name contains this",
    ),
    (
        "HISTENCIL_CHECK_EXPECT_DRIVER",
        "--expect-driver",
        Form::Value,
        "refuse to run unless the driver line contains this (the driver the job built)",
    ),
    (
        "HISTENCIL_CHECK_INJECT_FAULT",
        "--inject-fault",
        Form::List,
        "faults, comma-separated (drop-flushes, crash=PART...): prove the suite catches one",
    ),
    (
        "HISTENCIL_CHECK_OUT",
        "--out",
        Form::Value,
        "where a failing case's images and messages go",
    ),
    (
        "HISTENCIL_CHECK_ACCEPT_MESSAGES",
        "--accept-messages",
        Form::Value,
        "validation messages to accept",
    ),
    (
        "HISTENCIL_CHECK_GENERAL_PATH",
        "--general-path",
        Form::Flag,
        "1: apply no driver quirk",
    ),
];

/// The variables for `check --help`, a line each.
pub fn help() -> String {
    let mut text = String::from(
        "As the `bin` of a deqp-runner suite entry (`[[gtest]]`, ci/mesa/histencil.toml): \
         started with a googletest flag first (`histencil --gtest_list_tests`, `histencil \
         --gtest_filter=...`), histencil runs this command in its gtest face with these \
         variables of its environment (set them in the job: deqp-runner 0.24.0 applies no \
         `[[gtest]]` entry's `env`):\n",
    );
    for (name, option, _, what) in VARIABLES {
        text.push_str(&format!("  {name:<32} {option}: {what}\n"));
    }
    text
}

/// Whether `args` (the process's, program name first) start histencil as a gtest binary.
pub fn is_gtest_binary(args: &[OsString]) -> bool {
    args.get(1)
        .and_then(|a| a.to_str())
        .is_some_and(|a| a.starts_with("--gtest_"))
}

/// The `histencil check` command line for a gtest-binary start: the program, `check`, the
/// options `lookup` (a variable's value, if set) gives, then the googletest arguments.
///
/// # Errors
/// A flag variable that is neither `1`, `true`, `0`, `false` nor empty, named.
pub fn check_args(
    args: &[OsString],
    lookup: &dyn Fn(&str) -> Option<String>,
) -> Result<Vec<OsString>, String> {
    let mut out: Vec<OsString> = args.iter().take(1).cloned().collect();
    out.push("check".into());
    for (name, option, form, _) in VARIABLES {
        let Some(value) = lookup(name) else { continue };
        match form {
            Form::Flag => match value.as_str() {
                "1" | "true" => out.push(option.into()),
                "0" | "false" | "" => {}
                _ => return Err(format!("{name}={value}: expected 1 or 0")),
            },
            Form::Value => out.push(format!("{option}={value}").into()),
            Form::List => out.extend(
                value
                    .split(',')
                    .map(str::trim)
                    .filter(|v| !v.is_empty())
                    .map(|v| format!("{option}={v}").into()),
            ),
        }
    }
    out.extend(args.iter().skip(1).cloned());
    Ok(out)
}

/// The variables set, `NAME=value` comma-separated, for the run's first stdout line; `None`
/// when none is.
pub fn settings_line(lookup: &dyn Fn(&str) -> Option<String>) -> Option<String> {
    let set: Vec<String> = VARIABLES
        .iter()
        .filter_map(|(name, ..)| lookup(name).map(|v| format!("{name}={v}")))
        .collect();
    (!set.is_empty()).then(|| set.join(", "))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env<'a>(vars: &'a [(&'a str, &'a str)]) -> impl Fn(&str) -> Option<String> + 'a {
        move |name| {
            vars.iter()
                .find(|(n, _)| *n == name)
                .map(|(_, v)| v.to_string())
        }
    }

    fn os(args: &[&str]) -> Vec<OsString> {
        args.iter().map(OsString::from).collect()
    }

    #[test]
    fn the_environment_becomes_the_check_command_line() {
        let args = os(&["histencil", "--gtest_filter=a.b:c.d"]);
        assert!(is_gtest_binary(&args));
        assert!(!is_gtest_binary(&os(&[
            "histencil",
            "check",
            "--gtest_list_tests"
        ])));
        assert!(!is_gtest_binary(&os(&["histencil"])));
        let vars = [
            ("HISTENCIL_CHECK_QUICK", "1"),
            ("HISTENCIL_CHECK_SCENES", "brdfs-1, default,"),
            ("HISTENCIL_CHECK_FILTER", "-7x5"),
            ("HISTENCIL_CHECK_INJECT_FAULT", "drop-flushes,crash=x"),
            ("HISTENCIL_CHECK_GENERAL_PATH", "0"),
        ];
        let got = check_args(&args, &env(&vars)).unwrap();
        assert_eq!(
            got,
            os(&[
                "histencil",
                "check",
                "--quick",
                "--scene=brdfs-1",
                "--scene=default",
                "--filter=-7x5",
                "--inject-fault=drop-flushes",
                "--inject-fault=crash=x",
                "--gtest_filter=a.b:c.d",
            ])
        );
        let line = settings_line(&env(&vars)).unwrap();
        assert!(
            line.starts_with("HISTENCIL_CHECK_QUICK=1, HISTENCIL_CHECK_SCENES="),
            "{line}"
        );
        assert_eq!(settings_line(&env(&[])), None);
        let err = check_args(&args, &env(&[("HISTENCIL_CHECK_QUICK", "yes")])).unwrap_err();
        assert!(err.contains("HISTENCIL_CHECK_QUICK=yes"), "{err}");
    }

    #[test]
    fn the_help_names_every_variable() {
        let help = help();
        for (name, option, ..) in VARIABLES {
            assert!(help.contains(name) && help.contains(option), "{name}");
        }
    }
}
