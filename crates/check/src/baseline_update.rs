//! The next baseline from the one a run used and what failed in it (`check merge
//! --update-baseline`): a baseline keeps a reason beside each line (`scene/case,Fail  # why`),
//! and a copy of `failures.csv` has none. Pure: texts and names in, text and lists out.
//!
//! Each line of the old baseline whose case still fails as it says stays as written, reason and
//! all; a case that now fails otherwise gets its new status and a mark asking for a reason (the
//! old one quoted); a case that no longer fails loses its line and is listed. Failures the old
//! baseline lacks are added at the end, each marked. Comments and blank lines stay.

use crate::lists::Status;
use std::collections::BTreeMap;

/// What a line added or changed carries until someone writes why.
pub const NEEDS_REASON: &str = "NEEDS A REASON";

/// The next baseline and what changed.
#[derive(Debug, Default, PartialEq, Eq)]
pub struct BaselineUpdate {
    /// The next baseline's text.
    pub text: String,
    /// Lines kept as written: the case still fails as they say.
    pub kept: usize,
    /// Cases whose failure changed (`name: old -> new`).
    pub changed: Vec<String>,
    /// Cases that fail and had no line (`name,Status`).
    pub added: Vec<String>,
    /// The old lines whose case no longer fails, as written: removed.
    pub now_pass: Vec<String>,
}

/// The next baseline from `old` (a baseline's text, `scene/case` spelling) and `failing` (every
/// case that ended failing, expected or not, with the failure it ended with: what
/// `failures.csv` lists). `ran` says whether a case was part of the run: a line for a case the
/// run did not include (another shard's, a full run's case in a quick job) is kept as written.
pub fn update_baseline(
    old: &str,
    failing: &BTreeMap<String, Status>,
    ran: &dyn Fn(&str) -> bool,
) -> BaselineUpdate {
    let mut out = BaselineUpdate::default();
    let mut left = failing.clone();
    for line in old.lines() {
        let (content, reason) = match line.split_once('#') {
            Some((c, r)) => (c.trim(), Some(r.trim())),
            None => (line.trim(), None),
        };
        let Some((name, status)) = content.rsplit_once(',') else {
            // A comment or a blank line.
            out.text.push_str(line);
            out.text.push('\n');
            continue;
        };
        let name = name.trim();
        let status = status.trim();
        match left.remove(name) {
            Some(now) if now.name() == status => {
                out.kept += 1;
                out.text.push_str(line);
            }
            Some(now) => {
                out.changed.push(format!("{name}: {status} -> {now}"));
                let was = reason.map(|r| format!(" ({r})")).unwrap_or_default();
                out.text.push_str(&format!(
                    "{name},{now}  # {NEEDS_REASON}: was {status}{was}"
                ));
            }
            None if !ran(name) => {
                out.kept += 1;
                out.text.push_str(line);
            }
            None => {
                out.now_pass.push(line.trim().to_owned());
                continue;
            }
        }
        out.text.push('\n');
    }
    if !left.is_empty() {
        out.text
            .push_str("# New failures: each needs a reason before it is expected for good.\n");
        for (name, status) in left {
            out.text
                .push_str(&format!("{name},{status}  # {NEEDS_REASON}\n"));
            out.added.push(format!("{name},{status}"));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reasons_survive_and_changes_are_marked() {
        let old = "# lavapipe's known failures\n\
                   a/x,Fail   # the rasteriser rounds\n\
                   a/y,Fail   # fixed upstream\n\
                   a/z,Crash  # a driver bug\n\
                   \n\
                   b/w,Timeout  # the other shard's\n";
        let failing: BTreeMap<String, Status> = [
            ("a/x".to_owned(), Status::Fail),
            ("a/z".to_owned(), Status::Timeout),
            ("a/new".to_owned(), Status::Fail),
        ]
        .into();
        let ran = |name: &str| name.starts_with("a/");
        let u = update_baseline(old, &failing, &ran);
        assert_eq!(
            u.text,
            "# lavapipe's known failures\n\
             a/x,Fail   # the rasteriser rounds\n\
             a/z,Timeout  # NEEDS A REASON: was Crash (a driver bug)\n\
             \n\
             b/w,Timeout  # the other shard's\n\
             # New failures: each needs a reason before it is expected for good.\n\
             a/new,Fail  # NEEDS A REASON\n"
        );
        assert_eq!(u.kept, 2);
        assert_eq!(u.changed, ["a/z: Crash -> Timeout"]);
        assert_eq!(u.added, ["a/new,Fail"]);
        assert_eq!(u.now_pass, ["a/y,Fail   # fixed upstream"]);
        // The next baseline is one: it parses, and expects exactly what failed (and the
        // other shard's line).
        let next = crate::lists::Baseline::parse(&u.text, "next").unwrap();
        assert_eq!(next.expected.len(), 4);
        // Updating with nothing changed changes nothing.
        let again = update_baseline(&u.text, &failing, &ran);
        assert_eq!(again.text, u.text);
        assert!(again.changed.is_empty() && again.added.is_empty() && again.now_pass.is_empty());
    }
}
