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

/// Expected results: the case's full name and the status it is known to end with, and why.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Baseline {
    pub expected: BTreeMap<String, Status>,
    /// Each line's reason, where the file gives one: the comment at the end of the line, else
    /// the comment lines directly above it (no blank line between). What a driver team's
    /// `*-fails.txt` carries beside each line, which `--print-gtest-baseline` keeps.
    pub reasons: BTreeMap<String, String>,
}

/// The comment each `name,Status` line of `text` carries, by line number (1-based): its own
/// trailing comment, else the comment lines directly above it, joined by a space.
fn line_reasons(text: &str) -> BTreeMap<usize, String> {
    let mut reasons = BTreeMap::new();
    let mut above: Vec<&str> = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let (content, comment) = match line.split_once('#') {
            Some((c, comment)) => (c.trim(), Some(comment.trim())),
            None => (line.trim(), None),
        };
        if content.is_empty() {
            match comment {
                Some(c) if !c.is_empty() => above.push(c),
                _ => above.clear(),
            }
            continue;
        }
        let reason = match comment.filter(|c| !c.is_empty()) {
            Some(own) => own.to_owned(),
            None => above.join(" "),
        };
        if !reason.is_empty() {
            reasons.insert(i + 1, reason);
        }
        above.clear();
    }
    reasons
}

impl Baseline {
    /// Parses `scene/case,Status` lines. Only failing statuses belong in a baseline (a passing
    /// case needs no line), and a muted validation layer can never be expected.
    pub fn parse(text: &str, path: &str) -> Result<Baseline, ListError> {
        let mut expected = BTreeMap::new();
        let mut reasons = BTreeMap::new();
        let mut line_reasons = line_reasons(text);
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
            if let Some(reason) = line_reasons.remove(&line) {
                reasons.insert(name.clone(), reason);
            }
            if expected.insert(name.clone(), status).is_some() {
                return Err(err(format!("`{name}` is listed twice")));
            }
        }
        Ok(Baseline { expected, reasons })
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

/// The case names of the case list at `path`. A line naming a `.txt` file includes that file's
/// names (relative to the including file's folder), as deqp-runner reads dEQP's newer case lists
/// (`vk-default.txt` lists other `.txt` files); an include that loops back is refused.
pub fn load_caselist(path: &Path) -> Result<Vec<String>, ListError> {
    let mut names = Vec::new();
    load_included(path, &mut Vec::new(), &mut names)?;
    Ok(names)
}

fn load_included(
    path: &Path,
    reading: &mut Vec<std::path::PathBuf>,
    names: &mut Vec<String>,
) -> Result<(), ListError> {
    let text = read(path)?;
    let key = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
    reading.push(key);
    for (line, content) in lines(&text) {
        let name = content.split(',').next().unwrap_or(content).trim();
        if !name.ends_with(".txt") {
            names.push(name.to_owned());
            continue;
        }
        let included = path.parent().unwrap_or(Path::new(".")).join(name);
        let canonical = std::fs::canonicalize(&included).unwrap_or_else(|_| included.clone());
        if reading.contains(&canonical) {
            return Err(ListError {
                path: path.display().to_string(),
                line,
                message: format!("`{name}` includes a list that includes this one"),
            });
        }
        load_included(&included, reading, names).map_err(|e| ListError {
            path: path.display().to_string(),
            line,
            message: format!("including `{name}`: {e}"),
        })?;
    }
    reading.pop();
    Ok(())
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
    /// Mesa's split (`--fraction N --fraction-start K`, as deqp-runner's): every Nth case of
    /// the run's order from the Kth. Otherwise histencil's `--shard K/N`: a hash of each
    /// case's name.
    pub interleaved: bool,
}

impl Shard {
    /// `K/N` (`--shard`), or `fraction K/N` as a report writes an interleaved split.
    pub fn parse(text: &str) -> Result<Shard, String> {
        let (interleaved, split) = match text.strip_prefix("fraction ") {
            Some(rest) => (true, rest),
            None => (false, text),
        };
        let bad = || format!("`{text}` is not a shard: write K/N with 1 <= K <= N");
        let (k, n) = split.split_once('/').ok_or_else(bad)?;
        let (index, count) = (
            k.trim().parse::<u32>().map_err(|_| bad())?,
            n.trim().parse::<u32>().map_err(|_| bad())?,
        );
        Shard::new(index, count, interleaved).map_err(|_| bad())
    }

    /// Split `index` of `count` (from 1), refused unless `1 <= index <= count`.
    pub fn new(index: u32, count: u32, interleaved: bool) -> Result<Shard, String> {
        if index == 0 || index > count {
            return Err(format!(
                "{index} of {count} is not a part: the start must be 1 to the count"
            ));
        }
        Ok(Shard {
            index,
            count,
            interleaved,
        })
    }

    /// Whether the case named `full` (`scene/case`), at `position` (from 0) of the run's
    /// order, is this part's. A hash shard reads the name alone, so adding, removing or
    /// filtering other cases moves no case between shards; an interleaved part reads the
    /// position, as deqp-runner's `--fraction` does (deqp-runner after a seeded shuffle of its
    /// list, so its parts are other cases).
    pub fn holds(&self, position: usize, full: &str) -> bool {
        if self.interleaved {
            position % self.count as usize == (self.index - 1) as usize
        } else {
            (fnv1a(full) % u64::from(self.count)) as u32 == self.index - 1
        }
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let kind = if self.interleaved { "fraction " } else { "" };
        write!(f, "{kind}{}/{}", self.index, self.count)
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
        // Each line's reason: its own comment, else the comment lines right above it.
        assert_eq!(b.reasons["scene/a"], "known on lavapipe 22.3");
        assert_eq!(b.reasons["scene/b"], "comment");
        let b = Baseline::parse(
            "# header

# why
# and more
scene/c,Fail
scene/d,Fail
",
            "b",
        )
        .unwrap();
        assert_eq!(b.reasons["scene/c"], "why and more");
        assert!(!b.reasons.contains_key("scene/d"), "{:?}", b.reasons);
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
    fn caselists_include_other_lists_and_refuse_loops() {
        let dir = std::env::temp_dir().join(format!("histencil-caselist-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        std::fs::write(dir.join("top.txt"), "a/1\nsub/more.txt\n# note\nb/2,Fail\n").unwrap();
        std::fs::write(dir.join("sub/more.txt"), "c/3\n").unwrap();
        assert_eq!(
            load_caselist(&dir.join("top.txt")).unwrap(),
            ["a/1", "c/3", "b/2"]
        );
        std::fs::write(dir.join("sub/more.txt"), "../top.txt\n").unwrap();
        let err = load_caselist(&dir.join("top.txt")).unwrap_err().to_string();
        assert!(
            err.contains("includes a list that includes this one"),
            "{err}"
        );
        std::fs::write(dir.join("top.txt"), "missing.txt\n").unwrap();
        let err = load_caselist(&dir.join("top.txt")).unwrap_err().to_string();
        assert!(err.contains("top.txt:1: including `missing.txt`"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn shards_partition_and_are_stable() {
        let names: Vec<String> = (0..500).map(|i| format!("scene/case-{i}")).collect();
        for interleaved in [false, true] {
            let shards: Vec<Shard> = (1..=4)
                .map(|k| Shard::new(k, 4, interleaved).unwrap())
                .collect();
            for (i, n) in names.iter().enumerate() {
                assert_eq!(shards.iter().filter(|s| s.holds(i, n)).count(), 1, "{n}");
            }
            // Round-trips through the report's spelling.
            for s in &shards {
                assert_eq!(Shard::parse(&s.to_string()), Ok(*s));
            }
        }
        // deqp-runner's --fraction 3 --fraction-start 2: the 2nd, 5th, 8th... case.
        let part = Shard::new(2, 3, true).unwrap();
        let held: Vec<usize> = (0..9).filter(|&i| part.holds(i, "")).collect();
        assert_eq!(held, [1, 4, 7]);
        let shards: Vec<Shard> = (1..=4).map(|k| Shard::new(k, 4, false).unwrap()).collect();
        for s in &shards {
            let held = names
                .iter()
                .enumerate()
                .filter(|(i, n)| s.holds(*i, n))
                .count();
            assert!((80..=170).contains(&held), "{s:?} holds {held}");
        }
        // The FNV-1a test vector: the hash cannot drift between releases.
        assert_eq!(fnv1a("a"), 0xaf63_dc4c_8601_ec8c);
        for bad in ["0/4", "5/4", "1", "a/b", "1/0"] {
            assert!(Shard::parse(bad).is_err(), "{bad}");
        }
        assert_eq!(Shard::parse("2/3"), Shard::new(2, 3, false));
        assert_eq!(Shard::parse("fraction 2/3"), Shard::new(2, 3, true));
    }
}
