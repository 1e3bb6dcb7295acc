//! The LUT technique's tables through C: one table per material of the engine's (a BRDF by name
//! with its parameters), baked at one resolution and uploaded, then lent to a lighting whose
//! `HISTENCIL_TECHNIQUE_LUT` frames read each pixel's table by the G-buffer's material index.

use crate::gbuffer::brdf_of;
use crate::handles::{self, Kind};
use crate::lighting::HistencilLighting;
use crate::shaders::{shaders_of, utf8, HistencilShaders};
use crate::{call, slice, Failure, HistencilBrdfParam, HistencilContext, HistencilResult};
use histencil::{BrdfModules, Context, LutTables};
use std::ffi::c_char;
use std::sync::Arc;

/// A material: a BRDF by name with its parameters (an engine BRDF's left out take their
/// defaults).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct HistencilMaterial {
    /// The BRDF's name, NUL-terminated.
    pub brdf_name: *const c_char,
    /// How many parameters.
    pub param_count: u32,
    /// The parameters by name.
    pub params: *const HistencilBrdfParam,
}

/// The LUT technique's tables, one per material in the order the G-buffer's material index
/// names them.
pub struct HistencilLutTables {
    tables: LutTables<Arc<Context>>,
}

/// The most materials a set of tables holds: far past what the G-buffer indexes.
const MAX_MATERIALS: u32 = 1 << 12;

/// Bakes one table per material at `resolution` grid points per axis (a built-in's from its f64
/// reference on the CPU, an engine BRDF's by its own GLSL on the GPU, waited for) and uploads
/// them.
///
/// Errors: `INVALID_ARGUMENT` for a null or freed handle or pointer, too many materials;
/// `BAD_SETUP` for a BRDF the shaders' set lacks, parameters out of range, a resolution
/// histencil-brdf refuses, a BRDF no table can hold (the message says why: a function that
/// takes the tint, the tangent read, light where N.L <= 0), or a BRDF of the shaders' set that
/// returns NaN, an infinity or negative light where the probe evaluates it; `DEVICE_LIMIT` when the values pass the device's storage-buffer range.
///
/// Thread safety: not at the same time as another call on `context`.
///
/// # Safety
/// `materials` is null or points at `material_count` materials whose pointers hold what they
/// say; `shaders` is null or a live handle; `tables` is null or writable.
#[no_mangle]
pub unsafe extern "C" fn histencil_lut_tables_create(
    context: *mut HistencilContext,
    shaders: *const HistencilShaders,
    materials: *const HistencilMaterial,
    material_count: u32,
    resolution: u32,
    tables: *mut *mut HistencilLutTables,
) -> HistencilResult {
    call(|| {
        // SAFETY: the header's thread-safety rule.
        let context = unsafe { handles::get(context, Kind::Context, "context") }?;
        if tables.is_null() {
            return Err(Failure::invalid("tables (the out pointer) is null"));
        }
        if material_count > MAX_MATERIALS {
            return Err(Failure::invalid(format!(
                "material_count is {material_count}, past {MAX_MATERIALS}"
            )));
        }
        // SAFETY: this fn's # Safety.
        let modules = unsafe { shaders_of(shaders) }?.map_or(BrdfModules::builtin(), |s| s.modules);
        // SAFETY: as above: `material_count` materials.
        let given = unsafe { slice(materials, material_count, "materials") }?;
        let mut brdfs = Vec::with_capacity(given.len());
        for (i, m) in given.iter().enumerate() {
            // SAFETY: this fn's # Safety: each name NUL-terminated, its parameters counted.
            let (name, params) = unsafe {
                (
                    utf8(m.brdf_name, &format!("materials[{i}].brdf_name"))?,
                    slice(m.params, m.param_count, &format!("materials[{i}].params"))?,
                )
            };
            brdfs.push(brdf_of(modules, name, params)?);
        }
        let made = LutTables::with_modules(context.ctx.clone(), modules, &brdfs, resolution)?;
        let handle = handles::make(HistencilLutTables { tables: made }, Kind::LutTables);
        // SAFETY: checked non-null; writable by this fn's # Safety.
        unsafe { tables.write(handle) };
        Ok(())
    })
}

/// Points `lighting`'s `HISTENCIL_TECHNIQUE_LUT` frames at `tables`. Refused with `IN_FLIGHT`
/// while a slot of the lighting is not declared finished (the binding is rewritten in place).
///
/// Errors: `INVALID_ARGUMENT` for a null or freed handle; `IN_FLIGHT` as above.
///
/// Thread safety: not at the same time as another call on `lighting` or `tables`.
///
/// # Safety
/// `lighting` and `tables` are null or handles (freed ones are refused).
#[no_mangle]
pub unsafe extern "C" fn histencil_lighting_set_lut_tables(
    lighting: *mut HistencilLighting,
    tables: *mut HistencilLutTables,
) -> HistencilResult {
    call(|| {
        // SAFETY: the header's thread-safety rule.
        let held = unsafe { handles::get(lighting, Kind::Lighting, "lighting") }?;
        // SAFETY: as above.
        let tables = unsafe { handles::get(tables, Kind::LutTables, "tables") }?;
        if held.lighting.in_flight() {
            return Err(Failure {
                result: HistencilResult::InFlight,
                message: "frames in flight: the tables' binding is rewritten in place, which a \
                          frame still pending may read: declare its slots finished first"
                    .into(),
            });
        }
        // SAFETY: no slot of the lighting is pending (checked above), and the tables outlive
        // every command buffer recorded with them: freeing them leaves their buffers to the
        // context until it is destroyed (`histencil_lut_tables_destroy`), which is refused
        // while a lighting lives.
        unsafe { held.lighting.set_lut_tables(&tables.tables) };
        Ok(())
    })
}

/// Frees the handle. Any lighting may have bound the tables and histencil sees no fence, so
/// their GPU buffers stay with the context until `histencil_context_destroy`.
///
/// Errors: `INVALID_ARGUMENT` for a null or freed handle.
///
/// Thread safety: not at the same time as another call naming `tables`.
///
/// # Safety
/// `tables` is null or a handle from `histencil_lut_tables_create` (a freed one is refused).
#[no_mangle]
pub unsafe extern "C" fn histencil_lut_tables_destroy(
    tables: *mut HistencilLutTables,
) -> HistencilResult {
    call(|| {
        // SAFETY: the header's thread-safety rule.
        drop(unsafe { handles::take(tables, Kind::LutTables, "tables") }?);
        Ok(())
    })
}
