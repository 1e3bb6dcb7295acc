//! Parameters per material, not per BRDF: an engine's materials as rows that its decode hook
//! reads by the material index its G-buffer carries.
//!
//! A G-buffer that stores a BRDF id and reads the BRDF's parameters from a row per id gives
//! every surface of one BRDF the same roughness; a second roughness then needs a second BRDF
//! name. Here each row is a material: its BRDF's id and packed parameters, so two materials of
//! one BRDF differ in their rows and share their BRDF (its stencil id, its light shader). The
//! other way, parameters the G-buffer carries per pixel (histencil's own G-buffer, the example
//! engine's compact one), needs no rows at all.
//!
//! # The row, in GLSL
//! One row is 32 bytes, the same in std140 and std430:
//!
//! ```glsl
//! struct MaterialRow {
//!     vec4 params; // Brdf::packed_params: p.xyz the parameters, p.w 0
//!     uvec4 brdf;  // x: BrdfId::index; y, z, w 0
//! };
//! ```
//!
//! `examples/hooks/two_target/surface_decode.glsl` reads them from a uniform block of 256 rows
//! (an 8-bit index in its G-buffer): [`MaterialRows::check_capacity`] holds the rows to what a
//! hook declares. The book's "hooks" chapter shows the whole hook.

use crate::id::BrdfId;
use crate::model::{Brdf, BrdfError};
use crate::set::BrdfSet;

/// Bytes of one row: a `vec4` of parameters and a `uvec4` holding the BRDF id.
pub const MATERIAL_ROW_BYTES: usize = 32;

/// Why materials could not be made rows.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MaterialError {
    /// No material at all: a decode hook would index an empty buffer.
    #[error("no materials: give at least one (a decode hook indexes the rows by material)")]
    Empty,
    /// More materials than the decode hook's rows hold (or its G-buffer's index can name).
    #[error("{count} materials, and the decode hook holds {rows} rows: materials past them could not be named or read")]
    TooMany {
        /// How many materials.
        count: usize,
        /// The rows the hook declares.
        rows: usize,
    },
    /// A material whose BRDF the set does not hold, or whose parameters it refuses.
    #[error("material {index}: {source}")]
    Material {
        /// The material's index, as the G-buffer carries it.
        index: usize,
        /// What the set said.
        source: BrdfError,
    },
}

/// An engine's materials in G-buffer index order, each checked against the BRDF set the light
/// shaders were compiled for.
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialRows {
    materials: Vec<Brdf>,
}

impl MaterialRows {
    /// Rows for `materials`, in the order the G-buffer's material index names them.
    ///
    /// # Errors
    /// [`MaterialError::Empty`] for no material, and [`MaterialError::Material`] naming the
    /// first material whose BRDF `set` does not hold or whose parameters are out of range.
    pub fn new(set: &BrdfSet, materials: &[Brdf]) -> Result<Self, MaterialError> {
        if materials.is_empty() {
            return Err(MaterialError::Empty);
        }
        for (index, m) in materials.iter().enumerate() {
            set.check(m)
                .map_err(|source| MaterialError::Material { index, source })?;
        }
        Ok(Self {
            materials: materials.to_vec(),
        })
    }

    /// Refuses more materials than `rows`, the rows the decode hook declares (256 in the book's
    /// two-target hook, whose G-buffer holds an 8-bit index): a material past them would be
    /// written past the hook's buffer and never read.
    ///
    /// # Errors
    /// [`MaterialError::TooMany`].
    pub fn check_capacity(&self, rows: usize) -> Result<(), MaterialError> {
        let count = self.materials.len();
        if count > rows {
            return Err(MaterialError::TooMany { count, rows });
        }
        Ok(())
    }

    /// The materials, by index.
    pub fn materials(&self) -> &[Brdf] {
        &self.materials
    }

    /// The distinct BRDFs of the materials in first-use order: what a lighting of these
    /// materials shades (`LightingDesc::brdfs` in histencil-vk), each once however many
    /// materials share it.
    pub fn brdfs(&self) -> Vec<BrdfId> {
        let mut ids: Vec<BrdfId> = Vec::new();
        for m in &self.materials {
            if !ids.contains(&m.id()) {
                ids.push(m.id());
            }
        }
        ids
    }

    /// The rows as the decode hook's buffer holds them ([`MATERIAL_ROW_BYTES`] each, little
    /// endian as every Vulkan device is): the packed parameters as four `f32`, then the BRDF
    /// id and three zeros as `u32`.
    pub fn bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(self.materials.len() * MATERIAL_ROW_BYTES);
        for m in &self.materials {
            for p in m.packed_params() {
                out.extend((p as f32).to_le_bytes());
            }
            for word in [m.id().index(), 0, 0, 0] {
                out.extend(word.to_le_bytes());
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ggx(alpha: f64) -> Brdf {
        Brdf::Ggx {
            alpha,
            f0: 0.04,
            f90: 1.0,
        }
    }

    /// Two roughnesses of one BRDF are two rows of one BRDF: the lighting shades it once.
    #[test]
    fn materials_of_one_brdf_share_it_and_keep_their_own_parameters() {
        let set = BrdfSet::new(&BrdfId::ALL, vec![]).unwrap();
        let lambert = Brdf::Lambert { rho: 0.5 };
        let rows = MaterialRows::new(&set, &[ggx(0.2), lambert, ggx(0.6)]).unwrap();
        assert_eq!(rows.brdfs(), [BrdfId::Ggx, BrdfId::Lambert]);
        let bytes = rows.bytes();
        assert_eq!(bytes.len(), 3 * MATERIAL_ROW_BYTES);
        let word = |row: usize, i: usize| {
            let at = row * MATERIAL_ROW_BYTES + 4 * i;
            <[u8; 4]>::try_from(&bytes[at..at + 4]).unwrap()
        };
        assert_eq!(f32::from_le_bytes(word(0, 0)), 0.2);
        assert_eq!(f32::from_le_bytes(word(2, 0)), 0.6);
        assert_eq!(u32::from_le_bytes(word(2, 4)), BrdfId::Ggx.index());
        assert_eq!(u32::from_le_bytes(word(1, 4)), BrdfId::Lambert.index());
        assert_eq!(u32::from_le_bytes(word(1, 5)), 0);
    }

    #[test]
    fn a_material_the_set_refuses_is_named_by_its_index() {
        let set = BrdfSet::new(&[BrdfId::Ggx], vec![]).unwrap();
        let err = MaterialRows::new(&set, &[ggx(0.2), Brdf::Lambert { rho: 0.5 }]).unwrap_err();
        assert!(
            matches!(err, MaterialError::Material { index: 1, .. }),
            "{err}"
        );
        assert!(err.to_string().starts_with("material 1: "), "{err}");
        let err = MaterialRows::new(&set, &[ggx(7.0)]).unwrap_err();
        assert!(
            matches!(err, MaterialError::Material { index: 0, .. }),
            "{err}"
        );
        assert_eq!(MaterialRows::new(&set, &[]), Err(MaterialError::Empty));
        let rows = MaterialRows::new(&set, &[ggx(0.2); 3]).unwrap();
        assert_eq!(rows.check_capacity(3), Ok(()));
        let err = rows.check_capacity(2).unwrap_err();
        assert_eq!(err, MaterialError::TooMany { count: 3, rows: 2 });
    }
}
