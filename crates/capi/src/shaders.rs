//! histencil's shaders for an engine's own BRDFs and hooks, through C: compiled at run time from
//! folders with glslc (`histencil_shaders_compile`: the BRDF folder of the book's "Your BRDFs",
//! the hook folder of its "Hooks"), or read from the file `histencil shaders` wrote at the
//! engine's build (`histencil_shaders_load`: no cargo and no glslc where the engine runs). The
//! engine BRDFs are probed on the context's device for NaN, infinities and negative light, and
//! named by a lighting's description and by `histencil_brdf_encode`.

use crate::handles::{self, Kind};
use crate::{call, required, Failure, HistencilResult, Outcome};
use histencil::brdf::{BrdfId, BrdfSet};
use histencil::BrdfModules;
use histencil_vk::ShaderFile;
use std::ffi::{c_char, CStr};

/// histencil's shaders compiled for a BRDF set and, if the engine gave them, its hooks.
pub struct HistencilShaders {
    pub(crate) modules: &'static BrdfModules,
    /// The set with its folder, which `histencil_shaders_write_includes` copies from.
    set: BrdfSet,
    /// Whether the light shaders call the engine's hooks: a lighting made with them takes
    /// `HistencilHooks` (the layouts the hooks' resources are bound with).
    pub(crate) engine_hooks: bool,
    /// A shader file's copy of the BRDF folder, kept while the handle lives.
    _file: Option<ShaderFile>,
}

fn setup(message: String) -> Failure {
    Failure {
        result: HistencilResult::BadSetup,
        message,
    }
}

/// An optional folder argument: null for none.
///
/// # Safety
/// `folder` is null or NUL-terminated.
unsafe fn optional_folder<'a>(folder: *const c_char, what: &str) -> Outcome<Option<&'a str>> {
    if folder.is_null() {
        return Ok(None);
    }
    // SAFETY: the caller's: non-null, so NUL-terminated.
    unsafe { utf8(folder, what) }.map(Some)
}

/// Compiles histencil's shaders (glslc, as `histencil render --brdfs` does; compiled once per
/// set and hooks in a process) for the BRDF folder `brdf_folder` (its `brdfs.toml` and the GLSL
/// files it names, each confined to the folder; null for histencil's own BRDFs) and the hook
/// folder `hooks_folder` (`surface_decode.glsl` and/or `light_visibility.glsl`; null for
/// histencil's G-buffer and no shadows), and probes each engine BRDF on the context's device:
/// one that returns NaN, an infinity or negative light anywhere is refused. With hooks, a
/// lighting made with these shaders takes `HistencilLightingDesc.hooks`.
///
/// Errors: `INVALID_ARGUMENT` for a null or freed handle, a null `shaders`, a folder that is not
/// UTF-8; `BAD_SETUP` for a manifest or GLSL file histencil refuses (the message gives the file
/// and line), a hook folder with neither hook file, a GLSL compile error (glslc's words, with
/// the engine's file and line), a probe that fails; `UNSUPPORTED` when glslc cannot be run.
///
/// Thread safety: not at the same time as another call on `context`.
///
/// # Safety
/// `brdf_folder` and `hooks_folder` are null or NUL-terminated; `shaders` is null or writable.
#[no_mangle]
pub unsafe extern "C" fn histencil_shaders_compile(
    context: *mut crate::HistencilContext,
    brdf_folder: *const c_char,
    hooks_folder: *const c_char,
    shaders: *mut *mut HistencilShaders,
) -> HistencilResult {
    call(|| {
        // SAFETY: the header's thread-safety rule.
        let context = unsafe { handles::get(context, Kind::Context, "context") }?;
        if shaders.is_null() {
            return Err(Failure::invalid("shaders (the out pointer) is null"));
        }
        // SAFETY: this fn's # Safety.
        let (brdfs, hooks) = unsafe {
            (
                optional_folder(brdf_folder, "brdf_folder")?,
                optional_folder(hooks_folder, "hooks_folder")?,
            )
        };
        let set = match brdfs {
            Some(folder) => BrdfSet::load(folder.as_ref()).map_err(|e| setup(e.to_string()))?,
            None => BrdfSet::default(),
        };
        let modules = histencil::vk::compile_brdf_set_with_hooks(&set, hooks.map(AsRef::as_ref))
            .map_err(|e| {
                let result = if e.contains("glslc") && e.contains("No such file") {
                    HistencilResult::Unsupported
                } else {
                    HistencilResult::BadSetup
                };
                Failure { result, message: e }
            })?;
        histencil::probe_brdfs(&context.ctx, modules)?;
        let made = HistencilShaders {
            modules,
            set,
            engine_hooks: hooks.is_some(),
            _file: None,
        };
        // SAFETY: checked non-null; writable by this fn's # Safety.
        unsafe { shaders.write(handles::make(made, Kind::Shaders)) };
        Ok(())
    })
}

/// Reads the shader file `path` that `histencil shaders --brdfs DIR --hooks DIR --out FILE`
/// wrote at the engine's build, with this version of histencil, and probes its engine BRDFs on
/// the context's device as `histencil_shaders_compile` does. Needs no glslc.
///
/// Errors: `INVALID_ARGUMENT` for a null or freed handle or pointer, a path that is not UTF-8;
/// `BAD_SETUP` for a file that cannot be read, is not a shader file, was written by another
/// version, is damaged or cut (its checksum), lacks a module or holds one of the wrong stage,
/// or whose BRDF folder histencil refuses, each naming the file; a probe that fails.
///
/// Thread safety: not at the same time as another call on `context`.
///
/// # Safety
/// `path` is null or NUL-terminated; `shaders` is null or writable.
#[no_mangle]
pub unsafe extern "C" fn histencil_shaders_load(
    context: *mut crate::HistencilContext,
    path: *const c_char,
    shaders: *mut *mut HistencilShaders,
) -> HistencilResult {
    call(|| {
        // SAFETY: the header's thread-safety rule.
        let context = unsafe { handles::get(context, Kind::Context, "context") }?;
        // SAFETY: this fn's # Safety.
        let path = unsafe { utf8(path, "path") }?;
        if shaders.is_null() {
            return Err(Failure::invalid("shaders (the out pointer) is null"));
        }
        let file = histencil_vk::read_shader_file(path.as_ref()).map_err(setup)?;
        histencil::probe_brdfs(&context.ctx, file.modules)?;
        let made = HistencilShaders {
            modules: file.modules,
            set: file.set.clone(),
            engine_hooks: !file.hooks.is_empty(),
            _file: Some(file),
        };
        // SAFETY: checked non-null; writable by this fn's # Safety.
        unsafe { shaders.write(handles::make(made, Kind::Shaders)) };
        Ok(())
    })
}

/// Frees the handle. Lightings made with the shaders keep what they need: it may go at once.
///
/// Errors: `INVALID_ARGUMENT` for a null or freed handle.
///
/// Thread safety: not at the same time as another call naming `shaders`.
///
/// # Safety
/// `shaders` is null or a handle from `histencil_shaders_compile` or `histencil_shaders_load`
/// (a freed one is refused).
#[no_mangle]
pub unsafe extern "C" fn histencil_shaders_destroy(
    shaders: *mut HistencilShaders,
) -> HistencilResult {
    call(|| {
        // SAFETY: the header's thread-safety rule.
        drop(unsafe { handles::take(shaders, Kind::Shaders, "shaders") }?);
        Ok(())
    })
}

/// Writes what histencil's shaders include to evaluate the shaders' BRDF set into `folder`
/// (`brdf_set/*.glsl` and the engine's GLSL files under their own folder): put `folder` before
/// the installed `share/histencil/shaders/include` on glslc's include path, and an engine's own
/// shader that includes `light.glsl` (a forward reference) evaluates the set's BRDFs as
/// histencil does; a G-buffer shader includes `brdf_set/ids.glsl` for the ids.
///
/// Errors: `INVALID_ARGUMENT` for a null or freed handle or pointer; `BAD_SETUP` when the folder
/// cannot be written (the message names the file).
///
/// Thread safety: any thread, not at the same time as `histencil_shaders_destroy(shaders)`.
///
/// # Safety
/// `folder` is null or NUL-terminated.
#[no_mangle]
pub unsafe extern "C" fn histencil_shaders_write_includes(
    shaders: *mut HistencilShaders,
    folder: *const c_char,
) -> HistencilResult {
    call(|| {
        // SAFETY: the header's thread-safety rule.
        let held = unsafe { handles::get(shaders, Kind::Shaders, "shaders") }?;
        // SAFETY: this fn's # Safety.
        let folder = unsafe { utf8(folder, "folder") }?;
        histencil_build::stage_brdf_set(&held.set, folder.as_ref())
            .map_err(|e| setup(e.to_string()))?;
        Ok(())
    })
}

/// The shaders a lighting or encode names: `shaders`, or histencil's own for null.
///
/// # Safety
/// As [`handles::get`].
pub(crate) unsafe fn shaders_of<'a>(
    shaders: *const HistencilShaders,
) -> Outcome<Option<&'a HistencilShaders>> {
    if shaders.is_null() {
        return Ok(None);
    }
    // SAFETY: the caller's.
    unsafe { handles::get(shaders.cast_mut(), Kind::Shaders, "shaders") }.map(|s| Some(&*s))
}

/// The modules of [`shaders_of`]'s answer.
///
/// # Safety
/// As [`handles::get`].
pub(crate) unsafe fn modules_of(shaders: *const HistencilShaders) -> Outcome<&'static BrdfModules> {
    // SAFETY: the caller's.
    Ok(unsafe { shaders_of(shaders) }?.map_or(BrdfModules::builtin(), |s| s.modules))
}

/// `name` as an id of `modules`' set, or the error listing the names it holds.
pub(crate) fn brdf_named(modules: &BrdfModules, name: &str) -> Outcome<BrdfId> {
    let ids = modules.set.ids();
    ids.iter()
        .copied()
        .find(|b| b.name() == name)
        .ok_or_else(|| {
            let known: Vec<&str> = ids.iter().map(|b| b.name()).collect();
            setup(format!(
                "no BRDF named `{name}` in the lighting's set ({}); an engine's own come from \
             histencil_shaders_compile or histencil_shaders_load",
                known.join(", ")
            ))
        })
}

/// # Safety
/// `name` is null or NUL-terminated.
pub(crate) unsafe fn utf8<'a>(name: *const c_char, what: &str) -> Outcome<&'a str> {
    // SAFETY: the caller's, after the null check.
    let name = unsafe { required(name, what) }?;
    // SAFETY: as above: a non-null name is NUL-terminated.
    unsafe { CStr::from_ptr(name) }
        .to_str()
        .map_err(|_| Failure::invalid(format!("{what} is not UTF-8")))
}
