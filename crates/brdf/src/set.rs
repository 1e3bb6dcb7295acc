//! The shading models a lighting is made for: histencil's own by name and an engine's own, each a
//! GLSL function with a few lines of data. The talk's subject is an engine's artists choosing
//! among many BRDFs; a set lets those be the engine's, not only histencil's eight.
//!
//! # The GLSL contract
//! An engine BRDF is a function in a file of the engine's:
//!
//! ```glsl
//! vec3 toon(vec4 p, vec3 N, vec3 T, vec3 V, vec3 L)
//! ```
//!
//! returning `f_r * N.L` of a white surface (the surface's tint multiplies it), as every built-in
//! does. `p.xyz` are its parameters in the order its set declares them (`p.w` is 0); `N`, `V` and
//! `L` are unit vectors pointing away from the surface (`V` may lie below the horizon along
//! silhouettes, as interpolated normals give); `T` is histencil's fibre direction (world +Y
//! projected onto the surface: not unit, zero where `N` is vertical). With a white part (as
//! glTF's BRDF has: a dielectric's specular is not tinted), a second function
//! `float name(vec4 p, vec3 N, vec3 T, vec3 V, vec3 L)` gives the part added untinted.
//!
//! A BRDF whose value is not affine in the surface's colour (many engines' metallic-roughness,
//! whose Fresnel takes F0 = mix(0.04, base, metallic) and weighs the diffuse, goes with the base
//! colour squared; glTF's own Appendix B, histencil's built-in, is affine) takes the colour itself:
//! declared with `tint = true`, its function is
//! `vec3 name(vec4 p, vec3 tint, vec3 N, vec3 T, vec3 V, vec3 L)` and returns the whole
//! `f_r * N.L` of a surface of that colour, per channel, with no white part. The file
//! may use histencil's helpers (`brdf/common.glsl`: `PI`, `INV_PI`, `brdf_pow`,
//! `brdf_normalize`, `brdf_above_horizon`), which are included before it.
//!
//! Every technique evaluates the same function: the per-BRDF light shaders specialised to its
//! id, branching's switch, the tiled and depth-id kernels, the alpha lightmaps and the forward
//! reference. [`BrdfSet::glsl_files`] writes what the shaders include to reach it.

use std::path::{Path, PathBuf};

use crate::id::{BrdfId, EngineBrdf, ENGINE_FIRST, MAX_ENGINE_BRDFS};
use crate::lut::LutError;
use crate::model::{Brdf, BrdfError, Range, F32_FINITE};

/// The most parameters an engine BRDF takes: histencil's G-buffer stores three per pixel (the
/// fourth channel of its material texel is the BRDF id).
pub const MAX_ENGINE_PARAMS: usize = 3;

/// One parameter of an engine BRDF.
#[derive(Clone, Debug, PartialEq)]
pub struct EngineParam {
    /// Its name in glTF extras and scene files.
    pub name: String,
    /// The values accepted; a material's value outside it is refused, as a built-in's is.
    pub range: Range,
    /// The value of a material that does not give it.
    pub default: f64,
}

/// An engine BRDF as its engine declares it (the manifest's `[[brdf]]` table).
#[derive(Clone, Debug, PartialEq)]
pub struct EngineBrdfSpec {
    /// Its name in glTF extras, scene files, plans and reports: lower case, digits and `_`,
    /// starting with a letter, and none of the built-ins' names.
    pub name: String,
    /// The GLSL file defining its function, relative to the set's folder, `/`-separated.
    pub glsl: String,
    /// The function returning its tinted part (the contract in this module's docs).
    pub function: String,
    /// The function returning its white part, if it has one.
    pub white: Option<String>,
    /// Its parameters, at most [`MAX_ENGINE_PARAMS`], in the order `p.xyz` holds them.
    pub params: Vec<EngineParam>,
    /// Whether it reads `T`: said so a decode hook that gives no tangent can refuse it.
    pub tangent: bool,
    /// Whether its function takes the surface's colour and returns the whole value
    /// (`vec3 name(vec4 p, vec3 tint, vec3 N, vec3 T, vec3 V, vec3 L)`), for a BRDF that is
    /// not `tint * f + white`; such a BRDF has no `white` function.
    pub tint: bool,
}

/// Why a set of BRDFs was refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SetError {
    /// The set holds no BRDF at all.
    #[error("the BRDF set is empty: name a built-in or declare a BRDF of your own")]
    Empty,
    /// A built-in named twice, or an engine name given twice.
    #[error("BRDF `{0}` is named twice")]
    Twice(String),
    /// An engine BRDF named as a built-in is.
    #[error("BRDF `{0}` has a built-in's name; give your own BRDF another")]
    BuiltinName(String),
    /// A name or GLSL identifier histencil cannot use as it is.
    #[error("{what} `{name}` must be lower-case letters, digits and `_`, starting with a letter, at most 32 characters")]
    BadName {
        /// What was named: a BRDF, a parameter, a function.
        what: &'static str,
        /// The name given.
        name: String,
    },
    /// More engine BRDFs than the tiled classification's ids hold.
    #[error("{count} BRDFs of your own; a set holds at most {MAX_ENGINE_BRDFS}")]
    TooMany {
        /// How many were declared.
        count: usize,
    },
    /// A BRDF with more parameters than the G-buffer stores.
    #[error("BRDF `{brdf}` has {count} parameters; at most {MAX_ENGINE_PARAMS} (histencil's G-buffer stores three per pixel)")]
    TooManyParams {
        /// The BRDF.
        brdf: String,
        /// How many it declared.
        count: usize,
    },
    /// A parameter whose range or default cannot be.
    #[error("BRDF `{brdf}`, parameter `{param}`: {why}")]
    BadParam {
        /// The BRDF.
        brdf: String,
        /// The parameter.
        param: String,
        /// What is wrong, in words.
        why: String,
    },
    /// A BRDF whose function takes the tint and that also names a white part: the function
    /// returns the whole value, so there is nothing to add.
    #[error("BRDF `{0}` takes the tint (`tint = true`) and names a `white` function: a function that takes the tint returns the whole value; drop `white` or `tint`")]
    TintAndWhite(String),
    /// A GLSL path that does not end in `.glsl` (the files copied for the compiler are those).
    #[error("BRDF `{brdf}`: `{path}` must be a `.glsl` file")]
    NotGlsl {
        /// The BRDF.
        brdf: String,
        /// The path given.
        path: String,
    },
    /// A GLSL path that leaves the set's folder or is not a plain relative path.
    #[error("BRDF `{brdf}`: `{path}` must be a relative path inside the BRDF folder (no `..`, no absolute path)")]
    OutsideFolder {
        /// The BRDF.
        brdf: String,
        /// The path given.
        path: String,
    },
}

/// The BRDFs a lighting is made for, in id order: the built-ins it names, then the engine's own
/// (ids [`ENGINE_FIRST`] on). Fixed when the lighting is made, as its stencil layout is.
#[derive(Clone, Debug, PartialEq)]
pub struct BrdfSet {
    builtins: Vec<BrdfId>,
    engine: Vec<(EngineBrdf, EngineBrdfSpec)>,
    /// The folder the engine's GLSL paths are relative to.
    folder: Option<PathBuf>,
}

impl Default for BrdfSet {
    /// histencil's eight, no engine BRDF: the shaders as histencil ships them.
    fn default() -> Self {
        Self {
            builtins: BrdfId::ALL.to_vec(),
            engine: Vec::new(),
            folder: None,
        }
    }
}

fn is_identifier(name: &str) -> bool {
    let mut chars = name.chars();
    chars.next().is_some_and(|c| c.is_ascii_lowercase())
        && chars.all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
        && name.len() <= 32
}

/// A GLSL function name: an identifier (any case), not reserved by GLSL (`gl_`, `__`).
fn is_function_name(name: &str) -> bool {
    let mut chars = name.chars();
    chars.next().is_some_and(|c| c.is_ascii_alphabetic())
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
        && !name.starts_with("gl_")
        && !name.contains("__")
        && name.len() <= 64
}

/// Whether `path` is a plain relative path: `/`-separated names, none empty, `.` or `..`.
pub(crate) fn is_confined(path: &str) -> bool {
    !path.is_empty()
        && path.split('/').all(|part| {
            !part.is_empty()
                && part != "."
                && part != ".."
                && part
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.'))
        })
}

/// Holds engine BRDF `model`'s parameter `p` to its range: one rule for a material built from
/// the set and one handed back to it.
fn held(model: &'static str, p: &EngineParam, x: f64) -> Result<(), BrdfError> {
    if p.range.holds(x) {
        return Ok(());
    }
    Err(BrdfError::BadEngineParam {
        model,
        param: p.name.clone(),
        rule: p.range.text(),
        value: x.to_string(),
    })
}

fn check_spec(spec: &EngineBrdfSpec) -> Result<(), SetError> {
    let brdf = || spec.name.clone();
    if !is_identifier(&spec.name) {
        return Err(SetError::BadName {
            what: "BRDF",
            name: spec.name.clone(),
        });
    }
    if BrdfId::ALL.iter().any(|b| b.name() == spec.name) {
        return Err(SetError::BuiltinName(spec.name.clone()));
    }
    for function in std::iter::once(&spec.function).chain(&spec.white) {
        if !is_function_name(function) {
            return Err(SetError::BadName {
                what: "GLSL function",
                name: function.clone(),
            });
        }
    }
    if spec.tint && spec.white.is_some() {
        return Err(SetError::TintAndWhite(spec.name.clone()));
    }
    if !is_confined(&spec.glsl) {
        return Err(SetError::OutsideFolder {
            brdf: brdf(),
            path: spec.glsl.clone(),
        });
    }
    if !spec.glsl.ends_with(".glsl") {
        return Err(SetError::NotGlsl {
            brdf: brdf(),
            path: spec.glsl.clone(),
        });
    }
    if spec.params.len() > MAX_ENGINE_PARAMS {
        return Err(SetError::TooManyParams {
            brdf: brdf(),
            count: spec.params.len(),
        });
    }
    for (i, p) in spec.params.iter().enumerate() {
        let bad = |why: String| SetError::BadParam {
            brdf: brdf(),
            param: p.name.clone(),
            why,
        };
        if !is_identifier(&p.name) {
            return Err(SetError::BadName {
                what: "parameter",
                name: p.name.clone(),
            });
        }
        if spec.params[..i].iter().any(|q| q.name == p.name) {
            return Err(bad("named twice".into()));
        }
        // A glTF material's extras say `brdf` and `tint` for the model and the colour.
        if matches!(p.name.as_str(), "brdf" | "tint") {
            return Err(bad(
                "`brdf` and `tint` name a material's model and colour in glTF extras".into(),
            ));
        }
        let Range { min, max } = p.range;
        if !(F32_FINITE.holds(min) && F32_FINITE.holds(max) && min <= max) {
            return Err(bad(format!(
                "range [{min}, {max}] must be finite in f32 with min <= max"
            )));
        }
        if !p.range.holds(p.default) {
            return Err(bad(format!(
                "default {} is outside its range [{min}, {max}]",
                p.default
            )));
        }
    }
    Ok(())
}

impl BrdfSet {
    /// The built-ins `builtins` (each at most once) and the engine's `engine` BRDFs, in the
    /// order given: the `k`-th engine BRDF has id [`ENGINE_FIRST`] + `k`.
    ///
    /// # Errors
    /// [`SetError`]: an empty set, a name given twice or a built-in's, a name or function that
    /// is no identifier, more than [`MAX_ENGINE_BRDFS`] BRDFs or [`MAX_ENGINE_PARAMS`]
    /// parameters, a range or default that cannot be, a GLSL path outside the folder.
    pub fn new(builtins: &[BrdfId], engine: Vec<EngineBrdfSpec>) -> Result<Self, SetError> {
        if builtins.is_empty() && engine.is_empty() {
            return Err(SetError::Empty);
        }
        if engine.len() > MAX_ENGINE_BRDFS {
            return Err(SetError::TooMany {
                count: engine.len(),
            });
        }
        for (i, b) in builtins.iter().enumerate() {
            if !b.is_builtin() {
                return Err(SetError::BadName {
                    what: "built-in BRDF",
                    name: b.name().into(),
                });
            }
            if builtins[..i].contains(b) {
                return Err(SetError::Twice(b.name().into()));
            }
        }
        for (i, spec) in engine.iter().enumerate() {
            check_spec(spec)?;
            if engine[..i].iter().any(|s| s.name == spec.name) {
                return Err(SetError::Twice(spec.name.clone()));
            }
        }
        let engine = engine
            .into_iter()
            .enumerate()
            .map(|(k, spec)| (EngineBrdf::new(k as u8, &spec.name), spec))
            .collect();
        Ok(Self {
            builtins: builtins.to_vec(),
            engine,
            folder: None,
        })
    }

    /// The set with its engine GLSL paths relative to `folder` (what [`BrdfSet::load`] gives).
    pub fn with_folder(mut self, folder: PathBuf) -> Self {
        self.folder = Some(folder);
        self
    }

    /// The folder its engine GLSL paths are relative to, if it has one.
    pub fn folder(&self) -> Option<&Path> {
        self.folder.as_deref()
    }

    /// Every BRDF of the set, in id order.
    pub fn ids(&self) -> Vec<BrdfId> {
        let engine = self.engine.iter().map(|(id, _)| BrdfId::Engine(*id));
        self.builtins.iter().copied().chain(engine).collect()
    }

    /// The built-ins it holds.
    pub fn builtins(&self) -> &[BrdfId] {
        &self.builtins
    }

    /// The engine's BRDFs with their declarations, in id order.
    pub fn engine(&self) -> impl Iterator<Item = (BrdfId, &EngineBrdfSpec)> {
        self.engine
            .iter()
            .map(|(id, spec)| (BrdfId::Engine(*id), spec))
    }

    /// Whether the set holds no BRDF of the engine's: histencil's shaders as shipped, or a
    /// selection of them, serve it.
    pub fn is_builtin_only(&self) -> bool {
        self.engine.is_empty()
    }

    /// Whether `id` is one of the set's BRDFs.
    pub fn contains(&self, id: BrdfId) -> bool {
        match id {
            BrdfId::Engine(e) => self.engine.iter().any(|(own, _)| *own == e),
            b => self.builtins.contains(&b),
        }
    }

    /// The set's BRDF named `name`.
    pub fn by_name(&self, name: &str) -> Option<BrdfId> {
        self.ids().into_iter().find(|b| b.name() == name)
    }

    /// The set's BRDF of numeric id `index` (what a G-buffer stores).
    pub fn by_index(&self, index: u32) -> Option<BrdfId> {
        self.ids().into_iter().find(|b| b.index() == index)
    }

    /// The declaration of the engine BRDF `id`.
    pub fn spec(&self, id: BrdfId) -> Option<&EngineBrdfSpec> {
        let BrdfId::Engine(e) = id else { return None };
        self.engine
            .iter()
            .find(|(own, _)| *own == e)
            .map(|(_, spec)| spec)
    }

    /// The engine BRDF `name` with the parameters `given` (name, value); a parameter not given
    /// takes its default. For an engine that builds its materials in code, and for the scene
    /// readers (glTF extras, scene files).
    ///
    /// # Errors
    /// [`BrdfError`]: a name the set does not hold (or a built-in's: use [`Brdf`]'s variants),
    /// an unknown parameter, a value outside its range.
    pub fn engine_brdf(&self, name: &str, given: &[(&str, f64)]) -> Result<Brdf, BrdfError> {
        let Some((id, spec)) = self.engine.iter().find(|(_, s)| s.name == name) else {
            return Err(BrdfError::UnknownModel(name.to_owned()));
        };
        let model = id.name();
        let accepted = || {
            let names: Vec<&str> = spec.params.iter().map(|p| p.name.as_str()).collect();
            names.join(", ")
        };
        if let Some((unknown, _)) = given
            .iter()
            .find(|(g, _)| !spec.params.iter().any(|p| p.name == *g))
        {
            return Err(BrdfError::UnknownParam {
                model,
                param: (*unknown).to_owned(),
                accepted: accepted(),
            });
        }
        let mut params = [0.0; 3];
        for (slot, p) in params.iter_mut().zip(&spec.params) {
            let value = given
                .iter()
                .rev()
                .find(|(g, _)| *g == p.name)
                .map_or(p.default, |(_, x)| *x);
            held(model, p, value)?;
            *slot = value;
        }
        Ok(Brdf::Engine { id: *id, params })
    }

    /// Holds `brdf` to the set: a BRDF the set holds, with each engine parameter in its range
    /// (a built-in's, to [`Brdf::check`]).
    ///
    /// # Errors
    /// [`BrdfError`]: the BRDF is not in the set, or a parameter is out of its range.
    pub fn check(&self, brdf: &Brdf) -> Result<(), BrdfError> {
        if !self.contains(brdf.id()) {
            return Err(BrdfError::NotInSet {
                model: brdf.name(),
                set: self
                    .ids()
                    .iter()
                    .map(|b| b.name())
                    .collect::<Vec<_>>()
                    .join(", "),
            });
        }
        let Brdf::Engine { id, params } = brdf else {
            return brdf.check();
        };
        let spec = self.spec(BrdfId::Engine(*id)).expect("contains it");
        for (p, x) in spec.params.iter().zip(params) {
            held(id.name(), p, *x)?;
        }
        Ok(())
    }

    /// Whether the LUT technique can hold `brdf` in a table: every built-in
    /// ([`Brdf::is_tabulable`]); an engine BRDF of this set unless its function takes the tint
    /// (an entry holds two factors, `tint * tinted + white`, and a value that is not affine in
    /// the tint has none) or it reads the tangent (its table is over the three angles of an
    /// isotropic BRDF, [`crate::lut::LutAxes::Isotropic`]).
    ///
    /// # Errors
    /// [`LutError::EngineUntabulable`] saying why not, also for an engine BRDF this set does
    /// not hold.
    pub fn tabulable(&self, brdf: &Brdf) -> Result<(), LutError> {
        let Brdf::Engine { id, .. } = brdf else {
            return Ok(());
        };
        let reason = match self.spec(BrdfId::Engine(*id)) {
            None => "it is not in the BRDF set",
            Some(spec) if spec.tint => {
                "its function takes the tint, and a table entry holds two factors of it \
                 (tinted and white), not a function of it"
            }
            Some(spec) if spec.tangent => {
                "it reads the tangent, and a table is over the three angles of an isotropic BRDF"
            }
            Some(_) => return Ok(()),
        };
        Err(LutError::EngineUntabulable {
            brdf: id.name(),
            reason,
        })
    }

    /// Whether `brdf`'s value has a white part: a built-in as [`Brdf::has_white_part`], an
    /// engine BRDF of this set when it names a `white` function.
    pub fn has_white_part(&self, brdf: &Brdf) -> bool {
        match brdf {
            Brdf::Engine { id, .. } => self
                .spec(BrdfId::Engine(*id))
                .is_some_and(|s| s.white.is_some()),
            _ => brdf.has_white_part(),
        }
    }

    /// The files the shaders include to evaluate the set (`brdf/eval.glsl` includes them), as
    /// (path under the include folder, text). `engine_prefix` is the include path under which
    /// the engine's GLSL files are found (a compiler copies them there, so their names cannot
    /// hide histencil's own includes). For histencil's own set every file is empty of code and
    /// the shaders are those histencil ships, byte for byte. `brdf_set/ids.glsl` alone (the
    /// engine BRDFs' `BRDF_ENGINE_*` ids) is for an engine's own shaders, a G-buffer pass say.
    pub fn glsl_files(&self, engine_prefix: &str) -> [(&'static str, String); 5] {
        let head =
            "// Generated by histencil from a BRDF set (histencil_brdf::BrdfSet). Do not edit.\n";
        let mut ids = format!("{head}#ifndef BRDF_SET_IDS_GLSL\n#define BRDF_SET_IDS_GLSL\n");
        for b in BrdfId::ALL {
            if !self.builtins.contains(&b) {
                ids += &format!("#define BRDF_OMIT_{}\n", b.name().to_uppercase());
            }
        }
        let mut functions = format!("{head}#include \"brdf_set/ids.glsl\"\n");
        let (mut cases, mut parts, mut tinted) =
            (head.to_owned(), head.to_owned(), head.to_owned());
        let mut included: Vec<&str> = Vec::new();
        for (id, spec) in self.engine() {
            let constant = id.glsl_constant();
            ids += &format!("#define {constant} {}u\n", id.index());
            if !included.contains(&spec.glsl.as_str()) {
                functions += &format!("#include \"{engine_prefix}/{}\"\n", spec.glsl);
                included.push(&spec.glsl);
            }
            let call = |f: &str| format!("{f}(p, N, T, V, L)");
            let tinted_part = call(&spec.function);
            match &spec.white {
                // The whole value of a surface of colour `tint`; a white surface's for the
                // switch, and as its parts (no white part), which the probe and brdf-eval read.
                None if spec.tint => {
                    let function = &spec.function;
                    let white_surface = format!("{function}(p, vec3(1.0), N, T, V, L)");
                    cases += &format!("    case {constant}:\n        return {white_surface};\n");
                    tinted += &format!(
                        "    if (model == {constant}) {{\n        return {function}(p, tint, N, T, V, L);\n    }}\n"
                    );
                }
                None => cases += &format!("    case {constant}:\n        return {tinted_part};\n"),
                Some(white) => {
                    let white = call(white);
                    cases += &format!(
                        "    case {constant}:\n        return {tinted_part} + vec3({white});\n"
                    );
                    parts += &format!(
                        "    if (model == {constant}) {{\n        return BrdfParts({tinted_part}, {white});\n    }}\n"
                    );
                    tinted += &format!(
                        "    if (model == {constant}) {{\n        return tint * {tinted_part} + {white};\n    }}\n"
                    );
                }
            }
        }
        // Every id of the set, built-in or the engine's, is below this: what an engine's decode
        // hook sizes its per-id parameter rows with (`BrdfParams::Rows` in histencil-vk).
        let count = (self.engine().map(|(id, _)| id.index() + 1))
            .max()
            .unwrap_or(0)
            .max(BrdfId::ALL.len() as u32);
        ids += &format!("#define BRDF_ID_COUNT {count}u\n#endif\n");
        [
            ("brdf_set/ids.glsl", ids),
            ("brdf_set/functions.glsl", functions),
            ("brdf_set/eval_cases.glsl", cases),
            ("brdf_set/parts.glsl", parts),
            ("brdf_set/tinted.glsl", tinted),
        ]
    }

    /// What glslc's `message` cannot say when it points into the GLSL this set generates
    /// (`brdf_set/...`, [`BrdfSet::glsl_files`]) rather than the engine's own file: which BRDF of
    /// the manifest is called there, and the signature its function must have, for each BRDF
    /// whose function the message names. `None` when the message is not about such a call.
    pub fn generated_call_hint(&self, message: &str) -> Option<String> {
        if !message.contains("brdf_set/") && !message.contains("brdf_set\\") {
            return None;
        }
        let args = "vec3 N, vec3 T, vec3 V, vec3 L";
        let mut lines = Vec::new();
        for (_, spec) in self.engine() {
            // As a whole word: `base(` inside `sheen_base(` is not `base`'s call.
            let named = |f: &str| {
                let call = format!("{f}(");
                message.contains(&format!("'{f}'"))
                    || message.match_indices(&call).any(|(at, _)| {
                        let before = message[..at].chars().next_back();
                        !before.is_some_and(|c| c.is_alphanumeric() || c == '_')
                    })
            };
            let (function, glsl) = (&spec.function, &spec.glsl);
            if named(function) {
                let signature = if spec.tint {
                    format!("vec3 {function}(vec4 p, vec3 tint, {args}) (`tint = true`)")
                } else {
                    format!("vec3 {function}(vec4 p, {args}) (with `tint = true`, it takes `vec3 tint` after `p`)")
                };
                lines.push(format!(
                    "BRDF `{}` of the manifest is called as `{signature}`: `{glsl}` must define \
                     it so",
                    spec.name
                ));
            }
            if let Some(white) = spec.white.as_ref().filter(|w| named(w)) {
                lines.push(format!(
                    "BRDF `{}` of the manifest calls its white part as `float {white}(vec4 p, \
                     {args})`: `{glsl}` must define it so",
                    spec.name
                ));
            }
        }
        (!lines.is_empty()).then(|| {
            format!(
                "the brdf_set/ files are histencil's, generated from the manifest: {}",
                lines.join("; ")
            )
        })
    }

    /// A Rust expression that makes this set again (without its folder), for `include!` in an
    /// engine whose build script compiled it (histencil-build). Every name is spelt by its full
    /// path through the `histencil` crate an engine depends on, so the file compiles whatever
    /// the engine has in scope (a `Range` of its own, say).
    pub fn rust_expression(&self) -> String {
        let builtins: Vec<String> = self
            .builtins
            .iter()
            .map(|b| format!("::histencil::brdf::BrdfId::{b:?}"))
            .collect();
        let mut out = format!(
            "::histencil::brdf::BrdfSet::new(\n    &[{}],\n    vec![\n",
            builtins.join(", ")
        );
        for (_, spec) in &self.engine {
            let params: Vec<String> = spec
                .params
                .iter()
                .map(|p| {
                    format!(
                        "::histencil::brdf::EngineParam {{ name: {:?}.into(), range: ::histencil::brdf::Range::new({:?}, {:?}), default: {:?} }}",
                        p.name, p.range.min, p.range.max, p.default
                    )
                })
                .collect();
            out += &format!(
                "        ::histencil::brdf::EngineBrdfSpec {{\n            name: {:?}.into(),\n            glsl: {:?}.into(),\n            function: {:?}.into(),\n            white: {},\n            params: vec![{}],\n            tangent: {},\n            tint: {},\n        }},\n",
                spec.name,
                spec.glsl,
                spec.function,
                spec.white
                    .as_ref()
                    .map_or("None".into(), |w| format!("Some({w:?}.into())")),
                params.join(", "),
                spec.tangent,
                spec.tint
            );
        }
        out + "    ],\n)\n.expect(\"the set histencil-build compiled\")\n"
    }
}

#[cfg(feature = "files")]
impl BrdfSet {
    /// A BRDF named in a scene file or glTF extras: one of the set's own with its parameters
    /// (numbers; those left out take their defaults), or a built-in as [`Brdf::parse`] reads it.
    ///
    /// # Errors
    /// [`BrdfError`], as [`BrdfSet::engine_brdf`] and [`Brdf::parse`] give it.
    pub fn parse(
        &self,
        name: &str,
        params: &serde_json::Map<String, serde_json::Value>,
    ) -> Result<Brdf, BrdfError> {
        let Some((id, _)) = self.engine.iter().find(|(_, s)| s.name == name) else {
            return Brdf::parse(name, params).map_err(|e| match e {
                BrdfError::UnknownModel(name) if !self.is_builtin_only() => self.unknown(name),
                other => other,
            });
        };
        let mut given = Vec::new();
        for (key, value) in params {
            let x = value.as_f64().ok_or_else(|| BrdfError::BadEngineParam {
                model: id.name(),
                param: key.clone(),
                rule: "a number".into(),
                value: value.to_string(),
            })?;
            given.push((key.as_str(), x));
        }
        self.engine_brdf(name, &given)
    }
}

#[cfg(feature = "files")]
impl BrdfSet {
    /// The refusal of a name this set does not hold: its names, and the nearest of them when a
    /// typo is likely (one or two edits).
    fn unknown(&self, name: String) -> BrdfError {
        let names: Vec<&str> = self.ids().iter().map(|b| b.name()).collect();
        let nearest = (names.iter())
            .map(|n| (edits(n, &name.to_lowercase()), *n))
            .filter(|(d, _)| *d <= 2)
            .min()
            .map_or(String::new(), |(_, n)| format!("; did you mean `{n}`?"));
        BrdfError::UnknownInSet {
            name,
            known: names.join(", "),
            nearest,
        }
    }
}

/// The edit distance between `a` and `b` (insertions, deletions, substitutions, and swaps of
/// two neighbours, the commonest typo).
#[cfg(feature = "files")]
fn edits(a: &str, b: &str) -> usize {
    let (a, b): (Vec<char>, Vec<char>) = (a.chars().collect(), b.chars().collect());
    let mut d = vec![vec![0usize; b.len() + 1]; a.len() + 1];
    for (i, row) in d.iter_mut().enumerate() {
        row[0] = i;
    }
    for (j, cell) in d[0].iter_mut().enumerate() {
        *cell = j;
    }
    for i in 1..=a.len() {
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut best = (d[i - 1][j] + 1)
                .min(d[i][j - 1] + 1)
                .min(d[i - 1][j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                best = best.min(d[i - 2][j - 2] + 1);
            }
            d[i][j] = best;
        }
    }
    d[a.len()][b.len()]
}

/// The first id after the set's last engine BRDF could take: ids below it are histencil's or an
/// engine's, so a G-buffer value past it names no BRDF.
pub const MODEL_IDS: u32 = ENGINE_FIRST + MAX_ENGINE_BRDFS as u32;

#[cfg(test)]
mod tests {
    use super::*;

    pub(crate) fn toon() -> EngineBrdfSpec {
        EngineBrdfSpec {
            name: "toon".into(),
            glsl: "toon.glsl".into(),
            function: "toon".into(),
            white: None,
            params: vec![EngineParam {
                name: "bands".into(),
                range: Range::new(1.0, 8.0),
                default: 3.0,
            }],
            tangent: false,
            tint: false,
        }
    }

    /// A BRDF whose function `metal_rough` takes the tint, in `toon.glsl`.
    fn metal() -> EngineBrdfSpec {
        EngineBrdfSpec {
            name: "metal".into(),
            function: "metal_rough".into(),
            tint: true,
            ..toon()
        }
    }

    #[test]
    fn a_table_holds_an_engine_brdf_unless_it_takes_the_tint_or_reads_the_tangent() {
        let mut sheen = toon();
        sheen.name = "sheen".into();
        sheen.white = Some("sheen_white".into());
        let mut hair = toon();
        hair.name = "hair".into();
        hair.tangent = true;
        let set = BrdfSet::new(&[BrdfId::Ggx], vec![toon(), sheen, hair, metal()]).unwrap();
        let of = |name: &str| set.engine_brdf(name, &[]).unwrap();
        assert_eq!(set.tabulable(&of("toon")), Ok(()));
        // Two factors per entry: the white part is held beside the tinted one.
        assert_eq!(set.tabulable(&of("sheen")), Ok(()));
        assert!(set.has_white_part(&of("sheen")) && !set.has_white_part(&of("toon")));
        let refused = |name: &str| set.tabulable(&of(name)).unwrap_err().to_string();
        assert!(refused("hair").contains("`hair`: it reads the tangent"));
        assert!(refused("metal").contains("`metal`: its function takes the tint"));
        let ggx = Brdf::Ggx {
            alpha: 0.16,
            f0: 0.04,
            f90: 1.0,
        };
        assert_eq!(set.tabulable(&ggx), Ok(()));
        let gltf = Brdf::GltfMetalRough {
            alpha: 0.25,
            metallic: 0.0,
        };
        assert_eq!(set.tabulable(&gltf), Ok(()));
        assert!(set.has_white_part(&gltf));
        // Another set's engine BRDF: not this one's to tabulate.
        let other = BrdfSet::new(&[], vec![toon()]).unwrap();
        let toon_there = other.engine_brdf("toon", &[]).unwrap();
        let mut renamed = toon();
        renamed.name = "ramp".into();
        let mine = BrdfSet::new(&[], vec![renamed]).unwrap();
        assert!(mine.tabulable(&toon_there).is_err());
    }

    /// A function that takes the tint returns the whole value: every technique calls it with
    /// the pixel's colour (`brdf_eval_tinted`), the switch and the parts with a white surface's;
    /// a white part beside it is refused.
    #[test]
    fn a_brdf_that_takes_the_tint_is_called_with_it() {
        let mut metal = metal();
        let set = BrdfSet::new(&[], vec![metal.clone()]).unwrap();
        let files = set.glsl_files("engine");
        let text = |name: &str| &files.iter().find(|(n, _)| *n == name).unwrap().1;
        assert!(text("brdf_set/tinted.glsl").contains("return metal_rough(p, tint, N, T, V, L);"));
        assert!(text("brdf_set/eval_cases.glsl")
            .contains("return metal_rough(p, vec3(1.0), N, T, V, L);"));
        assert!(!text("brdf_set/parts.glsl").contains("metal_rough"));
        assert!(set.rust_expression().contains("tint: true"));
        metal.white = Some("metal_white".into());
        assert_eq!(
            BrdfSet::new(&[], vec![metal]),
            Err(SetError::TintAndWhite("metal".into()))
        );
    }

    /// glslc names the generated file where a function's signature does not match the call:
    /// the hint names the BRDF, its file and the signature the call wants.
    #[test]
    fn a_mismatched_signature_is_explained_from_the_manifest() {
        let metal = metal();
        let set = BrdfSet::new(&[], vec![toon(), metal]).unwrap();
        let message = "/out/set/brdf_set/tinted.glsl:3: error: 'metal_rough' : no matching \
                       overloaded function found";
        let hint = set.generated_call_hint(message).unwrap();
        assert!(
            hint.contains("BRDF `metal`")
                && hint.contains(
                    "vec3 metal_rough(vec4 p, vec3 tint, vec3 N, vec3 T, vec3 V, vec3 L)"
                )
                && hint.contains("`toon.glsl` must define it")
                && !hint.contains("BRDF `toon`"),
            "{hint}"
        );
        assert_eq!(
            set.generated_call_hint("toon.glsl:3: error: 'x' : undeclared"),
            None
        );
        // A call of another function whose name ends in this one's is not its call.
        let other = "brdf_set/tinted.glsl:3: error: in call to my_metal_rough(p, tint";
        assert_eq!(set.generated_call_hint(other), None);
    }

    /// A misspelt name in a scene read with an engine's set names the set's BRDFs, its own
    /// among them, and the nearest; without engine BRDFs the built-ins' refusal stands.
    #[cfg(feature = "files")]
    #[test]
    fn an_unknown_name_lists_the_sets_brdfs_and_the_nearest() {
        let mut metal = toon();
        metal.name = "ue4_standard".into();
        let set = BrdfSet::new(&[BrdfId::Lambert], vec![toon(), metal]).unwrap();
        let none = serde_json::Map::new();
        let text = set.parse("ue4_standrad", &none).unwrap_err().to_string();
        assert!(
            text.contains("holds: lambert, toon, ue4_standard")
                && text.ends_with("did you mean `ue4_standard`?"),
            "{text}"
        );
        let shouted = set.parse("UE4_STANDARD", &none).unwrap_err().to_string();
        assert!(
            shouted.ends_with("did you mean `ue4_standard`?"),
            "{shouted}"
        );
        let far = set.parse("velvet", &none).unwrap_err().to_string();
        assert!(!far.contains("did you mean"), "{far}");
        let builtin = BrdfSet::new(&BrdfId::ALL, vec![]).unwrap();
        assert!(matches!(
            builtin.parse("velvet", &none),
            Err(BrdfError::UnknownModel(_))
        ));
        assert_eq!(edits("abc", "acb"), 1);
        assert_eq!(edits("", "ab"), 2);
    }

    #[test]
    fn ids_follow_the_builtins_and_parameters_take_defaults() {
        let mut sheen = toon();
        sheen.name = "sheen".into();
        sheen.white = Some("sheen_white".into());
        let set = BrdfSet::new(&[BrdfId::Ggx], vec![toon(), sheen]).unwrap();
        let ids = set.ids();
        assert_eq!(ids[0], BrdfId::Ggx);
        assert_eq!(ids[1].index(), ENGINE_FIRST);
        assert_eq!(ids[2].name(), "sheen");
        assert_eq!(set.by_index(ENGINE_FIRST + 1), Some(ids[2]));
        assert!(!set.contains(BrdfId::Lambert));
        let b = set.engine_brdf("toon", &[]).unwrap();
        assert_eq!(b.packed_params(), [3.0, 0.0, 0.0, 0.0]);
        assert_eq!(b.name(), "toon");
        set.check(&b).unwrap();
        assert!(set.check(&Brdf::Lambert { rho: 1.0 }).is_err());
        let files = set.glsl_files("engine");
        assert!(files[0].1.contains("#define BRDF_OMIT_LAMBERT"));
        assert!(!files[0].1.contains("BRDF_OMIT_GGX"));
        assert!(files[0].1.contains("#define BRDF_ENGINE_SHEEN 9u"));
        assert!(files[1].1.contains("#include \"engine/toon.glsl\""));
        // The ids, then one include for two BRDFs of one file.
        assert_eq!(files[1].1.matches("#include").count(), 2);
        assert!(files[2].1.contains("return toon(p, N, T, V, L);"));
        assert!(files[3]
            .1
            .contains("BrdfParts(toon(p, N, T, V, L), sheen_white("));
        // histencil's own set: no code, so the shaders are as shipped.
        for (name, text) in BrdfSet::default().glsl_files("engine") {
            let code = text
                .lines()
                .filter(|l| !l.starts_with("//") && !l.starts_with('#'))
                .count();
            assert_eq!(code, 0, "{name}: {text}");
            assert!(
                !text.contains("BRDF_OMIT") && !text.contains("BRDF_ENGINE"),
                "{text}"
            );
        }
        // The Rust spelling makes the same set.
        let rust = set.rust_expression();
        assert!(
            rust.starts_with(
                "::histencil::brdf::BrdfSet::new(\n    &[::histencil::brdf::BrdfId::Ggx],"
            ),
            "{rust}"
        );
        assert!(
            rust.contains("white: Some(\"sheen_white\".into())"),
            "{rust}"
        );
        assert!(
            rust.contains("::histencil::brdf::Range::new(1.0, 8.0), default: 3.0"),
            "{rust}"
        );
    }

    #[test]
    fn every_bad_declaration_is_refused_with_its_reason() {
        let err = |builtins: &[BrdfId], specs: Vec<EngineBrdfSpec>| {
            BrdfSet::new(builtins, specs).unwrap_err().to_string()
        };
        let with = |f: &dyn Fn(&mut EngineBrdfSpec)| {
            let mut s = toon();
            f(&mut s);
            err(&[], vec![s])
        };
        assert!(err(&[], vec![]).contains("empty"));
        assert!(err(&[BrdfId::Ggx, BrdfId::Ggx], vec![]).contains("`ggx` is named twice"));
        assert!(err(&[], vec![toon(), toon()]).contains("`toon` is named twice"));
        assert!(with(&|s| s.name = "ggx".into()).contains("built-in's name"));
        assert!(with(&|s| s.name = "Toon!".into()).contains("lower-case"));
        assert!(with(&|s| s.function = "gl_x".into()).contains("GLSL function"));
        assert!(with(&|s| s.glsl = "../x.glsl".into()).contains("inside the BRDF folder"));
        assert!(with(&|s| s.glsl = "/etc/x.glsl".into()).contains("inside the BRDF folder"));
        let four = |s: &mut EngineBrdfSpec| s.params = vec![s.params[0].clone(); 4];
        assert!(with(&four).contains("4 parameters; at most 3"));
        assert!(with(&|s| s.params[0].default = 9.0).contains("outside its range"));
        assert!(with(&|s| s.glsl = "toon.frag".into()).contains("must be a `.glsl` file"));
        assert!(with(&|s| s.params[0].name = "tint".into()).contains("in glTF extras"));
        assert!(with(&|s| s.params[0].range = Range::new(2.0, 1.0)).contains("min <= max"));
        let many: Vec<EngineBrdfSpec> = (0..=MAX_ENGINE_BRDFS)
            .map(|i| EngineBrdfSpec {
                name: format!("b{i}"),
                ..toon()
            })
            .collect();
        assert!(err(&[], many).contains("17 BRDFs of your own; a set holds at most 16"));
        let set = BrdfSet::new(&[], vec![toon()]).unwrap();
        let e = |given: &[(&str, f64)]| set.engine_brdf("toon", given).unwrap_err().to_string();
        assert!(e(&[("bands", 9.0)]).contains("`bands` must be a number in [1, 8], got 9"));
        assert!(e(&[("steps", 2.0)]).contains("unknown parameter `steps` (accepted: bands)"));
        assert!(set.engine_brdf("sheen", &[]).is_err());
    }
}
