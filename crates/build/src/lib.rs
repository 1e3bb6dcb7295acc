//! Compiles histencil's light shaders with an engine's shader hooks, from the engine's build
//! script.
//!
//! histencil's deferred light shaders read each pixel's surface through a *decode hook* and
//! scale each light by a *visibility hook* (`crates/vk/shaders/hooks/`: histencil's own G-buffer,
//! and no shadows). An engine with its own G-buffer layout or its own shadows writes either file
//! itself, `surface_decode.glsl` and/or `light_visibility.glsl`, in a folder of its own, and its
//! `build.rs` calls [`compile_light_shaders`]:
//!
//! ```no_run
//! // build.rs of an engine that depends on histencil (directly: cargo hands its shader folders
//! // only to the build scripts of direct dependents).
//! let out = std::path::PathBuf::from(std::env::var("OUT_DIR").unwrap());
//! histencil_build::compile_light_shaders("shaders/histencil_hooks".as_ref(), &out)
//!     .unwrap_or_else(|e| panic!("{e}"));
//! // main.rs, with histencil::LightModules in scope:
//! // const LIGHT_MODULES: LightModules =
//! //     include!(concat!(env!("OUT_DIR"), "/histencil_light_modules.rs"));
//! ```
//!
//! An engine with shading models of its own declares them as a [`BrdfSet`] (in code, or read
//! from a folder with `brdfs.toml` by `brdf_folder` with the feature `files`) and compiles the light
//! shaders with them by [`compile_light_shaders_for`]: every technique then evaluates its
//! functions. [`write_brdf_set`] gives the include folder for the engine's own shaders that
//! include histencil's `light.glsl` (a forward pass, say) or need the set's ids (a G-buffer pass:
//! `brdf_set/ids.glsl`).
//!
//! Why at build time and not at run time: histencil already compiles its shaders with `glslc`
//! at build time, so an engine needs no new tool, links no shader compiler into its binary
//! (linking shaderc needs per-distribution link flags; see histencil-vk's build script), and a
//! mistake in a hook is a build error naming the engine's file and line, not a run-time failure.
//! An engine that generates hooks at run time can run the same `glslc` command and hand the
//! SPIR-V to `histencil::LightModules` itself.

#![warn(missing_docs)]

use std::fmt;
use std::path::{Path, PathBuf};
use std::process::Command;

pub use histencil_brdf::BrdfSet;

/// The options every histencil shader is compiled with: Vulkan 1.3 semantics and SPIR-V 1.3 (from
/// 1.4 glslang copies structs out of buffers with OpCopyLogical, which naga's SPIR-V reader, the
/// check histencil-vk runs on its own modules, does not parse); warnings are errors.
pub const GLSLC_OPTIONS: [&str; 4] = [
    "--target-env=vulkan1.3",
    "--target-spv=spv1.3",
    "-O0",
    "-Werror",
];

/// The hook files an engine may supply; a file its folder lacks is histencil's.
pub const HOOK_FILES: [&str; 2] = ["surface_decode.glsl", "light_visibility.glsl"];

/// A shader stage histencil compiles again for an engine: for its hooks, its BRDFs, or both.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Stage {
    /// The file under histencil's `shaders/`; its stem is the module's field name
    /// ([`Stage::field`]) in `LightModules` (a hooked stage) or `BrdfModules` (the others).
    pub file: &'static str,
    /// It calls the decode and visibility hooks: a light shader, compiled per engine's hooks
    /// into `LightModules`.
    pub hooked: bool,
    /// It evaluates a BRDF (includes `brdf/eval.glsl`): compiled per BRDF set.
    pub evaluates_brdf: bool,
}

impl Stage {
    /// The module's field name: the file's stem (`deferred_light` of `deferred_light.frag`).
    pub fn field(&self) -> &'static str {
        self.file.split('.').next().unwrap_or(self.file)
    }
}

/// Every stage compiled per engine, once: [`HOOKED_STAGES`], [`BRDF_STAGES`], the fields of the
/// generated `LightModules` and `BrdfModules` expressions and histencil's run-time compile all
/// come from this table. A stage added here is compiled into both wherever it belongs; its
/// field must exist in the struct its flags put it in: a build script's generated expression
/// does not compile otherwise, and histencil-vk's tests hold its run-time assembly of the
/// modules to this table.
pub const STAGES: [Stage; 14] = {
    const fn stage(file: &'static str, hooked: bool, evaluates_brdf: bool) -> Stage {
        Stage {
            file,
            hooked,
            evaluates_brdf,
        }
    }
    [
        stage("deferred_light.frag", true, true),
        stage("lut_light.frag", true, true),
        stage("tile_classify.comp", true, false),
        stage("tile_shade.comp", true, true),
        stage("tile_classify_8.comp", true, false),
        stage("tile_shade_8.comp", true, true),
        stage("depth_id_copy.frag", true, false),
        stage("depth_id_shade.frag", true, true),
        stage("forward.frag", false, true),
        stage("lightmap.frag", false, true),
        stage("lightmap_directional.frag", false, true),
        stage("alpha_object.frag", false, true),
        stage("particle.frag", false, true),
        stage("brdf_eval.comp", false, true),
    ]
};

/// Which of the [`STAGES`] a list holds.
#[derive(Clone, Copy)]
enum Select {
    Hooked,
    EvaluatesBrdf,
}

/// The files of the [`STAGES`] `select` names, in the table's order (a const fn: the lists
/// below are consts of the table, not copies of it; `N` is checked against the table).
const fn files<const N: usize>(select: Select) -> [&'static str; N] {
    let mut out = [""; N];
    let (mut i, mut n) = (0, 0);
    while i < STAGES.len() {
        let s = STAGES[i];
        let keep = match select {
            Select::Hooked => s.hooked,
            Select::EvaluatesBrdf => s.evaluates_brdf,
        };
        if keep {
            out[n] = s.file;
            n += 1;
        }
        i += 1;
    }
    assert!(n == N, "the list's length is not its count in STAGES");
    out
}

/// The light shaders that call the hooks, compiled per engine ([`STAGES`] that are hooked).
pub const HOOKED_STAGES: [&str; 8] = files(Select::Hooked);

/// Why the light shaders could not be compiled.
#[derive(Debug)]
pub enum BuildError {
    /// A `DEP_HISTENCIL_*` variable is missing: the calling build script's package does not
    /// depend on histencil or histencil-vk directly.
    NotADependent(&'static str),
    /// The hook folder holds neither hook file: nothing would change.
    NoHooks(PathBuf),
    /// `glslc` could not be run.
    NoGlslc(String),
    /// The engine's BRDF folder or set was refused (the manifest's path and line), or one of
    /// its GLSL files could not be read.
    Brdfs(String),
    /// `glslc` rejected a stage compiled with the hooks or a BRDF set (one of [`STAGES`]).
    Compile {
        /// The stage's file name.
        stage: String,
        /// glslc's error output, which names the hook file and line at fault.
        message: String,
    },
    /// Writing the outputs failed.
    Io(String),
}

impl fmt::Display for BuildError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BuildError::NotADependent(var) => write!(
                f,
                "DEP_HISTENCIL_{var} is not set: call histencil_build from the build script of a \
                 package that depends on histencil (or histencil-vk) directly"
            ),
            BuildError::NoHooks(dir) => write!(
                f,
                "{} holds neither {} nor {}: nothing to compile",
                dir.display(),
                HOOK_FILES[0],
                HOOK_FILES[1]
            ),
            BuildError::NoGlslc(e) => write!(
                f,
                "histencil compiles shaders with glslc, which could not be run ({e}); install it \
                 (Debian and Ubuntu: `apt install glslc`, elsewhere the Vulkan SDK) or point \
                 HISTENCIL_GLSLC at it"
            ),
            BuildError::Compile { stage, message } => {
                write!(
                    f,
                    "glslc failed on {stage} with the engine's hooks and BRDFs:\n{message}"
                )
            }
            BuildError::Brdfs(e) => write!(f, "{e}"),
            BuildError::Io(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for BuildError {}

/// The `glslc` to run: `HISTENCIL_GLSLC`, or the one on `PATH`.
pub fn glslc() -> PathBuf {
    std::env::var_os("HISTENCIL_GLSLC")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("glslc"))
}

/// A `glslc` command compiling `source` to `out` with [`GLSLC_OPTIONS`], searching `includes`
/// in order after the source's own folder.
pub fn glslc_command(source: &Path, includes: &[&Path], out: &Path) -> Command {
    let mut command = Command::new(glslc());
    command.args(GLSLC_OPTIONS);
    for dir in includes {
        command.arg(format!("-I{}", dir.display()));
    }
    command.arg(source).arg("-o").arg(out);
    command
}

/// Runs `command` (from [`glslc_command`]) for `stage`.
pub fn run_glslc(mut command: Command, stage: &str) -> Result<(), BuildError> {
    let output = command
        .output()
        .map_err(|e| BuildError::NoGlslc(e.to_string()))?;
    if output.status.success() {
        Ok(())
    } else {
        Err(BuildError::Compile {
            stage: stage.to_owned(),
            message: String::from_utf8_lossy(&output.stderr).into_owned(),
        })
    }
}

/// histencil-vk's metadata `name`, as a direct dependent of histencil-vk
/// (`DEP_HISTENCIL_GLSL_*`) or of the `histencil` crate (`DEP_HISTENCIL_*`) sees it.
fn dep_var(name: &'static str) -> Result<PathBuf, BuildError> {
    [
        format!("DEP_HISTENCIL_GLSL_{name}"),
        format!("DEP_HISTENCIL_{name}"),
    ]
    .iter()
    .find_map(std::env::var_os)
    .map(PathBuf::from)
    .ok_or(BuildError::NotADependent(name))
}

/// Compiles [`HOOKED_STAGES`] with the hook files in `hook_folder` searched before histencil's
/// own, into `out_dir/histencil/`, and writes `out_dir/histencil_light_modules.rs`: a
/// `LightModules { .. }` expression holding the SPIR-V, for `include!` where `LightModules` is in
/// scope (`histencil::LightModules` or `histencil_vk::LightModules`). Tells cargo to
/// rerun when a hook file or histencil's shaders change. histencil's own BRDFs; with an
/// engine's, [`compile_light_shaders_for`].
///
/// # Errors
/// [`BuildError`]: not run from a direct dependent's build script, an empty hook folder, no
/// `glslc`, a hook that does not compile (glslc's message names the file and line), I/O.
pub fn compile_light_shaders(hook_folder: &Path, out_dir: &Path) -> Result<PathBuf, BuildError> {
    if !HOOK_FILES.iter().any(|f| hook_folder.join(f).is_file()) {
        for file in HOOK_FILES {
            println!(
                "cargo:rerun-if-changed={}",
                hook_folder.join(file).display()
            );
        }
        return Err(BuildError::NoHooks(hook_folder.to_owned()));
    }
    compile_light_shaders_for(Some(hook_folder), &BrdfSet::default(), out_dir)
}

/// Reads an engine's BRDF folder (`brdfs.toml` and the GLSL it names, as the command line's
/// `--brdfs` takes it) and tells cargo to rerun when anything in it changes.
///
/// # Errors
/// [`BuildError::Brdfs`] with the manifest's path and line.
#[cfg(feature = "files")]
pub fn brdf_folder(dir: &Path) -> Result<BrdfSet, BuildError> {
    println!("cargo:rerun-if-changed={}", dir.display());
    BrdfSet::load(dir).map_err(|e| BuildError::Brdfs(e.to_string()))
}

/// The engine's GLSL files in `folder` (any depth, `/`-separated paths, links followed only
/// inside it), which its BRDFs' files may include from one another.
pub fn engine_files(folder: &Path) -> Result<Vec<(String, PathBuf)>, BuildError> {
    fn walk(
        folder: &Path,
        dir: &Path,
        seen: &mut Vec<PathBuf>,
        out: &mut Vec<(String, PathBuf)>,
    ) -> Result<(), BuildError> {
        let entries = std::fs::read_dir(dir)
            .map_err(|e| BuildError::Brdfs(format!("{}: {e}", dir.display())))?;
        for entry in entries {
            let path = entry.map_err(|e| BuildError::Io(e.to_string()))?.path();
            let Ok(real) = path.canonicalize() else {
                continue;
            };
            if !real.starts_with(folder) {
                continue;
            }
            if real.is_dir() {
                // A folder reached twice (through links) is walked once: no cycle.
                if !seen.contains(&real) {
                    seen.push(real.clone());
                    walk(folder, &path, seen, out)?;
                }
            } else if path.extension().is_some_and(|e| e == "glsl") {
                let relative = path.strip_prefix(folder).expect("walked from the folder");
                let parts: Vec<_> = relative
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect();
                out.push((parts.join("/"), real));
            }
        }
        Ok(())
    }
    let mut out = Vec::new();
    let mut seen = vec![folder.to_owned()];
    walk(folder, folder, &mut seen, &mut out)?;
    out.sort();
    Ok(out)
}

/// The set's ids and names, comma-separated, as `LightModules::brdfs` and `brdf_names` spell
/// them: the light shaders' BRDFs by number and by name, so that a set whose id 8 is another
/// BRDF cannot take these shaders.
fn ids_and_names(set: &BrdfSet) -> (String, String) {
    let ids: Vec<String> = set.ids().iter().map(|b| b.index().to_string()).collect();
    let names: Vec<String> = set
        .ids()
        .iter()
        .map(|b| format!("{:?}", b.name()))
        .collect();
    (ids.join(", "), names.join(", "))
}

/// The stages that evaluate a BRDF (each includes `brdf/eval.glsl`): what a BRDF set is compiled
/// into ([`compile_brdf_modules`]; [`STAGES`] that evaluate a BRDF).
pub const BRDF_STAGES: [&str; 11] = files(Select::EvaluatesBrdf);

/// Writes what histencil's shaders include to evaluate `set` into `folder` (its `brdf_set/`
/// files, and a copy of the engine's GLSL under `engine/`, so that no name of the engine's can
/// hide one of histencil's includes); returns the engine files copied, where they are on disk.
/// Prints nothing: for a run-time compile as well as a build script's.
///
/// # Errors
/// [`BuildError::Brdfs`] when the engine's files cannot be read (a set with engine BRDFs and no
/// folder has none), [`BuildError::Io`] when the copies cannot be written.
pub fn stage_brdf_set(set: &BrdfSet, folder: &Path) -> Result<Vec<PathBuf>, BuildError> {
    let write = |relative: &str, bytes: &[u8]| {
        let path = folder.join(relative);
        let dir = path.parent().expect("a file under the set folder");
        std::fs::create_dir_all(dir)
            .and_then(|()| std::fs::write(&path, bytes))
            .map_err(|e| BuildError::Io(format!("{}: {e}", path.display())))
    };
    // A file the engine has since removed must not stay includable from an earlier staging.
    let engine_copies = folder.join("engine");
    if engine_copies.exists() {
        std::fs::remove_dir_all(&engine_copies)
            .map_err(|e| BuildError::Io(format!("{}: {e}", engine_copies.display())))?;
    }
    for (name, text) in set.glsl_files("engine") {
        write(name, text.as_bytes())?;
    }
    let mut copied = Vec::new();
    match set.folder() {
        Some(engine) => {
            for (relative, path) in engine_files(engine)? {
                let bytes = std::fs::read(&path)
                    .map_err(|e| BuildError::Brdfs(format!("{}: {e}", path.display())))?;
                write(&format!("engine/{relative}"), &bytes)?;
                copied.push(path);
            }
        }
        None if set.is_builtin_only() => {}
        None => {
            return Err(BuildError::Brdfs(
                "a BRDF set with BRDFs of the engine's needs its folder (BrdfSet::with_folder)"
                    .into(),
            ))
        }
    }
    Ok(copied)
}

/// glslc's `message` about a stage compiled with a set staged in `staged` by
/// [`stage_brdf_set`], with the engine's files named by their own paths, not their copies', and,
/// where it points into the generated `brdf_set/` files, which BRDF of the manifest is called
/// there and with what signature ([`BrdfSet::generated_call_hint`]).
pub fn engine_paths(message: &str, set: &BrdfSet, staged: &Path) -> String {
    let message = match set.folder() {
        Some(folder) => message.replace(
            &staged.join("engine").display().to_string(),
            &folder.display().to_string(),
        ),
        None => message.to_owned(),
    };
    match set.generated_call_hint(&message) {
        Some(hint) => format!("{message}\n{hint}"),
        None => message,
    }
}

/// [`stage_brdf_set`] into `out_dir/histencil/set/`, telling cargo to rerun when an engine file
/// changes; returns that folder. Search it before histencil's include folders
/// (`DEP_HISTENCIL_INCLUDE`, `DEP_HISTENCIL_GENERATED`) when compiling a shader of your own that
/// includes histencil's `light.glsl`, or include `brdf_set/ids.glsl` from it for the
/// `BRDF_ENGINE_*` ids.
///
/// # Errors
/// As [`stage_brdf_set`].
pub fn write_brdf_set(set: &BrdfSet, out_dir: &Path) -> Result<PathBuf, BuildError> {
    let root = out_dir.join("histencil").join("set");
    for path in stage_brdf_set(set, &root)? {
        println!("cargo:rerun-if-changed={}", path.display());
    }
    Ok(root)
}

/// Compiles [`BRDF_STAGES`] for `set` with histencil's own decode and visibility (its G-buffer,
/// no shadows) into `out_dir/histencil/brdf-modules/`, and writes
/// `out_dir/histencil_brdf_modules.rs`: a `BrdfModules { .. }` expression (the set, its light
/// shaders, the forward reference, the lightmaps and the BRDF evaluator), for `include!` where
/// `BrdfModules`, `LightModules` and the set's types are in scope (`histencil::*` and
/// `histencil::brdf::*`). What histencil's `Renderer`, `AlphaLightmaps::with_modules` and
/// `LightHooks::BuiltinWithBrdfs` take; an engine with hooks of its own compiles its light
/// shaders with [`compile_light_shaders_for`].
///
/// # Errors
/// As [`compile_light_shaders_for`].
pub fn compile_brdf_modules(set: &BrdfSet, out_dir: &Path) -> Result<PathBuf, BuildError> {
    let shaders = dep_var("SHADERS")?;
    let generated = dep_var("GENERATED")?;
    println!("cargo:rerun-if-env-changed=HISTENCIL_GLSLC");
    let target = out_dir.join("histencil").join("brdf-modules");
    std::fs::create_dir_all(&target)
        .map_err(|e| BuildError::Io(format!("{}: {e}", target.display())))?;
    let set_folder = write_brdf_set(set, out_dir)?;
    let (include, defaults) = (shaders.join("include"), shaders.join("hooks"));
    let includes = [
        set_folder.as_path(),
        include.as_path(),
        generated.as_path(),
        defaults.as_path(),
    ];
    // Each stage's field, by the table: a hooked stage's in `light`, the others' beside it.
    let (mut light_fields, mut fields) = (String::new(), String::new());
    for row in STAGES.iter().filter(|s| s.evaluates_brdf) {
        let field = compile_stage(row, (&shaders, &includes, &target), set, &set_folder)?;
        if row.hooked {
            light_fields += &format!("        {field}");
        } else {
            fields += &format!("    {field}");
        }
    }
    let (ids, names) = ids_and_names(set);
    let expression = format!(
        "::histencil::BrdfModules {{\n    set: {set},\n    light: ::histencil::LightModules {{\n{light_fields}        brdfs: &[{ids}],\n        brdf_names: &[{names}],\n        ..::histencil::LightModules::BUILTIN\n    }},\n{fields}}}\n",
        set = set.rust_expression(),
    );
    let rust = out_dir.join("histencil_brdf_modules.rs");
    std::fs::write(&rust, expression)
        .map_err(|e| BuildError::Io(format!("{}: {e}", rust.display())))?;
    Ok(rust)
}

/// Compiles `row`'s stage from histencil's `shaders` folder into `target` with `includes`
/// searched, and returns its line of a generated expression (`field: include_bytes!(..),`).
/// glslc's message names the engine's BRDF files by their own paths, not their copies' under
/// `set_folder`.
fn compile_stage(
    row: &Stage,
    (shaders, includes, target): (&Path, &[&Path], &Path),
    set: &BrdfSet,
    set_folder: &Path,
) -> Result<String, BuildError> {
    let stage = row.file;
    let out = target.join(format!("{stage}.spv"));
    run_glslc(glslc_command(&shaders.join(stage), includes, &out), stage).map_err(|e| match e {
        BuildError::Compile { stage, message } => BuildError::Compile {
            stage,
            message: engine_paths(&message, set, set_folder),
        },
        other => other,
    })?;
    Ok(format!(
        "{}: include_bytes!({:?}),\n",
        row.field(),
        out.display().to_string()
    ))
}

/// Compiles [`HOOKED_STAGES`] for the engine's BRDF `set`, with the hook files in `hook_folder`
/// (if any) searched before histencil's own, into `out_dir/histencil/`, and writes
/// `out_dir/histencil_light_modules.rs` (the `LightModules` expression, as
/// [`compile_light_shaders`] does; its `brdfs` are the set's ids) and
/// `out_dir/histencil_brdf_set.rs` (the set, [`BrdfSet::rust_expression`]), both for `include!`.
///
/// # Errors
/// As [`compile_light_shaders`], and [`BuildError::Brdfs`]; glslc's message names the engine's
/// own BRDF file and line.
pub fn compile_light_shaders_for(
    hook_folder: Option<&Path>,
    set: &BrdfSet,
    out_dir: &Path,
) -> Result<PathBuf, BuildError> {
    let shaders = dep_var("SHADERS")?;
    let generated = dep_var("GENERATED")?;
    println!("cargo:rerun-if-env-changed=HISTENCIL_GLSLC");
    if let Some(hooks) = hook_folder {
        println!("cargo:rerun-if-changed={}", hooks.display());
        for file in HOOK_FILES {
            println!("cargo:rerun-if-changed={}", hooks.join(file).display());
        }
    }
    let target = out_dir.join("histencil");
    std::fs::create_dir_all(&target)
        .map_err(|e| BuildError::Io(format!("{}: {e}", target.display())))?;
    let set_folder = write_brdf_set(set, out_dir)?;
    let (include, defaults) = (shaders.join("include"), shaders.join("hooks"));
    // The engine's hooks first: `#include "surface_decode.glsl"` in a stage (whose own folder
    // holds no hook) resolves there before histencil's defaults; the set's `brdf_set/` before
    // histencil's generated (empty) one.
    let mut includes: Vec<&Path> = hook_folder.into_iter().collect();
    includes.extend([
        set_folder.as_path(),
        include.as_path(),
        generated.as_path(),
        defaults.as_path(),
    ]);
    // Unqualified: the engine names it through `histencil` or `histencil_vk`, whichever it uses.
    let mut fields = String::from("LightModules {\n");
    for row in STAGES.iter().filter(|s| s.hooked) {
        let field = compile_stage(row, (&shaders, &includes, &target), set, &set_folder)?;
        fields += &format!("    {field}");
    }
    let (ids, names) = ids_and_names(set);
    fields += &format!("    brdfs: &[{ids}],\n    brdf_names: &[{names}],\n}}\n");
    let rust = out_dir.join("histencil_light_modules.rs");
    std::fs::write(&rust, fields)
        .map_err(|e| BuildError::Io(format!("{}: {e}", rust.display())))?;
    let set_rust = out_dir.join("histencil_brdf_set.rs");
    std::fs::write(&set_rust, set.rust_expression())
        .map_err(|e| BuildError::Io(format!("{}: {e}", set_rust.display())))?;
    Ok(rust)
}
