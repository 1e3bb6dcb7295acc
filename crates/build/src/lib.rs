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

/// The light shaders that call the hooks, compiled per engine.
pub const HOOKED_STAGES: [&str; 8] = [
    "deferred_light.frag",
    "lut_light.frag",
    "tile_classify.comp",
    "tile_shade.comp",
    "tile_classify_8.comp",
    "tile_shade_8.comp",
    "depth_id_copy.frag",
    "depth_id_shade.frag",
];

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
    /// `glslc` rejected a stage compiled with the hooks.
    Compile {
        /// The stage's file name, one of [`HOOKED_STAGES`].
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
                    "glslc failed on {stage} with the engine's hooks:\n{message}"
                )
            }
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
/// rerun when a hook file or histencil's shaders change.
///
/// # Errors
/// [`BuildError`]: not run from a direct dependent's build script, an empty hook folder, no
/// `glslc`, a hook that does not compile (glslc's message names the file and line), I/O.
pub fn compile_light_shaders(hook_folder: &Path, out_dir: &Path) -> Result<PathBuf, BuildError> {
    let shaders = dep_var("SHADERS")?;
    let generated = dep_var("GENERATED")?;
    println!("cargo:rerun-if-env-changed=HISTENCIL_GLSLC");
    println!("cargo:rerun-if-changed={}", hook_folder.display());
    let mut any = false;
    for file in HOOK_FILES {
        let path = hook_folder.join(file);
        println!("cargo:rerun-if-changed={}", path.display());
        any |= path.is_file();
    }
    if !any {
        return Err(BuildError::NoHooks(hook_folder.to_owned()));
    }
    let target = out_dir.join("histencil");
    std::fs::create_dir_all(&target)
        .map_err(|e| BuildError::Io(format!("{}: {e}", target.display())))?;
    let (include, defaults) = (shaders.join("include"), shaders.join("hooks"));
    // The engine's folder first: `#include "surface_decode.glsl"` in a stage (whose own folder
    // holds no hook) resolves there before histencil's defaults.
    let includes = [
        hook_folder,
        include.as_path(),
        generated.as_path(),
        defaults.as_path(),
    ];
    // Unqualified: the engine names it through `histencil` or `histencil_vk`, whichever it uses.
    let mut fields = String::from("LightModules {\n");
    for stage in HOOKED_STAGES {
        let source = shaders.join(stage);
        let out = target.join(format!("{stage}.spv"));
        run_glslc(glslc_command(&source, &includes, &out), stage)?;
        let field = stage.split('.').next().unwrap_or(stage);
        fields += &format!(
            "    {field}: include_bytes!({:?}),\n",
            out.display().to_string()
        );
    }
    fields += "}\n";
    let rust = out_dir.join("histencil_light_modules.rs");
    std::fs::write(&rust, fields)
        .map_err(|e| BuildError::Io(format!("{}: {e}", rust.display())))?;
    Ok(rust)
}
