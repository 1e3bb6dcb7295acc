//! `--brdfs DIR`: an engine's own BRDFs, the same folder for `render` and `check` (and the
//! example engine's build script). The folder is read and compiled before any device is made,
//! so a mistake in it is refused before anything is recorded or written.

use anyhow::{Context as _, Result};
use histencil_brdf::BrdfSet;
use histencil_scene::{DefaultLights, Scene};
use histencil_vk::BrdfModules;
use std::path::PathBuf;

/// The BRDF folder argument.
#[derive(clap::Args, Clone, Debug, Default)]
pub struct BrdfsArg {
    /// A folder of an engine's own BRDFs: `brdfs.toml` and the GLSL it names (the book's "Your
    /// BRDFs"). glTF extras may name them (`{"brdf": "toon"}`); an embedded scene's BRDFs
    /// become them, each distinct BRDF the folder's next, said on stderr.
    #[arg(long, value_name = "DIR")]
    pub brdfs: Option<PathBuf>,
}

impl BrdfsArg {
    /// The folder's set compiled for every technique (with the `glslc` histencil builds with),
    /// or histencil's own set.
    pub fn modules(&self) -> Result<&'static BrdfModules> {
        let Some(dir) = &self.brdfs else {
            return Ok(BrdfModules::builtin());
        };
        let set = BrdfSet::load(dir)?;
        histencil_vk::compile_brdf_set(&set)
            .map_err(anyhow::Error::msg)
            .with_context(|| format!("compiling the BRDFs of {}", dir.display()))
    }
}

/// The scene `spec` names with `modules`' BRDFs: a glTF file's extras may name them, and a scene
/// that names none of them has its BRDFs retargeted onto them (said on stderr).
pub fn load_scene(spec: &str, lights: DefaultLights, modules: &BrdfModules) -> Result<Scene> {
    let mut scene = crate::load_scene_in(spec, lights, &modules.set)?;
    let pairs = histencil_scene::retarget_brdfs(&mut scene, &modules.set);
    if !pairs.is_empty() {
        let said: Vec<String> = pairs
            .iter()
            .map(|(from, to)| format!("{from} -> {to}"))
            .collect();
        eprintln!(
            "histencil: scene `{spec}` shaded with the folder's BRDFs (default parameters): {}",
            said.join(", ")
        );
    }
    Ok(scene)
}
