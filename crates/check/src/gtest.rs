//! The check matrix as a googletest binary sees it, so that Mesa's deqp-runner (`gtest-runner`)
//! drives `histencil check` unchanged: the names, the filter and the lines on stdout. Pure:
//! names in, names and lines out (the process around it is the CLI's `gtest` module).
//!
//! A case `scene/case` is the test `Group.name`: the group is the scene's file name (an embedded
//! scene's name, a glTF file's stem) and the name the case's, each with every character other
//! than an ASCII letter or digit written `_` (`brdfs-1/stencil-ps3-auto-pA0-lightmap-d32s8-7x5`
//! is `brdfs_1.stencil_ps3_auto_pA0_lightmap_d32s8_7x5`). That is a valid gtest name (a C++
//! identifier each side of the dot), it holds none of the characters a `--gtest_filter` gives a
//! meaning to (`-`, `:`, `*`, `?`, `.`), and deqp-runner's list parser, which takes any line
//! with a dot for a group, reads it back. The mapping is one-to-one over the cases a run
//! selects or it is refused ([`GtestNames::new`] names the two cases that would share a name),
//! so a baseline in either spelling serves both runners.

use std::collections::HashMap;

/// `text` with every character but an ASCII letter or digit written `_`.
fn identifier(text: &str) -> String {
    text.chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect()
}

/// The gtest name of case `case` of the scene whose file name is `scene_file`.
pub fn test_name(scene_file: &str, case: &str) -> String {
    format!("{}.{}", identifier(scene_file), identifier(case))
}

/// The selected cases' gtest names, both ways, in the order given.
#[derive(Debug, Default)]
pub struct GtestNames {
    /// `(gtest name, scene/case)` in the run's order.
    order: Vec<(String, String)>,
    by_gtest: HashMap<String, String>,
    by_full: HashMap<String, String>,
}

impl GtestNames {
    /// The names of `cases`, each `(scene file name, scene/case name, case name)`; refused
    /// where two cases would share a gtest name (two scenes `a-b` and `a_b`, say).
    pub fn new<'a>(
        cases: impl IntoIterator<Item = (&'a str, &'a str, &'a str)>,
    ) -> Result<GtestNames, String> {
        let mut names = GtestNames::default();
        for (scene_file, full, case) in cases {
            let gtest = test_name(scene_file, case);
            if let Some(other) = names.by_gtest.get(&gtest) {
                return Err(format!(
                    "`{other}` and `{full}` would both be the gtest test `{gtest}`: rename one \
                     scene's file (a gtest name keeps letters and digits only)"
                ));
            }
            names.by_gtest.insert(gtest.clone(), full.to_owned());
            names.by_full.insert(full.to_owned(), gtest.clone());
            names.order.push((gtest, full.to_owned()));
        }
        Ok(names)
    }

    /// `scene/case` of a gtest name.
    pub fn full_name(&self, gtest: &str) -> Option<&str> {
        self.by_gtest.get(gtest).map(String::as_str)
    }

    /// The gtest name of `scene/case`.
    pub fn gtest_name(&self, full: &str) -> Option<&str> {
        self.by_full.get(full).map(String::as_str)
    }

    /// Every case as `(gtest name, scene/case)`, in the run's order.
    pub fn iter(&self) -> impl Iterator<Item = (&str, &str)> {
        self.order.iter().map(|(g, f)| (g.as_str(), f.as_str()))
    }

    /// `--gtest_list_tests`' output for the cases `keep` holds (by `scene/case`): a line
    /// `Group.` where the group changes, then each test indented by two spaces, in the run's
    /// order (no other line: deqp-runner refuses any).
    pub fn list_text(&self, keep: &dyn Fn(&str) -> bool) -> String {
        let mut text = String::new();
        let mut group = None;
        for (gtest, _) in self.order.iter().filter(|(_, full)| keep(full)) {
            let (g, name) = gtest.split_once('.').unwrap_or(("", gtest));
            if group != Some(g) {
                text.push_str(g);
                text.push_str(".\n");
                group = Some(g);
            }
            text.push_str("  ");
            text.push_str(name);
            text.push('\n');
        }
        text
    }

    /// The `scene/case` names `filter` selects, in the run's order.
    pub fn select(&self, filter: &GtestFilter) -> Vec<&str> {
        self.order
            .iter()
            .filter(|(gtest, _)| filter.matches(gtest))
            .map(|(_, full)| full.as_str())
            .collect()
    }
}

/// A `--gtest_filter`, as googletest reads it: `POSITIVE[-NEGATIVE]`, each a `:`-separated list
/// of patterns where `*` matches any run of characters and `?` any one; a test runs when it
/// matches a positive pattern (an empty positive part is `*`) and no negative one.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GtestFilter {
    positive: Vec<String>,
    negative: Vec<String>,
}

impl GtestFilter {
    pub fn parse(text: &str) -> GtestFilter {
        let (positive, negative) = text.split_once('-').unwrap_or((text, ""));
        let patterns = |part: &str| -> Vec<String> {
            part.split(':')
                .filter(|p| !p.is_empty())
                .map(str::to_owned)
                .collect()
        };
        let mut positive = patterns(positive);
        if positive.is_empty() {
            positive.push("*".into());
        }
        GtestFilter {
            positive,
            negative: patterns(negative),
        }
    }

    pub fn matches(&self, name: &str) -> bool {
        self.positive.iter().any(|p| glob(p, name)) && !self.negative.iter().any(|p| glob(p, name))
    }
}

/// googletest's wildcard match: `*` any run (empty included), `?` any one character.
fn glob(pattern: &str, name: &str) -> bool {
    let (p, n): (Vec<char>, Vec<char>) = (pattern.chars().collect(), name.chars().collect());
    // The classic two-pointer match with one backtrack point for the last `*`.
    let (mut i, mut j) = (0, 0);
    let mut star: Option<(usize, usize)> = None;
    while j < n.len() {
        if i < p.len() && (p[i] == '?' || p[i] == n[j]) {
            i += 1;
            j += 1;
        } else if i < p.len() && p[i] == '*' {
            star = Some((i, j));
            i += 1;
        } else if let Some((si, sj)) = star {
            i = si + 1;
            j = sj + 1;
            star = Some((si, sj + 1));
        } else {
            return false;
        }
    }
    p[i..].iter().all(|&c| c == '*')
}

/// How a test ended, as googletest prints it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GtestStatus {
    Ok,
    Failed,
    Skipped,
}

/// The line that starts test `name`.
pub fn run_line(name: &str) -> String {
    format!("[ RUN      ] {name}")
}

/// The line that ends test `name` after `millis`.
pub fn end_line(status: GtestStatus, name: &str, millis: u64) -> String {
    let tag = match status {
        GtestStatus::Ok => "[       OK ]",
        GtestStatus::Failed => "[  FAILED  ]",
        GtestStatus::Skipped => "[  SKIPPED ]",
    };
    format!("{tag} {name} ({millis} ms)")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_identifiers_and_map_back() {
        let cases = [
            (
                "brdfs-1",
                "brdfs-1/stencil-ps3-auto-pA0-lightmap-d32s8-7x5",
                "stencil-ps3-auto-pA0-lightmap-d32s8-7x5",
            ),
            (
                "My_Model",
                "models/My_Model.gltf/tiled-p00-d32s8-1x1",
                "tiled-p00-d32s8-1x1",
            ),
        ];
        let names = GtestNames::new(cases).unwrap();
        assert_eq!(
            names.gtest_name("brdfs-1/stencil-ps3-auto-pA0-lightmap-d32s8-7x5"),
            Some("brdfs_1.stencil_ps3_auto_pA0_lightmap_d32s8_7x5")
        );
        assert_eq!(
            names.full_name("My_Model.tiled_p00_d32s8_1x1"),
            Some("models/My_Model.gltf/tiled-p00-d32s8-1x1")
        );
        for (gtest, _) in &names.order {
            let (group, name) = gtest.split_once('.').unwrap();
            for part in [group, name] {
                assert!(
                    part.chars().all(|c| c.is_ascii_alphanumeric() || c == '_'),
                    "{gtest}"
                );
            }
        }
        assert_eq!(
            names.list_text(&|full| !full.contains("nothing")),
            names.list_text(&|_| true)
        );
        assert_eq!(
            names.list_text(&|_| true),
            "brdfs_1.\n  stencil_ps3_auto_pA0_lightmap_d32s8_7x5\nMy_Model.\n  tiled_p00_d32s8_1x1\n"
        );
    }

    #[test]
    fn two_cases_that_would_share_a_name_are_refused_by_name() {
        let cases = [("a-b", "a-b/x-1", "x-1"), ("a_b", "a_b/x-1", "x-1")];
        let err = GtestNames::new(cases).unwrap_err();
        assert!(err.contains("`a-b/x-1` and `a_b/x-1`"), "{err}");
    }

    #[test]
    fn filters_read_as_googletest_reads_them() {
        let f = GtestFilter::parse("default.*:town.tiled_p00_d32s8_1x1");
        assert!(f.matches("default.stencil_native_p00_d32s8_1x1"));
        assert!(f.matches("town.tiled_p00_d32s8_1x1"));
        assert!(!f.matches("town.tiled_p00_d32s8_7x5"));
        let f = GtestFilter::parse("-*_1x1");
        assert!(f.matches("default.a_7x5") && !f.matches("default.a_1x1"));
        let f = GtestFilter::parse("*.stencil_?s3*-*d24s8*");
        assert!(f.matches("x.stencil_ps3_auto_d32s8") && !f.matches("x.stencil_ps3_auto_d24s8"));
        assert!(!f.matches("x.stencil_native"));
        // deqp-runner's own form: exact names joined by `:`.
        let f = GtestFilter::parse("g.a:g.b");
        assert!(f.matches("g.a") && f.matches("g.b") && !f.matches("g.ab"));
        assert!(glob("*", "") && glob("a*b*c", "aXbYc") && !glob("a*b", "aXc"));
    }

    #[test]
    fn lines_are_the_ones_deqp_runner_parses() {
        assert_eq!(run_line("g.a"), "[ RUN      ] g.a");
        assert_eq!(
            end_line(GtestStatus::Ok, "g.a", 12),
            "[       OK ] g.a (12 ms)"
        );
        assert_eq!(
            end_line(GtestStatus::Failed, "g.a", 1),
            "[  FAILED  ] g.a (1 ms)"
        );
        assert_eq!(
            end_line(GtestStatus::Skipped, "g.a", 0),
            "[  SKIPPED ] g.a (0 ms)"
        );
    }
}
