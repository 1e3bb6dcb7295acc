//! An engine's BRDF folder: `brdfs.toml` and the GLSL files it names, the folder the command line
//! takes (`--brdfs DIR`) and an engine's build script hands histencil-build. One `[[brdf]]` table
//! per BRDF:
//!
//! ```toml
//! builtins = ["lambert", "ggx"]  # the built-ins kept beside them; all eight if left out
//!
//! [[brdf]]
//! name = "toon"                  # in glTF extras: {"brdf": "toon", "bands": 4}
//! glsl = "toon.glsl"             # inside this folder
//! function = "toon"              # vec3 toon(vec4 p, vec3 N, vec3 T, vec3 V, vec3 L); the name if left out
//! white = "toon_rim"             # optional: float toon_rim(vec4 p, vec3 N, vec3 T, vec3 V, vec3 L)
//! tangent = false                # whether it reads T
//! tint = false                   # whether the function takes the colour: vec3 toon(vec4 p, vec3 tint, vec3 N, vec3 T, vec3 V, vec3 L)
//! params = [{ name = "bands", min = 1, max = 8, default = 3 }]
//! ```
//!
//! Every mistake is refused with the manifest's path and line before anything is compiled.

use std::path::{Path, PathBuf};

use toml_edit::{Document, Item, TableLike};

use crate::id::BrdfId;
use crate::model::Range;
use crate::set::{BrdfSet, EngineBrdfSpec, EngineParam, SetError};

/// The manifest's file name inside a BRDF folder.
pub const MANIFEST: &str = "brdfs.toml";

/// Why a BRDF folder was refused.
#[derive(Debug, thiserror::Error)]
pub enum ManifestError {
    /// The folder or a file in it could not be read.
    #[error("{path}: {error}")]
    Io {
        /// The path read.
        path: PathBuf,
        /// What the system said.
        error: std::io::Error,
    },
    /// The manifest is not valid TOML (the parser's message gives its line and column).
    #[error("{path}: not valid TOML: {message}")]
    Toml {
        /// The manifest.
        path: PathBuf,
        /// The parser's message.
        message: String,
    },
    /// A key missing, of the wrong type or unknown, or a declaration the set refuses.
    #[error("{path}:{line}: {message}")]
    At {
        /// The manifest.
        path: PathBuf,
        /// The line of the table or key at fault (1-based).
        line: usize,
        /// What is wrong.
        message: String,
    },
}

/// What one key of a table is read as.
struct Table<'a> {
    table: &'a dyn TableLike,
    text: &'a str,
    path: &'a Path,
    line: usize,
}

impl<'a> Table<'a> {
    fn new(
        table: &'a dyn TableLike,
        span: Option<std::ops::Range<usize>>,
        text: &'a str,
        path: &'a Path,
        fallback: usize,
    ) -> Self {
        let line = span.map_or(fallback, |span| line_of(text, span.start));
        Self {
            table,
            text,
            path,
            line,
        }
    }

    fn error(&self, line: usize, message: String) -> ManifestError {
        ManifestError::At {
            path: self.path.to_owned(),
            line,
            message,
        }
    }

    fn line_of_key(&self, key: &str) -> usize {
        self.table
            .get(key)
            .and_then(Item::span)
            .map_or(self.line, |span| line_of(self.text, span.start))
    }

    /// Refuses a key outside `known`, naming the ones accepted.
    fn only(&self, what: &str, known: &[&str]) -> Result<(), ManifestError> {
        for (key, _) in self.table.iter() {
            if !known.contains(&key) {
                return Err(self.error(
                    self.line_of_key(key),
                    format!(
                        "{what}: unknown key `{key}` (accepted: {})",
                        known.join(", ")
                    ),
                ));
            }
        }
        Ok(())
    }

    fn string(&self, key: &str) -> Result<Option<String>, ManifestError> {
        match self.table.get(key) {
            None => Ok(None),
            Some(item) => item.as_str().map(|s| Some(s.to_owned())).ok_or_else(|| {
                self.error(self.line_of_key(key), format!("`{key}` must be a string"))
            }),
        }
    }

    fn required_string(&self, what: &str, key: &str) -> Result<String, ManifestError> {
        self.string(key)?
            .ok_or_else(|| self.error(self.line, format!("{what}: `{key}` is missing")))
    }

    fn number(&self, what: &str, key: &str) -> Result<f64, ManifestError> {
        let item = self
            .table
            .get(key)
            .ok_or_else(|| self.error(self.line, format!("{what}: `{key}` is missing")))?;
        item.as_float()
            .or_else(|| item.as_integer().map(|i| i as f64))
            .ok_or_else(|| {
                self.error(
                    self.line_of_key(key),
                    format!("{what}: `{key}` must be a number"),
                )
            })
    }

    fn bool(&self, key: &str) -> Result<bool, ManifestError> {
        match self.table.get(key) {
            None => Ok(false),
            Some(item) => item.as_bool().ok_or_else(|| {
                self.error(
                    self.line_of_key(key),
                    format!("`{key}` must be true or false"),
                )
            }),
        }
    }

    /// The tables of an array of tables or of an inline array of inline tables.
    fn tables(&self, key: &str) -> Result<Vec<Table<'a>>, ManifestError> {
        let Some(item) = self.table.get(key) else {
            return Ok(Vec::new());
        };
        let line = self.line_of_key(key);
        let (text, path) = (self.text, self.path);
        if let Some(array) = item.as_array_of_tables() {
            return Ok(array
                .iter()
                .map(|t| Table::new(t as &dyn TableLike, t.span(), text, path, line))
                .collect());
        }
        let bad = || self.error(line, format!("`{key}` must be a list of tables"));
        let array = item.as_array().ok_or_else(bad)?;
        array
            .iter()
            .map(|v| {
                v.as_inline_table()
                    .map(|t| Table::new(t as &dyn TableLike, t.span(), text, path, line))
                    .ok_or_else(bad)
            })
            .collect()
    }
}

/// The 1-based line of byte `offset` in `text`.
fn line_of(text: &str, offset: usize) -> usize {
    text.as_bytes()[..offset.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

fn read_spec(t: &Table<'_>) -> Result<EngineBrdfSpec, ManifestError> {
    let name = t.required_string("[[brdf]]", "name")?;
    let what = format!("BRDF `{name}`");
    t.only(
        &what,
        &[
            "name", "glsl", "function", "white", "tangent", "tint", "params",
        ],
    )?;
    let mut params = Vec::new();
    for p in t.tables("params")? {
        let param = p.required_string(&what, "name")?;
        let what = format!("{what}, parameter `{param}`");
        p.only(&what, &["name", "min", "max", "default"])?;
        params.push(EngineParam {
            range: Range::new(p.number(&what, "min")?, p.number(&what, "max")?),
            default: p.number(&what, "default")?,
            name: param,
        });
    }
    Ok(EngineBrdfSpec {
        glsl: t.required_string(&what, "glsl")?,
        function: t.string("function")?.unwrap_or_else(|| name.clone()),
        white: t.string("white")?,
        tangent: t.bool("tangent")?,
        tint: t.bool("tint")?,
        params,
        name,
    })
}

impl BrdfSet {
    /// Reads the BRDF folder `dir`: its [`MANIFEST`] and the GLSL files it names, each of which
    /// must be a file inside `dir` (a path through `..` or a link out of it is refused, as glTF's
    /// paths are).
    ///
    /// # Errors
    /// [`ManifestError`]: an unreadable folder or manifest, invalid TOML (its line), a key
    /// missing, unknown or of the wrong type, any declaration [`BrdfSet::new`] refuses, a GLSL
    /// file missing or outside the folder; each with the manifest's path and line.
    pub fn load(dir: &Path) -> Result<BrdfSet, ManifestError> {
        let io = |path: &Path| {
            let path = path.to_owned();
            move |error| ManifestError::Io { path, error }
        };
        let folder = dir.canonicalize().map_err(io(dir))?;
        let path = dir.join(MANIFEST);
        let text = std::fs::read_to_string(&path).map_err(io(&path))?;
        let doc = Document::parse(text.as_str()).map_err(|e| ManifestError::Toml {
            path: path.clone(),
            message: e.to_string().trim_end().to_owned(),
        })?;
        let root = Table::new(doc.as_table() as &dyn TableLike, None, &text, &path, 1);
        root.only("brdfs.toml", &["builtins", "brdf"])?;
        let builtins = match root.table.get("builtins") {
            None => BrdfId::ALL.to_vec(),
            Some(item) => {
                let line = root.line_of_key("builtins");
                let names = item
                    .as_array()
                    .ok_or_else(|| root.error(line, "`builtins` must be a list of names".into()))?;
                names
                    .iter()
                    .map(|v| {
                        let name = v.as_str().ok_or_else(|| {
                            root.error(line, "`builtins` must be a list of names".into())
                        })?;
                        name.parse::<BrdfId>()
                            .map_err(|e| root.error(line, format!("`builtins`: {e}")))
                    })
                    .collect::<Result<_, _>>()?
            }
        };
        let tables = root.tables("brdf")?;
        let mut specs = Vec::new();
        for t in &tables {
            let spec = read_spec(t)?;
            let glsl = folder.join(&spec.glsl);
            // Confined by name first (no `..`, nothing absolute), then by what the name leads
            // to: a link inside the folder may point out of it.
            let inside = crate::set::is_confined(&spec.glsl)
                && glsl
                    .canonicalize()
                    .is_ok_and(|real| real.starts_with(&folder) && real.is_file());
            if crate::set::is_confined(&spec.glsl) && !glsl.exists() {
                return Err(t.error(
                    t.line_of_key("glsl"),
                    format!(
                        "BRDF `{}`: GLSL file {} does not exist",
                        spec.name,
                        glsl.display()
                    ),
                ));
            }
            if !inside {
                let e = SetError::OutsideFolder {
                    brdf: spec.name.clone(),
                    path: spec.glsl.clone(),
                };
                return Err(t.error(t.line_of_key("glsl"), e.to_string()));
            }
            // What the file includes is confined too, before anything reaches glslc.
            let real = glsl.canonicalize().map_err(io(&glsl))?;
            crate::includes::check_includes(&folder, &real, &mut Vec::new())?;
            specs.push(spec);
        }
        BrdfSet::new(&builtins, specs)
            .map(|set| set.with_folder(folder))
            .map_err(|e| {
                // The table of the BRDF the error names, else the manifest's first line.
                let line = tables
                    .iter()
                    .find(|t| {
                        t.string("name")
                            .ok()
                            .flatten()
                            .is_some_and(|n| e.to_string().contains(&format!("`{n}`")))
                    })
                    .map_or(1, |t| t.line);
                root.error(line, e.to_string())
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn folder(manifest: &str, files: &[&str]) -> tempdir::Dir {
        let dir = tempdir::Dir::new();
        std::fs::write(dir.0.join(MANIFEST), manifest).unwrap();
        for f in files {
            std::fs::write(
                dir.0.join(f),
                "vec3 toon(vec4 p, vec3 N, vec3 T, vec3 V, vec3 L) { return vec3(0.0); }\n",
            )
            .unwrap();
        }
        dir
    }

    mod tempdir {
        /// A fresh folder under the system's temporary one, removed on drop.
        pub struct Dir(pub std::path::PathBuf);
        impl Dir {
            pub fn new() -> Self {
                use std::sync::atomic::{AtomicUsize, Ordering};
                static N: AtomicUsize = AtomicUsize::new(0);
                let path = std::env::temp_dir().join(format!(
                    "histencil-brdfs-{}-{}",
                    std::process::id(),
                    N.fetch_add(1, Ordering::Relaxed)
                ));
                std::fs::create_dir_all(&path).unwrap();
                Self(path)
            }
        }
        impl Drop for Dir {
            fn drop(&mut self) {
                let _ = std::fs::remove_dir_all(&self.0);
            }
        }
    }

    const TOON: &str = "builtins = [\"ggx\"]\n\n[[brdf]]\nname = \"toon\"\nglsl = \"toon.glsl\"\nparams = [{ name = \"bands\", min = 1, max = 8, default = 3 }]\n";

    #[test]
    fn a_folder_loads_with_its_builtins_and_parameters() {
        let dir = folder(TOON, &["toon.glsl"]);
        let set = BrdfSet::load(&dir.0).unwrap();
        assert_eq!(set.builtins(), &[BrdfId::Ggx]);
        let (_, spec) = set.engine().next().unwrap();
        assert_eq!(spec.function, "toon");
        assert_eq!(spec.params[0].default, 3.0);
        assert_eq!(set.folder(), Some(dir.0.canonicalize().unwrap().as_path()));
        // The table form of the parameters reads the same.
        let tables = "[[brdf]]\nname = \"toon\"\nglsl = \"toon.glsl\"\n[[brdf.params]]\nname = \"bands\"\nmin = 1\nmax = 8\ndefault = 3\n";
        let dir = folder(tables, &["toon.glsl"]);
        let other = BrdfSet::load(&dir.0).unwrap();
        assert_eq!(other.engine().next().unwrap().1, spec);
        assert_eq!(other.builtins().len(), 8);
    }

    /// Each bad folder: its message names the file and the line, and says what is wrong.
    #[test]
    fn every_bad_folder_is_refused_with_path_and_line() {
        let cases: &[(&str, &[&str], &str)] = &[
            ("[[brdf]\nname = 1", &[], "brdfs.toml: not valid TOML"),
            ("[[brdf]]\nname = \"toon\"\nglsl = \"toon.glsl\"\n", &[], "brdfs.toml:3: BRDF `toon`: GLSL file"),
            ("[[brdf]]\nname = \"toon\"\nglsl = \"../toon.glsl\"\n", &[], ":3: BRDF `toon`: `../toon.glsl` must be a relative path inside"),
            ("[[brdf]]\nname = \"toon\"\nglsl = \"/etc/passwd\"\n", &[], ":3: BRDF `toon`: `/etc/passwd` must be a relative path"),
            ("[[brdf]]\nname = \"toon\"\nglsl = \"toon.glsl\"\n[[brdf]]\nname = \"toon\"\nglsl = \"toon.glsl\"\n", &["toon.glsl"], ":1: BRDF `toon` is named twice"),
            ("[[brdf]]\nname = \"lambert\"\nglsl = \"toon.glsl\"\n", &["toon.glsl"], ":1: BRDF `lambert` has a built-in's name"),
            ("[[brdf]]\nname = \"toon\"\nglsl = \"toon.glsl\"\nshiny = true\n", &["toon.glsl"], ":4: BRDF `toon`: unknown key `shiny`"),
            ("[[brdf]]\nname = \"toon\"\nglsl = \"toon.glsl\"\nparams = [{ name = \"x\", min = 0, max = 1, default = 2 }]\n", &["toon.glsl"], "parameter `x`: default 2 is outside its range [0, 1]"),
            ("[[brdf]]\nname = \"toon\"\nglsl = \"toon.glsl\"\nparams = [{ name = \"x\", min = 0, max = 1 }]\n", &["toon.glsl"], ":4: BRDF `toon`, parameter `x`: `default` is missing"),
            ("[[brdf]]\nglsl = \"toon.glsl\"\n", &["toon.glsl"], ":1: [[brdf]]: `name` is missing"),
            ("builtins = [\"phong\"]\n", &[], ":1: `builtins`: unknown BRDF `phong`"),
            ("builtins = []\n", &[], "empty"),
        ];
        for (manifest, files, expected) in cases {
            let dir = folder(manifest, files);
            let err = BrdfSet::load(&dir.0).unwrap_err().to_string();
            assert!(err.contains(expected), "{manifest:?}: {err}");
            assert!(err.contains("brdfs.toml"), "{manifest:?}: {err}");
        }
        // No folder, no manifest.
        let dir = tempdir::Dir::new();
        let err = BrdfSet::load(&dir.0).unwrap_err().to_string();
        assert!(err.contains("brdfs.toml"), "{err}");
        let err = BrdfSet::load(&dir.0.join("none")).unwrap_err().to_string();
        assert!(err.contains("none"), "{err}");
    }

    /// A link inside the folder to a file outside it is refused, as `..` is.
    #[cfg(unix)]
    #[test]
    fn a_link_out_of_the_folder_is_refused() {
        let outside = tempdir::Dir::new();
        std::fs::write(outside.0.join("secret.glsl"), "").unwrap();
        let dir = folder("[[brdf]]\nname = \"toon\"\nglsl = \"toon.glsl\"\n", &[]);
        std::os::unix::fs::symlink(outside.0.join("secret.glsl"), dir.0.join("toon.glsl")).unwrap();
        let err = BrdfSet::load(&dir.0).unwrap_err().to_string();
        assert!(err.contains("inside the BRDF folder"), "{err}");
    }
}
