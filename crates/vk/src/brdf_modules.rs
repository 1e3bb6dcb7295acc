//! The shaders that evaluate BRDFs, for a BRDF set of an engine's
//! ([`histencil_brdf::BrdfSet`]): every technique's light shaders, the alpha lightmaps and the
//! forward reference, each compiled with the set's functions so that all of them shade with the
//! same GLSL.
//!
//! An engine compiles them in its build script (histencil-build, beside its hooks); the command
//! line and the lab compile them at run time here, with the same `glslc` and options, from the
//! GLSL sources embedded in this crate. Why `glslc` and not a linked compiler: as for every
//! histencil shader (histencil-build's crate docs), nothing to link, and the compiler's message
//! names the engine's file and line, which [`compile`] keeps.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, OnceLock};

use histencil_brdf::lut::LutError;
use histencil_brdf::{Brdf, BrdfId, BrdfSet, V3};

use crate::gpu::device::context::Context;
use crate::gpu::device::error::{Error, Result};
use crate::lighting::hooks::LightModules;
use crate::shaders;

/// histencil's GLSL, as build.rs embeds it.
mod sources {
    include!(concat!(env!("OUT_DIR"), "/shader_sources.rs"));
}

/// Every module that evaluates a BRDF, compiled for one set, with the set.
#[derive(Debug)]
pub struct BrdfModules {
    /// The set they evaluate.
    pub set: BrdfSet,
    /// The light shaders of every technique (with histencil's own decode and visibility).
    pub light: LightModules,
    /// `forward.frag`: the forward reference.
    pub forward: &'static [u8],
    /// `lightmap.frag`: the alpha entities' lightmaps.
    pub lightmap: &'static [u8],
    /// `lightmap_directional.frag`: their directional lightmaps.
    pub lightmap_directional: &'static [u8],
    /// `alpha_object.frag`: translucent objects lit per pixel, by probe or by direction map.
    pub alpha_object: &'static [u8],
    /// `particle.frag`: particles, likewise.
    pub particle: &'static [u8],
    /// `brdf_eval.comp`: the BRDF evaluator (the engine BRDFs' finiteness probe).
    pub brdf_eval: &'static [u8],
}

/// The same modules: [`compile`] makes one per distinct set (its GLSL and its files' bytes), so
/// identity is equality.
impl PartialEq for BrdfModules {
    fn eq(&self, other: &Self) -> bool {
        std::ptr::eq(self, other)
    }
}

/// histencil's own set, as shipped.
static BUILTIN_MODULES: OnceLock<BrdfModules> = OnceLock::new();

impl BrdfModules {
    /// histencil's eight BRDFs with the shaders as built.
    pub fn builtin() -> &'static BrdfModules {
        BUILTIN_MODULES.get_or_init(|| BrdfModules {
            set: BrdfSet::default(),
            light: LightModules::BUILTIN,
            forward: shaders::FORWARD_FRAG,
            lightmap: shaders::LIGHTMAP_FRAG,
            lightmap_directional: shaders::LIGHTMAP_DIRECTIONAL_FRAG,
            alpha_object: shaders::ALPHA_OBJECT_FRAG,
            particle: shaders::PARTICLE_FRAG,
            brdf_eval: shaders::BRDF_EVAL_COMP,
        })
    }

    /// Whether these are histencil's own modules.
    pub fn is_builtin(&self) -> bool {
        std::ptr::eq(self, Self::builtin())
    }
}

/// A folder under the system's temporary one, removed with everything in it on drop (also when
/// a compile fails half way).
#[derive(Debug)]
pub(crate) struct Scratch(pub(crate) PathBuf);

impl Scratch {
    pub(crate) fn new() -> std::io::Result<Self> {
        use std::sync::atomic::{AtomicUsize, Ordering};
        static N: AtomicUsize = AtomicUsize::new(0);
        let path = std::env::temp_dir().join(format!(
            "histencil-brdf-set-{}-{}",
            std::process::id(),
            N.fetch_add(1, Ordering::Relaxed)
        ));
        std::fs::create_dir_all(&path)?;
        Ok(Self(path))
    }

    pub(crate) fn write(&self, relative: &str, text: &[u8]) -> Result<(), String> {
        let path = self.0.join(relative);
        let dir = path.parent().expect("a file in the scratch folder");
        std::fs::create_dir_all(dir)
            .and_then(|()| std::fs::write(&path, text))
            .map_err(|e| format!("{}: {e}", path.display()))
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Compiles every stage that evaluates a BRDF for `set`, with `glslc` (histencil-build's
/// options); the same set (its generated GLSL and its files' contents) compiles once per
/// process, and its modules live as long as the process, as a built-in module does.
///
/// # Errors
/// A message: the set's files could not be read or written, `glslc` could not be run, or it
/// refused a stage (its message, naming the engine's own file and line).
pub fn compile(set: &BrdfSet) -> Result<&'static BrdfModules, String> {
    compile_with_hooks(set, None)
}

/// As [`compile`], with an engine's hook files (`surface_decode.glsl`, `light_visibility.glsl`:
/// histencil-build's `HOOK_FILES`) from `hooks` searched before histencil's own, as
/// `histencil_build::compile_light_shaders_for` does at an engine's build: the run-time path
/// for an engine that cannot run cargo at its build (the C API's `histencil_shaders_compile`)
/// or ships a file of them (`histencil shaders`). Every hooked stage is compiled then, the
/// classification and id copy too, since they decode surfaces.
///
/// # Errors
/// As [`compile`], and a hook folder holding neither hook file.
pub fn compile_with_hooks(
    set: &BrdfSet,
    hooks: Option<&Path>,
) -> Result<&'static BrdfModules, String> {
    if set == &BrdfSet::default() && hooks.is_none() {
        return Ok(BrdfModules::builtin());
    }
    let mut hook_files = Vec::new();
    if let Some(folder) = hooks {
        for file in histencil_build::HOOK_FILES {
            let path = folder.join(file);
            if path.is_file() {
                let text = std::fs::read(&path).map_err(|e| format!("{}: {e}", path.display()))?;
                hook_files.push((file, text));
            }
        }
        if hook_files.is_empty() {
            return Err(format!(
                "the hook folder {} holds neither {}",
                folder.display(),
                histencil_build::HOOK_FILES.join(" nor ")
            ));
        }
    }
    let scratch = Scratch::new().map_err(|e| format!("a scratch folder for glslc: {e}"))?;
    let staged = scratch.0.join("set");
    let copied = histencil_build::stage_brdf_set(set, &staged).map_err(|e| e.to_string())?;
    // What the modules are a function of: the generated GLSL, every engine file's bytes and
    // the hook files'. The declarations too: parameters' ranges and defaults are checked and
    // probed from the set the modules carry.
    let mut key: Vec<u8> = format!("{set:?}").into_bytes();
    for (name, text) in set.glsl_files("engine") {
        key.extend(name.bytes().chain(text.bytes()).chain([0]));
    }
    for path in &copied {
        let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
        key.extend(path.display().to_string().bytes().chain(bytes).chain([0]));
    }
    for (name, text) in &hook_files {
        key.extend(
            b"hook "
                .iter()
                .chain(name.as_bytes())
                .chain(text)
                .chain(&[0]),
        );
    }
    static COMPILED: OnceLock<Mutex<HashMap<Vec<u8>, &'static BrdfModules>>> = OnceLock::new();
    let cache = COMPILED.get_or_init(Default::default);
    if let Some(done) = cache.lock().unwrap_or_else(|p| p.into_inner()).get(&key) {
        return Ok(done);
    }

    for (path, text) in sources::SOURCES {
        scratch.write(path, text.as_bytes())?;
    }
    let root = &scratch.0;
    // The engine's hooks first: `#include "surface_decode.glsl"` in a stage resolves there
    // before histencil's defaults (the build's order).
    let mut includes: Vec<PathBuf> = hooks.into_iter().map(Path::to_owned).collect();
    includes.extend([
        staged.clone(),
        root.join("include"),
        root.join("generated"),
        root.join("hooks"),
    ]);
    let includes: Vec<&Path> = includes.iter().map(PathBuf::as_path).collect();
    // The BRDF stages, and with hooks every hooked stage too: the build's table.
    let stages = histencil_build::STAGES
        .iter()
        .filter(|s| s.evaluates_brdf || (hooks.is_some() && s.hooked));
    let mut spirv = HashMap::new();
    for row in stages {
        let stage = row.file;
        let out = root.join(format!("{stage}.spv"));
        let command =
            histencil_build::glslc_command(&root.join("stages").join(stage), &includes, &out);
        histencil_build::run_glslc(command, stage).map_err(|e| {
            let message = match e {
                histencil_build::BuildError::Compile { stage, message } => {
                    format!("glslc refused {stage} compiled with the BRDF set:\n{message}")
                }
                other => other.to_string(),
            };
            // The engine's files by their own paths, histencil's by where they live in its tree.
            histencil_build::engine_paths(&message, set, &staged)
                .replace(&root.display().to_string(), "histencil-vk/shaders")
        })?;
        let bytes = std::fs::read(&out).map_err(|e| format!("{}: {e}", out.display()))?;
        spirv.insert(row.field(), &*Box::leak(bytes.into_boxed_slice()));
    }
    let modules: &'static BrdfModules = Box::leak(Box::new(
        modules_of(set, |field| spirv.get(field).copied()).expect("every BRDF stage compiled"),
    ));
    cache
        .lock()
        .unwrap_or_else(|p| p.into_inner())
        .insert(key, modules);
    Ok(modules)
}

/// The modules of `set` from its stages' SPIR-V by field name (`deferred_light`, `forward`,
/// ...): `None` when a BRDF stage is missing; a hooked stage that evaluates no BRDF
/// (`tile_classify`, `depth_id_copy`) missing is histencil's own.
pub(crate) fn modules_of(
    set: &BrdfSet,
    stage: impl Fn(&str) -> Option<&'static [u8]>,
) -> Option<BrdfModules> {
    let mut light = LightModules {
        brdfs: Box::leak(set.ids().iter().map(|b| b.index()).collect()),
        brdf_names: Box::leak(set.ids().iter().map(|b| b.name()).collect()),
        ..LightModules::BUILTIN
    };
    let evaluates = |field: &str| {
        histencil_build::STAGES
            .iter()
            .any(|s| s.evaluates_brdf && s.field() == field)
    };
    for (field, module) in light.named_mut() {
        match stage(field) {
            Some(spirv) => *module = spirv,
            None if evaluates(field) => return None,
            None => {}
        }
    }
    Some(BrdfModules {
        set: set.clone(),
        light,
        forward: stage("forward")?,
        lightmap: stage("lightmap")?,
        lightmap_directional: stage("lightmap_directional")?,
        alpha_object: stage("alpha_object")?,
        particle: stage("particle")?,
        brdf_eval: stage("brdf_eval")?,
    })
}

/// Unit vector at `elevation` degrees above the plane z = 0, `azimuth` degrees around +z.
fn direction(elevation: f32, azimuth: f32) -> V3<f32> {
    let (e, a) = (elevation.to_radians(), azimuth.to_radians());
    [e.cos() * a.cos(), e.cos() * a.sin(), e.sin()]
}

/// The shading points every engine BRDF is probed at, about the normal +z with histencil's
/// fibre tangent (+y): light and view from the pole to the horizon and below it, every azimuth
/// quarter, and the hard cases (view along -N, which has no azimuth; light along the view; a
/// vertical normal, whose fibre tangent is zero).
fn probe_directions() -> Vec<[V3<f32>; 4]> {
    let n = [0.0, 0.0, 1.0];
    let t = [0.0, 1.0, 0.0];
    let elevations = [90.0, 60.0, 30.0, 5.0, 0.0, -10.0];
    let azimuths = [0.0, 90.0, 180.0, 270.0];
    let mut out = Vec::new();
    for le in elevations {
        for ve in elevations {
            for va in azimuths {
                out.push([n, t, direction(ve, va), direction(le, 0.0)]);
            }
        }
    }
    let l = direction(45.0, 0.0);
    out.push([n, t, [0.0, 0.0, -1.0], l]);
    out.push([n, t, l, l]);
    out.push([[0.0, 1.0, 0.0], [0.0; 3], l, [0.0, 1.0, 0.0]]);
    out
}

/// Refuses an engine BRDF that returns NaN, an infinity or a negative value anywhere it is
/// probed (its parameters at their defaults, each at its ends, all at their ends, at
/// `probe_directions`; one that takes the tint at each of `probe_tints`), naming the BRDF and
/// the point: such a value is written into every technique's frame and the forward
/// reference's alike, where no comparison between them can see it. Histencil's own BRDFs are
/// held to their f64 reference instead, and pass at once.
///
/// # Errors
/// [`Error::BrdfSet`] naming the BRDF, its parameters and the directions; Vulkan errors.
pub fn probe_finite(ctx: &Context, modules: &'static BrdfModules) -> Result<()> {
    probe(ctx, modules)
}

/// Whether the LUT technique can hold `brdf` of `modules`' set in a table: the set's own answer
/// ([`BrdfSet::tabulable`]), and for an engine BRDF the device's, at the material's own
/// parameters: one that returns light where `N.L <= 0` (a wrap or translucent lobe) is refused,
/// since a table's axes end at the horizon and it would drop that light in silence. A value
/// there under a thousandth of the material's largest above the horizon (a division guarded
/// by `max(dot(N, L), 1e-4)`, say) is not counted: the table's own error is far larger. The
/// set is probed first ([`probe_finite`]). `Ok(None)` where a table can hold it.
///
/// # Errors
/// The probe's ([`probe_finite`]); Vulkan errors.
pub fn lut_refusal(
    ctx: &Context,
    modules: &'static BrdfModules,
    brdf: &Brdf,
) -> Result<Option<LutError>> {
    if let Err(why) = modules.set.tabulable(brdf) {
        return Ok(Some(why));
    }
    let Brdf::Engine { id, .. } = brdf else {
        return Ok(None);
    };
    probe(ctx, modules)?;
    Ok(
        lights_below_horizon(ctx, modules, brdf)?.then_some(LutError::EngineUntabulable {
            brdf: id.name(),
            reason: "it returns light where N.L <= 0 (a wrap or translucent lobe), and a \
                 table's axes end at the horizon: it would drop that light",
        }),
    )
}

/// Whether `brdf`, an engine BRDF with its parameters, returns light where `N.L <= 0` past a
/// thousandth of its largest value above the horizon, at `probe_directions` (both parts).
/// Once per material, modules and device.
fn lights_below_horizon(ctx: &Context, modules: &'static BrdfModules, brdf: &Brdf) -> Result<bool> {
    type Known = Vec<((usize, String, u32, [u64; 4]), bool)>;
    static KNOWN: OnceLock<Mutex<Known>> = OnceLock::new();
    let key = (
        modules as *const BrdfModules as usize,
        ctx.device_name().to_owned(),
        brdf.id().index(),
        brdf.packed_params().map(f64::to_bits),
    );
    let known = KNOWN.get_or_init(Default::default);
    if let Some((_, below)) =
        (known.lock().unwrap_or_else(|p| p.into_inner()).iter()).find(|(k, _)| *k == key)
    {
        return Ok(*below);
    }
    let cases: Vec<(Brdf, [V3<f32>; 4])> =
        probe_directions().into_iter().map(|d| (*brdf, d)).collect();
    let mut evaluator = crate::BrdfEvaluator::with_module(ctx, modules.brdf_eval)?;
    let values = evaluator.evaluate(ctx, &cases);
    evaluator.destroy(ctx);
    let (mut above, mut below) = (0f32, 0f32);
    for ((_, [n, _, _, l]), parts) in cases.iter().zip(values?) {
        let n_dot_l: f32 = n.iter().zip(l).map(|(a, b)| a * b).sum();
        let largest = parts.channels().into_iter().fold(0f32, f32::max);
        if n_dot_l <= 0.0 {
            below = below.max(largest);
        } else {
            above = above.max(largest);
        }
    }
    let lights = below > 0.0 && below > 1e-3 * above;
    known
        .lock()
        .unwrap_or_else(|p| p.into_inner())
        .push((key, lights));
    Ok(lights)
}

/// The surface colours a BRDF that takes the tint is probed at: each channel at 0, a half and 1
/// (27 colours, black, white and the saturated ones among them).
fn probe_tints() -> Vec<[f32; 3]> {
    let steps = [0.0, 0.5, 1.0];
    let mut out = Vec::new();
    for r in steps {
        for g in steps {
            for b in steps {
                out.push([r, g, b]);
            }
        }
    }
    out
}

/// [`probe_finite`], once per set and device.
fn probe(ctx: &Context, modules: &'static BrdfModules) -> Result<()> {
    if modules.set.is_builtin_only() {
        return Ok(());
    }
    // Once per modules and device: a check builds several renderers of one set.
    type Probed = Vec<(usize, String)>;
    static PROBED: OnceLock<Mutex<Probed>> = OnceLock::new();
    let key = (
        modules as *const BrdfModules as usize,
        ctx.device_name().to_owned(),
    );
    let probed = PROBED.get_or_init(Default::default);
    if probed
        .lock()
        .unwrap_or_else(|p| p.into_inner())
        .contains(&key)
    {
        return Ok(());
    }
    let directions = probe_directions();
    // A BRDF whose function takes the tint has no parts: it is probed as a surface of each of
    // the probe's colours, as every technique calls it.
    let tints = probe_tints();
    let mut cases: Vec<(Brdf, [V3<f32>; 4])> = Vec::new();
    let mut tinted: Vec<crate::tools::brdf_eval::TintedCase> = Vec::new();
    for (id, spec) in modules.set.engine() {
        let mut corners: Vec<Vec<(&str, f64)>> = vec![Vec::new()];
        for p in &spec.params {
            corners.push(vec![(p.name.as_str(), p.range.min)]);
            corners.push(vec![(p.name.as_str(), p.range.max)]);
        }
        for end in [true, false] {
            let all = spec.params.iter().map(|p| {
                let x = if end { p.range.min } else { p.range.max };
                (p.name.as_str(), x)
            });
            corners.push(all.collect());
        }
        for given in corners {
            let brdf = modules
                .set
                .engine_brdf(id.name(), &given)
                .expect("the set's own ranges");
            if spec.tint {
                let at = |tint| directions.iter().map(move |d| (brdf, tint, *d));
                tinted.extend(tints.iter().copied().flat_map(at));
            } else {
                cases.extend(directions.iter().map(|d| (brdf, *d)));
            }
        }
    }
    let mut evaluator = crate::BrdfEvaluator::with_module(ctx, modules.brdf_eval)?;
    let values = evaluator.evaluate(ctx, &cases).and_then(|parts| {
        let with_tint = evaluator.evaluate_tinted(ctx, &tinted)?;
        Ok((parts, with_tint))
    });
    evaluator.destroy(ctx);
    let (parts, with_tint) = values?;
    let values = cases
        .iter()
        .map(|(brdf, dirs)| (brdf, None, dirs))
        .zip(parts.iter().map(|p| p.channels().to_vec()))
        .chain(
            tinted
                .iter()
                .map(|(brdf, tint, dirs)| (brdf, Some(tint), dirs))
                .zip(with_tint.iter().map(|v| v.to_vec())),
        );
    for ((brdf, tint, [n, _, v, l]), channels) in values {
        refuse_bad(brdf, tint, [n, v, l], &channels)?;
    }
    probed.lock().unwrap_or_else(|p| p.into_inner()).push(key);
    Ok(())
}

/// Refuses a value that is NaN, infinite or negative. Negative light (a BRDF reading another's
/// parameters, say) is refused as a NaN is: every technique and the forward reference would
/// subtract it alike.
fn refuse_bad(
    brdf: &Brdf,
    tint: Option<&[f32; 3]>,
    [n, v, l]: [&V3<f32>; 3],
    channels: &[f32],
) -> Result<()> {
    let Some(x) = channels.iter().find(|x| !x.is_finite() || **x < 0.0) else {
        return Ok(());
    };
    let colour = tint.map_or(String::new(), |t| format!(" for a surface of colour {t:?}"));
    Err(Error::BrdfSet(format!(
        "engine BRDF `{}` returns {x} with parameters {:?}{colour} at N {n:?}, V {v:?}, L {l:?}: \
         it must be finite and not negative wherever it is evaluated (the forward reference \
         would hold the same value, so no comparison could see it)",
        brdf.name(),
        &brdf.packed_params()[..3],
    )))
}

/// [`probe_finite`]'s test at a scene's own materials: each material of a BRDF whose function
/// takes the tint, as a surface of its own colour, at the probe's directions. The set's probe
/// tries 27 colours; a function that goes negative only near another colour is found here,
/// for the materials a frame will shade. Histencil's `Renderer` runs it for its scene; an
/// engine runs it for its materials (each a BRDF and its colour) beside [`probe_finite`].
///
/// # Errors
/// [`Error::BrdfSet`] naming the BRDF, its parameters, the colour and the directions; Vulkan
/// errors.
pub fn probe_materials(
    ctx: &Context,
    modules: &'static BrdfModules,
    materials: &[(Brdf, [f32; 3])],
) -> Result<()> {
    let takes_tint = |b: &Brdf| match b {
        Brdf::Engine { id, .. } => modules
            .set
            .spec(BrdfId::Engine(*id))
            .is_some_and(|s| s.tint),
        _ => false,
    };
    let mut distinct: Vec<(Brdf, [f32; 3])> = Vec::new();
    for m in materials.iter().filter(|(b, _)| takes_tint(b)) {
        if !distinct.contains(m) {
            distinct.push(*m);
        }
    }
    if distinct.is_empty() {
        return Ok(());
    }
    let directions = probe_directions();
    let cases: Vec<crate::tools::brdf_eval::TintedCase> = (distinct.iter())
        .flat_map(|(brdf, tint)| directions.iter().map(move |d| (*brdf, *tint, *d)))
        .collect();
    let mut evaluator = crate::BrdfEvaluator::with_module(ctx, modules.brdf_eval)?;
    let values = evaluator.evaluate_tinted(ctx, &cases);
    evaluator.destroy(ctx);
    for ((brdf, tint, [n, _, v, l]), value) in cases.iter().zip(values?) {
        refuse_bad(brdf, Some(tint), [n, v, l], &value)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The modules a compile assembles are the build table's stages, every one and no other:
    /// a stage added to the table without a field here would be compiled and dropped.
    #[test]
    fn the_modules_are_assembled_from_every_stage_of_the_build_table() {
        let asked = std::cell::RefCell::new(Vec::new());
        let modules = modules_of(&BrdfSet::default(), |field| {
            asked.borrow_mut().push(field.to_owned());
            Some(&[0u8; 4][..])
        });
        assert!(modules.is_some());
        let mut asked = asked.into_inner();
        asked.sort();
        let mut table: Vec<String> = histencil_build::STAGES
            .iter()
            .map(|s| s.field().to_owned())
            .collect();
        table.sort();
        assert_eq!(asked, table);
    }
}
