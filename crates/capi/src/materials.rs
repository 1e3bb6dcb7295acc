//! Parameters per material through C: the rows a decode hook reads by the material index its
//! G-buffer carries (`histencil_brdf::MaterialRows`, the book's two-target hook), written for
//! the engine, and held to the BRDFs a lighting shades.

use crate::gbuffer::brdf_of;
use crate::handles::{self, Kind};
use crate::lighting::HistencilLighting;
use crate::lut::HistencilMaterial;
use crate::shaders::{shaders_of, utf8, HistencilShaders};
use crate::{call, slice, Failure, HistencilResult, Outcome};
use histencil::brdf::{Brdf, MaterialRows, MATERIAL_ROW_BYTES};
use histencil::BrdfModules;

/// Bytes of one material row: four floats of parameters (`vec4`), then the BRDF id and three
/// zeros (`uvec4`); the same in std140 and std430.
pub const HISTENCIL_MATERIAL_ROW_BYTES: u32 = 32;
// A number the header can spell, held to the Rust layout's.
const _: () = assert!(HISTENCIL_MATERIAL_ROW_BYTES as usize == MATERIAL_ROW_BYTES);

/// The most materials one call takes: far past what an 8- or 16-bit G-buffer index names.
const MAX_MATERIALS: u32 = 1 << 16;

/// The rows of `material_count` materials of `modules`' set, each checked against it.
///
/// # Safety
/// `materials` is null or points at `material_count` materials whose pointers hold what they
/// say.
unsafe fn rows_of(
    modules: &'static BrdfModules,
    materials: *const HistencilMaterial,
    material_count: u32,
) -> Outcome<MaterialRows> {
    if material_count > MAX_MATERIALS {
        return Err(Failure::invalid(format!(
            "material_count is {material_count}, past {MAX_MATERIALS}"
        )));
    }
    // SAFETY: this fn's # Safety: `material_count` materials.
    let given = unsafe { slice(materials, material_count, "materials") }?;
    let mut brdfs: Vec<Brdf> = Vec::with_capacity(given.len());
    for (i, m) in given.iter().enumerate() {
        // SAFETY: this fn's # Safety: each name NUL-terminated, its parameters counted.
        let (name, params) = unsafe {
            (
                utf8(m.brdf_name, &format!("materials[{i}].brdf_name"))?,
                slice(m.params, m.param_count, &format!("materials[{i}].params"))?,
            )
        };
        let brdf = brdf_of(modules, name, params).map_err(|f| Failure {
            message: format!("materials[{i}]: {}", f.message),
            ..f
        })?;
        brdfs.push(brdf);
    }
    MaterialRows::new(&modules.set, &brdfs).map_err(|e| Failure {
        result: HistencilResult::BadSetup,
        message: e.to_string(),
    })
}

/// Writes the rows of `material_count` materials (BRDFs by name with their parameters, of
/// histencil's own BRDFs and those of `shaders`) into `rows`, `HISTENCIL_MATERIAL_ROW_BYTES`
/// each, in order: what a decode hook reading rows by material index binds (the book's
/// two-target hook: a uniform block of 256 rows). Nothing is written on an error.
///
/// Errors: `INVALID_ARGUMENT` for a null pointer, no material, more than 65536, or `rows_size`
/// under `material_count * HISTENCIL_MATERIAL_ROW_BYTES`; `BAD_SETUP` for a BRDF the set lacks
/// or parameters out of range, naming the material.
///
/// Thread safety: any thread, not at the same time as `histencil_shaders_destroy(shaders)`.
///
/// # Safety
/// `shaders` is null (histencil's own BRDFs) or a live handle; `materials` is null or points at
/// `material_count` materials whose pointers hold what they say; `rows` is null or writable for
/// `rows_size` bytes.
#[no_mangle]
pub unsafe extern "C" fn histencil_material_rows_write(
    shaders: *const HistencilShaders,
    materials: *const HistencilMaterial,
    material_count: u32,
    rows: *mut u8,
    rows_size: usize,
) -> HistencilResult {
    call(|| {
        if rows.is_null() {
            return Err(Failure::invalid("rows is null"));
        }
        if material_count == 0 {
            return Err(Failure::invalid(
                "material_count is 0: a decode hook indexes the rows by material",
            ));
        }
        // SAFETY: this fn's # Safety.
        let modules = unsafe { shaders_of(shaders) }?.map_or(BrdfModules::builtin(), |s| s.modules);
        // SAFETY: this fn's # Safety.
        let made = unsafe { rows_of(modules, materials, material_count) }?;
        let bytes = made.bytes();
        if rows_size < bytes.len() {
            return Err(Failure::invalid(format!(
                "rows_size is {rows_size}, and {material_count} rows take {} bytes",
                bytes.len()
            )));
        }
        // SAFETY: `rows` is writable for `rows_size` >= `bytes.len()` bytes (this fn's
        // # Safety), and a slice of ours does not overlap the engine's memory.
        unsafe { std::ptr::copy_nonoverlapping(bytes.as_ptr(), rows, bytes.len()) };
        Ok(())
    })
}

/// Holds `material_count` materials (as `histencil_material_rows_write` takes them) to the BRDFs
/// `lighting` shades (its `brdf_names`): a material of another BRDF would get no light pass
/// under the stencil technique and no tile class under tiled, its pixels unlit with no error.
/// Call it whenever the rows change.
///
/// Errors: `INVALID_ARGUMENT` for a null or freed handle, a null pointer, no material or more
/// than 65536; `BAD_SETUP` for a BRDF the lighting's set lacks, parameters out of range, or a
/// material whose BRDF the lighting does not shade, naming the material.
///
/// Thread safety: not at the same time as another call naming `lighting`.
///
/// # Safety
/// `lighting` is null or a handle (a freed one is refused); `materials` is null or points at
/// `material_count` materials whose pointers hold what they say.
#[no_mangle]
pub unsafe extern "C" fn histencil_lighting_check_materials(
    lighting: *mut HistencilLighting,
    materials: *const HistencilMaterial,
    material_count: u32,
) -> HistencilResult {
    call(|| {
        // SAFETY: the header's thread-safety rule.
        let held = unsafe { handles::get(lighting, Kind::Lighting, "lighting") }?;
        if material_count == 0 {
            return Err(Failure::invalid(
                "material_count is 0: give the materials to check",
            ));
        }
        // SAFETY: this fn's # Safety.
        let rows = unsafe { rows_of(held.modules, materials, material_count) }?;
        held.lighting.check_materials(&rows)?;
        Ok(())
    })
}
