//! AMD's hierarchical stencil on the GPU, as `histencil_model::amd` models it: unlike the
//! consoles', no plan step drives it. The GPU keeps, per 8x8 tile, a summary of the stencil
//! (GFX9-11: whether some pixel may pass each of two pretests; GFX12: the AND and the OR of the
//! values), made from the G-buffer pass's stencil and updated wherever a draw writes, and rejects
//! the tiles of a stencil-testing draw the summary rules out. Since every tile's summary is
//! exact for its current values, the emulation evaluates it from the stencil itself just before
//! each such draw (`HiStencilSurface::record_evaluate`), into the surface the light shaders and
//! the statistics draws already read for the consoles. The CPU simulator's `run_with` is its
//! oracle: the same tiles tested and rejected, the same fragments shaded.

use histencil_model::amd::{Pretest, PRETEST_SLOTS};
use histencil_model::{CompareOp, FaceStencil, Pass};

/// What an AMD hierarchy asks of each tile's current stencil before a draw that tests stencil
/// (`hi_stencil_update.comp`, modes 1 and 2).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TileTest {
    /// GFX9-11: each of these pretests (mask, value: an EQUAL of `stencil & mask`), the ones the
    /// draw's test implies, has a passing pixel in the tile.
    Pretests([Option<(u8, u8)>; PRETEST_SLOTS]),
    /// GFX12: the tile's AND and OR of its values leave this stencil test (compare, mask,
    /// reference) possible.
    AndOr {
        compare: CompareOp,
        mask: u8,
        reference: u8,
    },
}

/// The GPU hierarchy a frame's lighting follows, on the AMD platforms.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GpuHierarchy {
    /// GFX9-11 with these pretests bound before the G-buffer pass
    /// (`histencil_model::amd::choose_pretests`).
    Pretests([Option<Pretest>; PRETEST_SLOTS]),
    /// GFX12's AND/OR tiles; without `read_mask`, the known-wrong case that compares every
    /// bit whatever the test's read mask (`histencil_model::amd::AndOrTiles::unmasked`).
    AndOr { read_mask: bool },
}

impl GpuHierarchy {
    /// What the hierarchy asks of each tile before `pass`, or `None` where it does not test the
    /// pass: the model's decision ([`histencil_model::amd::hierarchy_test`]), which the
    /// simulator holds the GPU's frames to.
    pub fn test_for(&self, pass: &Pass) -> Option<TileTest> {
        histencil_model::amd::hierarchy_test(pass).map(|face| self.test_of(&face))
    }

    fn test_of(&self, face: &FaceStencil) -> TileTest {
        match self {
            GpuHierarchy::Pretests(pretests) => {
                let mut implied = pretests
                    .iter()
                    .flatten()
                    .filter(|p| p.implied_by(face))
                    .map(|p| (p.mask, p.value));
                TileTest::Pretests([implied.next(), implied.next()])
            }
            GpuHierarchy::AndOr { read_mask } => TileTest::AndOr {
                compare: face.compare,
                mask: if *read_mask { face.compare_mask } else { 0xFF },
                reference: face.reference,
            },
        }
    }
}
