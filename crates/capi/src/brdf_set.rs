//! An engine's own BRDFs through C: a folder (`brdfs.toml` and its GLSL, the book's "Your
//! BRDFs") compiled at run time with glslc into every shader that evaluates them, probed on the
//! context's device for NaN, infinities and negative light, and named by a lighting's
//! description and by `histencil_brdf_encode`.

use crate::handles::{self, Kind};
use crate::{call, required, Failure, HistencilResult, Outcome};
use histencil::brdf::{BrdfId, BrdfSet};
use histencil::BrdfModules;
use std::ffi::{c_char, CStr};

/// A BRDF set and the shaders compiled for it.
pub struct HistencilBrdfSet {
    pub(crate) modules: &'static BrdfModules,
}

fn setup(message: String) -> Failure {
    Failure {
        result: HistencilResult::BadSetup,
        message,
    }
}

/// Reads the BRDF folder `folder` (its `brdfs.toml` and the GLSL files it names, each confined
/// to the folder), compiles histencil's shaders for the set (glslc, as `histencil render
/// --brdfs` does; compiled once per set in a process) and probes each engine BRDF on the
/// context's device: one that returns NaN, an infinity or negative light anywhere is refused.
///
/// Errors: `INVALID_ARGUMENT` for a null or freed handle or pointer, a folder that is not UTF-8;
/// `BAD_SETUP` for a manifest or GLSL file histencil refuses (the message gives the file and
/// line), a GLSL compile error (glslc's words, with the engine's file and line), a probe that
/// fails; `UNSUPPORTED` when glslc cannot be run.
///
/// Thread safety: not at the same time as another call on `context`.
///
/// # Safety
/// `folder` is null or NUL-terminated; `set` is null or writable.
#[no_mangle]
pub unsafe extern "C" fn histencil_brdf_set_load(
    context: *mut crate::HistencilContext,
    folder: *const c_char,
    set: *mut *mut HistencilBrdfSet,
) -> HistencilResult {
    call(|| {
        // SAFETY: the header's thread-safety rule.
        let context = unsafe { handles::get(context, Kind::Context, "context") }?;
        if folder.is_null() || set.is_null() {
            return Err(Failure::invalid("folder or set is null"));
        }
        // SAFETY: this fn's # Safety: NUL-terminated.
        let folder = unsafe { CStr::from_ptr(folder) }
            .to_str()
            .map_err(|_| Failure::invalid("folder is not UTF-8"))?;
        let loaded = BrdfSet::load(folder.as_ref()).map_err(|e| setup(e.to_string()))?;
        let modules = histencil::compile_brdf_set(&loaded).map_err(|e| {
            let result = if e.contains("glslc") && e.contains("No such file") {
                HistencilResult::Unsupported
            } else {
                HistencilResult::BadSetup
            };
            Failure { result, message: e }
        })?;
        histencil::probe_brdfs(&context.ctx, modules)?;
        let handle = handles::make(HistencilBrdfSet { modules }, Kind::BrdfSet);
        // SAFETY: checked non-null; writable by this fn's # Safety.
        unsafe { set.write(handle) };
        Ok(())
    })
}

/// Frees the handle. Lightings made with the set keep what they need: it may go at once.
///
/// Errors: `INVALID_ARGUMENT` for a null or freed handle.
///
/// Thread safety: not at the same time as another call naming `set`.
///
/// # Safety
/// `set` is null or a handle from `histencil_brdf_set_load` (a freed one is refused).
#[no_mangle]
pub unsafe extern "C" fn histencil_brdf_set_destroy(set: *mut HistencilBrdfSet) -> HistencilResult {
    call(|| {
        // SAFETY: the header's thread-safety rule.
        drop(unsafe { handles::take(set, Kind::BrdfSet, "set") }?);
        Ok(())
    })
}

/// Writes what histencil's shaders include to evaluate the set into `folder` (`brdf_set/*.glsl`
/// and the engine's GLSL files under their own folder): put `folder` before the installed
/// `share/histencil/shaders/include` on glslc's include path, and an engine's own shader that
/// includes `light.glsl` (a forward reference) evaluates the set's BRDFs as histencil does.
///
/// Errors: `INVALID_ARGUMENT` for a null or freed handle or pointer; `VULKAN` never;
/// `BAD_SETUP` when the folder cannot be written (the message names the file).
///
/// Thread safety: any thread, not at the same time as `histencil_brdf_set_destroy(set)`.
///
/// # Safety
/// `folder` is null or NUL-terminated.
#[no_mangle]
pub unsafe extern "C" fn histencil_brdf_set_write_includes(
    set: *mut HistencilBrdfSet,
    folder: *const c_char,
) -> HistencilResult {
    call(|| {
        // SAFETY: the header's thread-safety rule.
        let held = unsafe { handles::get(set, Kind::BrdfSet, "set") }?;
        // SAFETY: this fn's # Safety.
        let folder = unsafe { utf8(folder, "folder") }?;
        histencil_build::stage_brdf_set(&held.modules.set, folder.as_ref())
            .map_err(|e| setup(e.to_string()))?;
        Ok(())
    })
}

/// The set's shaders: `set`'s, or histencil's own for a null `set`.
///
/// # Safety
/// As [`handles::get`].
pub(crate) unsafe fn modules_of(set: *const HistencilBrdfSet) -> Outcome<&'static BrdfModules> {
    if set.is_null() {
        return Ok(BrdfModules::builtin());
    }
    // SAFETY: the caller's.
    let held = unsafe { handles::get(set.cast_mut(), Kind::BrdfSet, "brdf_set") }?;
    Ok(held.modules)
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
             histencil_brdf_set_load",
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
