//! What an engine's BRDF GLSL may `#include`: the folder's own files and histencil's includes,
//! nothing else. The manifest's own paths are confined to the folder (`BrdfSet::load`); an
//! `#include "../../etc/hostname"` at the top of a BRDF file would otherwise hand any file the
//! process can read to glslc (whose refusal then quotes it). Held before anything is compiled.

use crate::manifest::ManifestError;
use std::path::{Path, PathBuf};

/// The path an `#include` line names (`"path"` or `<path>`), if the line is one.
fn included(line: &str) -> Option<&str> {
    let rest = line.trim_start().strip_prefix('#')?.trim_start();
    let rest = rest.strip_prefix("include")?.trim_start();
    let close = match rest.chars().next()? {
        '"' => '"',
        '<' => '>',
        _ => return None,
    };
    let inner = &rest[1..];
    inner.find(close).map(|end| &inner[..end])
}

/// Checks every `#include` of `file` (inside `folder`, canonical) and of the folder's files it
/// includes: each names a path confined by name (no `..`, nothing absolute) and, where that
/// path is a file beside the including one, it is inside the folder (a link out is refused).
/// A confined name that is no file of the folder is left to histencil's include directories,
/// which glslc searches after the folder. `seen` stops include cycles.
pub(crate) fn check_includes(
    folder: &Path,
    file: &Path,
    seen: &mut Vec<PathBuf>,
) -> Result<(), ManifestError> {
    if seen.iter().any(|s| s == file) {
        return Ok(());
    }
    seen.push(file.to_owned());
    let text = std::fs::read_to_string(file).map_err(|error| ManifestError::Io {
        path: file.to_owned(),
        error,
    })?;
    let at = |line: usize, message: String| ManifestError::At {
        path: file.to_owned(),
        line,
        message,
    };
    for (index, line) in text.lines().enumerate() {
        let Some(path) = included(line) else {
            continue;
        };
        if !crate::set::is_confined(path) {
            return Err(at(
                index + 1,
                format!(
                    "`#include \"{path}\"` reaches outside the BRDF folder: a BRDF's GLSL may \
                     include the folder's own files and histencil's (relative paths without `..`)"
                ),
            ));
        }
        let beside = file.parent().unwrap_or(folder).join(path);
        if let Ok(real) = beside.canonicalize() {
            if !real.starts_with(folder) {
                return Err(at(
                    index + 1,
                    format!(
                        "`#include \"{path}\"` is a link to {}, outside the BRDF folder",
                        real.display()
                    ),
                ));
            }
            if real.is_file() {
                check_includes(folder, &real, seen)?;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn include_lines_are_read_as_glslc_reads_them() {
        assert_eq!(included("#include \"a.glsl\""), Some("a.glsl"));
        assert_eq!(
            included("  #  include <brdf/common.glsl> // x"),
            Some("brdf/common.glsl")
        );
        assert_eq!(included("#define include \"x\""), None);
        assert_eq!(included("// #include \"x\""), None);
    }

    #[test]
    fn includes_out_of_the_folder_are_refused_naming_file_and_line() {
        let dir = std::env::temp_dir().join(format!("histencil-includes-{}", std::process::id()));
        let outside = dir.join("outside");
        let folder = dir.join("brdfs");
        std::fs::create_dir_all(&outside).unwrap();
        std::fs::create_dir_all(folder.join("sub")).unwrap();
        std::fs::write(outside.join("secret.glsl"), "").unwrap();
        std::fs::write(
            folder.join("sub/ok.glsl"),
            "#include \"../../outside/secret.glsl\"\n",
        )
        .unwrap();
        let folder = folder.canonicalize().unwrap();
        let cases = [
            (
                "#include \"../../../../../etc/hostname\"\n",
                1,
                "reaches outside",
            ),
            ("// fine\n#include </etc/hostname>\n", 2, "reaches outside"),
            ("#include \"sub/ok.glsl\"\n", 1, "reaches outside"),
        ];
        for (text, line, words) in cases {
            let file = folder.join("toon.glsl");
            std::fs::write(&file, text).unwrap();
            let e = check_includes(&folder, &file, &mut Vec::new())
                .unwrap_err()
                .to_string();
            assert!(
                e.contains(&format!(":{line}: ")) && e.contains(words),
                "{e}"
            );
        }
        std::os::unix::fs::symlink(outside.join("secret.glsl"), folder.join("link.glsl")).unwrap();
        let file = folder.join("toon.glsl");
        std::fs::write(
            &file,
            "#include \"link.glsl\"\n#include \"brdf/common.glsl\"\n",
        )
        .unwrap();
        let e = check_includes(&folder, &file, &mut Vec::new())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(":1: ") && e.contains("outside the BRDF folder"),
            "{e}"
        );
        std::fs::write(
            &file,
            "#include \"brdf/common.glsl\"\n#include \"toon.glsl\"\n",
        )
        .unwrap();
        check_includes(&folder, &file, &mut Vec::new()).expect("histencil's includes and a cycle");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
