//! The files a CI team keeps beside the runner, read the way Mesa's deqp-runner reads its own:
//! a baseline of expected results (`scene/case,Status` per line, as the run's `failures.csv`
//! writes them, so the next baseline is a copy), skip and flake patterns (a regular expression
//! per line, matched anywhere in `scene/case`), a case list (a case name per line, or a
//! `results.csv` / `failures.csv`, whose first column is taken), and the validation messages a
//! team accepts (a message id per line and the reason after it). `#` starts a comment in all of
//! them; blank lines are ignored. Everything here is pure: files in, values out.

use regex::Regex;
use std::collections::BTreeMap;
use std::fmt;
use std::path::Path;

/// What a case came to. The first five are what a worker can see; the rest are what the runner
/// makes of them with a baseline and a rerun.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Status {
    Pass,
    Fail,
    Skip,
    /// The worker died (a signal, an abort, a lost device) while the case was in flight.
    Crash,
    /// The case ran past `--timeout`; its worker was killed.
    Timeout,
    /// The validation layer did not report the canary's deliberate invalid calls: nothing the
    /// run says about validation can be trusted. Never acceptable in a baseline.
    ValidationLayerMuted,
    /// Failed as the baseline says it does.
    ExpectedFail,
    /// The baseline says it fails, and it passed: the baseline should shrink.
    UnexpectedPass,
    /// Failed, then passed on its rerun, or failed and matches a flake pattern.
    Flake,
}

impl Status {
    pub const ALL: [Status; 9] = [
        Status::Pass,
        Status::Fail,
        Status::Skip,
        Status::Crash,
        Status::Timeout,
        Status::ValidationLayerMuted,
        Status::ExpectedFail,
        Status::UnexpectedPass,
        Status::Flake,
    ];

    /// The name written in `results.csv` and baselines (deqp-runner's spelling where it has
    /// one).
    pub fn name(self) -> &'static str {
        match self {
            Status::Pass => "Pass",
            Status::Fail => "Fail",
            Status::Skip => "Skip",
            Status::Crash => "Crash",
            Status::Timeout => "Timeout",
            Status::ValidationLayerMuted => "ValidationLayerMuted",
            Status::ExpectedFail => "ExpectedFail",
            Status::UnexpectedPass => "UnexpectedPass",
            Status::Flake => "Flake",
        }
    }

    pub fn parse(text: &str) -> Option<Status> {
        Status::ALL.into_iter().find(|s| s.name() == text)
    }

    /// A status a case run can end with that is a failure before any baseline is applied.
    pub fn is_failure(self) -> bool {
        matches!(
            self,
            Status::Fail | Status::Crash | Status::Timeout | Status::ValidationLayerMuted
        )
    }

    /// Whether a run with this final status fails (unexpected passes fail unless allowed).
    pub fn fails_run(self, allow_unexpected_pass: bool) -> bool {
        self.is_failure() || (self == Status::UnexpectedPass && !allow_unexpected_pass)
    }
}

impl fmt::Display for Status {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A list file's problem, with the file and line it is on.
#[derive(Debug, thiserror::Error)]
#[error("{path}:{line}: {message}")]
pub struct ListError {
    pub path: String,
    pub line: usize,
    pub message: String,
}

/// The meaningful lines of a list file: comments and surrounding blanks removed, with their line
/// numbers.
fn lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.lines().enumerate().filter_map(|(i, line)| {
        let line = line.split('#').next().unwrap_or("").trim();
        (!line.is_empty()).then_some((i + 1, line))
    })
}

fn read(path: &Path) -> Result<String, ListError> {
    std::fs::read_to_string(path).map_err(|e| ListError {
        path: path.display().to_string(),
        line: 0,
        message: format!("cannot read: {e}"),
    })
}

/// Expected results: the case's full name and the status it is known to end with.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Baseline {
    pub expected: BTreeMap<String, Status>,
}

impl Baseline {
    /// Parses `scene/case,Status` lines. Only failing statuses belong in a baseline (a passing
    /// case needs no line), and a muted validation layer can never be expected.
    pub fn parse(text: &str, path: &str) -> Result<Baseline, ListError> {
        let mut expected = BTreeMap::new();
        for (line, content) in lines(text) {
            let err = |message: String| ListError {
                path: path.to_owned(),
                line,
                message,
            };
            let (name, status) = content
                .rsplit_once(',')
                .ok_or_else(|| err(format!("`{content}` is not `scene/case,Status`")))?;
            let status = status.trim();
            let status = Status::parse(status).ok_or_else(|| {
                err(format!(
                    "unknown status `{status}` (a baseline takes Fail, Crash or Timeout)"
                ))
            })?;
            if !matches!(status, Status::Fail | Status::Crash | Status::Timeout) {
                return Err(err(format!(
                    "`{status}` cannot be expected: a baseline lists Fail, Crash or Timeout{}",
                    if status == Status::ValidationLayerMuted {
                        " (a muted validation layer makes every verdict worthless)"
                    } else {
                        ""
                    }
                )));
            }
            let name = name.trim().to_owned();
            if expected.insert(name.clone(), status).is_some() {
                return Err(err(format!("`{name}` is listed twice")));
            }
        }
        Ok(Baseline { expected })
    }

    pub fn load(path: &Path) -> Result<Baseline, ListError> {
        Baseline::parse(&read(path)?, &path.display().to_string())
    }
}

/// Regular expressions, one per line, matched anywhere in a case's full name.
#[derive(Clone, Debug, Default)]
pub struct Patterns {
    patterns: Vec<Regex>,
}

impl Patterns {
    pub fn parse(text: &str, path: &str) -> Result<Patterns, ListError> {
        let patterns = lines(text)
            .map(|(line, content)| {
                Regex::new(content).map_err(|e| ListError {
                    path: path.to_owned(),
                    line,
                    message: format!("bad pattern: {e}"),
                })
            })
            .collect::<Result<_, _>>()?;
        Ok(Patterns { patterns })
    }

    pub fn load(path: &Path) -> Result<Patterns, ListError> {
        Patterns::parse(&read(path)?, &path.display().to_string())
    }

    /// Adds another file's patterns.
    pub fn extend(&mut self, other: Patterns) {
        self.patterns.extend(other.patterns);
    }

    pub fn matches(&self, name: &str) -> bool {
        self.patterns.iter().any(|p| p.is_match(name))
    }

    pub fn is_empty(&self) -> bool {
        self.patterns.is_empty()
    }
}

/// The case names of a case list: a name per line, or the first column of a CSV the runner
/// wrote (`results.csv`, `failures.csv`).
pub fn parse_caselist(text: &str) -> Vec<String> {
    lines(text)
        .map(|(_, content)| {
            content
                .split(',')
                .next()
                .unwrap_or(content)
                .trim()
                .to_owned()
        })
        .collect()
}

pub fn load_caselist(path: &Path) -> Result<Vec<String>, ListError> {
    Ok(parse_caselist(&read(path)?))
}

/// Validation messages a team accepts on its device, each with the reason it gives: counted in
/// the report, never dropped silently.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct AcceptedMessages {
    /// Message id (as the layer names it, e.g. `VUID-...` or `SYNC-HAZARD-...`) and reason.
    pub accepted: Vec<(String, String)>,
}

impl AcceptedMessages {
    /// Parses `MESSAGE-ID reason...` lines; the reason is required, as Mesa's zink keeps one
    /// beside every message it mutes. The canary's id cannot be accepted: that would mute the
    /// proof that the layer listens.
    pub fn parse(text: &str, path: &str) -> Result<AcceptedMessages, ListError> {
        let mut accepted = Vec::new();
        for (line, content) in lines(text) {
            let err = |message: String| ListError {
                path: path.to_owned(),
                line,
                message,
            };
            let (id, reason) = content
                .split_once(char::is_whitespace)
                .map(|(id, reason)| (id, reason.trim()))
                .unwrap_or((content, ""));
            if reason.is_empty() {
                return Err(err(format!(
                    "`{id}` has no reason: write `MESSAGE-ID why it is accepted`"
                )));
            }
            if id == histencil_vk::CANARY_ID {
                return Err(err(format!(
                    "`{id}` is the canary's message: accepting it would hide a muted layer"
                )));
            }
            accepted.push((id.to_owned(), reason.to_owned()));
        }
        Ok(AcceptedMessages { accepted })
    }

    pub fn load(path: &Path) -> Result<AcceptedMessages, ListError> {
        AcceptedMessages::parse(&read(path)?, &path.display().to_string())
    }

    pub fn accepts(&self, id: &str) -> bool {
        self.accepted.iter().any(|(a, _)| a == id)
    }
}

/// A shard of the case list: `K/N`, K from 1.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    pub index: u32,
    pub count: u32,
}

impl Shard {
    pub fn parse(text: &str) -> Result<Shard, String> {
        let bad = || format!("`{text}` is not a shard: write K/N with 1 <= K <= N");
        let (k, n) = text.split_once('/').ok_or_else(bad)?;
        let (index, count) = (
            k.trim().parse::<u32>().map_err(|_| bad())?,
            n.trim().parse::<u32>().map_err(|_| bad())?,
        );
        if index == 0 || index > count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }

    /// Whether the case named `full` (`scene/case`) is this shard's. The hash is of the name
    /// alone, so adding, removing or filtering other cases moves no case between shards.
    pub fn holds(&self, full: &str) -> bool {
        (fnv1a(full) % u64::from(self.count)) as u32 == self.index - 1
    }
}

/// FNV-1a, 64 bits: stable across Rust releases and platforms (std's hasher is not).
fn fnv1a(text: &str) -> u64 {
    text.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn baselines_read_the_failures_csv_format_and_refuse_what_cannot_be_expected() {
        let b = Baseline::parse(
            "# known on lavapipe 22.3\nscene/a,Fail\n\n scene/b , Crash # comment\n",
            "b.txt",
        )
        .unwrap();
        assert_eq!(b.expected["scene/a"], Status::Fail);
        assert_eq!(b.expected["scene/b"], Status::Crash);
        for bad in [
            "scene/a",
            "scene/a,Pass",
            "scene/a,Bogus",
            "scene/a,ValidationLayerMuted",
            "x,Fail\nx,Fail",
        ] {
            let e = Baseline::parse(bad, "b.txt").unwrap_err();
            assert!(e.to_string().starts_with("b.txt:"), "{e}");
        }
    }

    #[test]
    fn patterns_match_anywhere_and_bad_ones_name_their_line() {
        let p = Patterns::parse("town/.*1x1\n# x\n^default/stencil", "s").unwrap();
        assert!(p.matches("town/stencil-x360-1x1-d32"));
        assert!(p.matches("default/stencil-ps3"));
        assert!(!p.matches("x/default/stencil"));
        assert_eq!(
            Patterns::parse("ok\n(", "s").unwrap_err().to_string()[..4],
            *"s:2:"
        );
    }

    #[test]
    fn caselists_take_the_first_column() {
        assert_eq!(
            parse_caselist("a/b,Fail\n# c\nc/d\n e/f ,Pass,1.0\n"),
            ["a/b", "c/d", "e/f"]
        );
    }

    #[test]
    fn accepted_messages_need_a_reason_and_never_take_the_canary() {
        let a = AcceptedMessages::parse("VUID-x-1 the driver's known bug\n", "a").unwrap();
        assert!(a.accepts("VUID-x-1") && !a.accepts("VUID-x-2"));
        assert!(AcceptedMessages::parse("VUID-x-1\n", "a").is_err());
        let canary = format!("{} because\n", histencil_vk::CANARY_ID);
        assert!(AcceptedMessages::parse(&canary, "a").is_err());
    }

    #[test]
    fn shards_partition_and_are_stable() {
        let names: Vec<String> = (0..500).map(|i| format!("scene/case-{i}")).collect();
        let shards: Vec<Shard> = (1..=4).map(|k| Shard { index: k, count: 4 }).collect();
        for n in &names {
            assert_eq!(shards.iter().filter(|s| s.holds(n)).count(), 1, "{n}");
        }
        for s in &shards {
            let held = names.iter().filter(|n| s.holds(n)).count();
            assert!((80..=170).contains(&held), "{s:?} holds {held}");
        }
        // The FNV-1a test vector: the hash cannot drift between releases.
        assert_eq!(fnv1a("a"), 0xaf63_dc4c_8601_ec8c);
        for bad in ["0/4", "5/4", "1", "a/b", "1/0"] {
            assert!(Shard::parse(bad).is_err(), "{bad}");
        }
        assert_eq!(Shard::parse("2/3"), Ok(Shard { index: 2, count: 3 }));
    }
}
