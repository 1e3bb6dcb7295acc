//! Today's AMD hierarchical stencil, as two more platforms: modelled from AMD's published driver
//! sources (PAL, GPUOpen-Drivers/pal at c5e80007, 2025-04-29), **not measured on AMD
//! hardware**. Unlike the consoles' hi-stencil, no plan step drives either: the GPU watches every
//! stencil write and may reject the tiles of any stencil-testing draw. So both run the native
//! plan, and the simulator ([`crate::Simulator::run_with`]) keeps the per-tile state beside it.
//!
//! **amd-pretest (GFX9 to GFX11: Vega, RDNA 1-3).** `inc/core/palCmdBuffer.h` lines 1773-1829:
//! two *pretests* per stencil image (`NumHiSPretests = 2`), each a compare function, an 8-bit
//! mask and an 8-bit value, evaluated as `value OP stencil` after masking both; "the stencil
//! image will track the results of the pretest for each 8x8 tile, keeping a record of whether
//! any pixel in the tile may-pass or may-fail" (two bits per pretest in the HTile word,
//! `gfx9MaskRam.cpp` lines 3340-3343). A pretest may be bound over a slot an initialisation
//! barrier reset; replacing one needs that reset *and* a rewrite of every stencil value before
//! the next stencil-testing draw (lines 1782-1793): the nearest thing to the consoles' flush,
//! and far dearer (the stencil must be rewritten, not just a surface copied). The frame
//! therefore binds its two pretests once, before the G-buffer pass, on the BRDF field: the two
//! BRDF slots [`choose_pretests`] picks are culled hierarchically, the others per pixel only.
//! Assumptions PAL does not document: a draw's stencil test uses a pretest when passing the test
//! implies passing the pretest (both `Equal`, the pretest's mask inside the test's, the
//! reference agreeing on it), and a tile where the pretest may not pass is rejected; a draw that
//! writes stencil in a tile leaves the tile's bits exact for its values then (the depth block
//! caches whole 8x8 tiles, so it has them all when it writes the tile back).
//! Through Vulkan none of this happens: AMD's Vulkan driver (xgl) never calls
//! `CmdUpdateHiSPretests`, and RADV leaves `DB_SRESULTS_COMPARE_STATE0/1` disabled
//! (`ac_cmdbuf.c`), so RADV and AMDVLK on GFX9-11 are the `native` platform.
//!
//! **amd-andor (GFX12: RDNA 4).** `gfx12Metadata.cpp` lines 127-136: per 8x8 tile the AND and
//! the OR of its stencil values ("the red channel ... represents the AND reduction of all
//! stencil values across the s-tile, and the green channel ... the OR reduction"); initial value
//! AND 0, OR 0xFF, the full range (`GetHiSInitialValue`, lines 336-345). Bits set in the AND are
//! known ones, bits clear in the OR known zeros, so a tile can reject a masked test with any read
//! mask whose reference contradicts a known bit. It is valid in the depth-target, copy-source and
//! shader-read layouts and reset to the full range on return from any other
//! (`gfx12Image.cpp` lines 461-484, `gfx12Barrier.cpp` `ExpandHiSZWithFullRange`): histencil's
//! frame never leaves those layouts, so it is never reset mid-frame here. PAL disables it on
//! Navi48 A1 for a hardware bug (`gfx12SettingsLoader.cpp` lines 140-143). Assumed, as the
//! "reduction of all stencil values across the s-tile" reads: a draw that writes stencil in a
//! tile leaves its AND and OR exact for the tile's values then.

use crate::backend::{Native, PlatformBackend, PlatformCaps};
use crate::layout::StencilLayout;
use crate::plan::Pass;
use crate::state::{CompareOp, FaceStencil, StencilOp};
use crate::tiles::TileSurface;

/// GFX9-11 (Vega, RDNA 1-3) with pretests bound, as PAL allows and no Vulkan driver does: plans
/// as [`Native`] (its hierarchy needs no plan step); simulate with [`PretestTiles`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AmdPretest;

impl PlatformBackend for AmdPretest {
    fn name(&self) -> &'static str {
        "amd-pretest"
    }

    fn caps(&self) -> PlatformCaps {
        Native.caps()
    }
}

/// GFX12 (RDNA 4): plans as [`Native`]; simulate with [`AndOrTiles`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AmdAndOr;

impl PlatformBackend for AmdAndOr {
    fn name(&self) -> &'static str {
        "amd-andor"
    }

    fn caps(&self) -> PlatformCaps {
        Native.caps()
    }
}

/// The per-tile state of a GPU's own hierarchical stencil, which watches stencil writes and may
/// reject the tiles of a stencil-testing draw. Every implementation is conservative: a tile it
/// rejects holds no pixel that passes (the simulator's tests hold it to that).
pub trait TileHierarchy {
    /// The platform's name in reports.
    fn name(&self) -> &'static str;
    /// Sizes the state for `tiles` tiles, every one unknown.
    fn reset_all(&mut self, tiles: usize);
    /// Whether some pixel of `tile` may pass `face`'s stencil test.
    fn may_pass(&self, tile: usize, face: &FaceStencil) -> bool;
    /// A draw wrote stencil in `tile`, whose pixels now hold `values`.
    fn written(&mut self, tile: usize, values: &[u8]);
}

/// The stencil test a GPU's own hierarchy applies to the tiles of `pass`, or `None` where it
/// does not test the pass: it tests a pass whose stencil test (of the faces it rasterises) can
/// fail and whose failing fragments keep their value, since a rejected tile runs no stencil op
/// at all. A volume drawing both face sets has no one test and is not tested. The one decision
/// the simulator and the GPU path (`histencil_vk`'s `GpuHierarchy::test_for`) both ask.
pub fn hierarchy_test(pass: &Pass) -> Option<FaceStencil> {
    let face = pass.state.stencil_for(pass.front_facing()?)?;
    (face.compare != CompareOp::Always && face.fail == StencilOp::Keep).then_some(face)
}

/// Builds `hierarchy`'s state from the stencil the G-buffer pass left (as the hardware built it
/// while that pass wrote), over `tiles`' partition of a `width`-wide target.
pub fn begin(hierarchy: &mut dyn TileHierarchy, stencil: &[u8], width: u32, tiles: &TileSurface) {
    hierarchy.reset_all(tiles.tile_count());
    let height = stencil.len() as u32 / width;
    for tile in 0..tiles.tile_count() {
        hierarchy.written(tile, &tile_values(stencil, width, height, tiles, tile));
    }
}

/// The stencil values of `tile`'s pixels.
pub fn tile_values(
    stencil: &[u8],
    width: u32,
    height: u32,
    tiles: &TileSurface,
    tile: usize,
) -> Vec<u8> {
    let (x0, y0, x1, y1) = tiles.tile_pixels(tile, width, height);
    (y0..y1)
        .flat_map(|y| (x0..x1).map(move |x| stencil[(y * width + x) as usize]))
        .collect()
}

/// The two pretest slots of GFX9-11.
pub const PRETEST_SLOTS: usize = 2;

/// One HiS pretest: `(value & mask) OP (stencil & mask)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pretest {
    /// How the pretest's value compares with the masked stencil.
    pub compare: CompareOp,
    /// The bits compared.
    pub mask: u8,
    /// The value the masked stencil is compared with.
    pub value: u8,
}

impl Pretest {
    /// Whether one pixel's stencil passes the pretest, as the hardware would evaluate it.
    pub fn passes(&self, stencil: u8) -> bool {
        self.compare
            .test(self.value & self.mask, stencil & self.mask)
    }

    /// Whether every stencil value passing `face` passes this pretest, so that a tile where this
    /// pretest may not pass holds no pixel passing `face`.
    pub fn implied_by(&self, face: &FaceStencil) -> bool {
        self.compare == CompareOp::Equal
            && face.compare == CompareOp::Equal
            && self.mask & !face.compare_mask == 0
            && face.reference & self.mask == self.value & self.mask
    }
}

/// GFX9-11's pretests and their per-tile may-pass / may-fail bits.
#[derive(Clone, Debug)]
pub struct PretestTiles {
    /// The frame's pretests (at most two); `None` for an unused slot.
    pub pretests: [Option<Pretest>; PRETEST_SLOTS],
    may_pass: Vec<[bool; PRETEST_SLOTS]>,
    may_fail: Vec<[bool; PRETEST_SLOTS]>,
}

impl PretestTiles {
    /// A hierarchy with these pretests and no tiles evaluated yet.
    pub fn new(pretests: [Option<Pretest>; PRETEST_SLOTS]) -> Self {
        Self {
            pretests,
            may_pass: Vec::new(),
            may_fail: Vec::new(),
        }
    }
}

impl TileHierarchy for PretestTiles {
    fn name(&self) -> &'static str {
        "amd-pretest"
    }

    /// "Unknown stencil test result" (both bits set), as PAL initialises HTile.
    fn reset_all(&mut self, tiles: usize) {
        self.may_pass = vec![[true; PRETEST_SLOTS]; tiles];
        self.may_fail = vec![[true; PRETEST_SLOTS]; tiles];
    }

    fn may_pass(&self, tile: usize, face: &FaceStencil) -> bool {
        !self
            .pretests
            .iter()
            .enumerate()
            .any(|(slot, p)| p.is_some_and(|p| p.implied_by(face)) && !self.may_pass[tile][slot])
    }

    fn written(&mut self, tile: usize, values: &[u8]) {
        for (slot, p) in self.pretests.iter().enumerate() {
            if let Some(p) = p {
                self.may_pass[tile][slot] = values.iter().any(|v| p.passes(*v));
                self.may_fail[tile][slot] = values.iter().any(|v| !p.passes(*v));
            }
        }
    }
}

/// The pretests a frame binds before its G-buffer pass (binding them later needs the reset and
/// full rewrite): `Equal` on the BRDF field for the two BRDF slots present in the fewest tiles,
/// whose shade passes (which test the BRDF field, and the culling bit clear) they then reject in
/// every tile without that BRDF. `slot_tiles[k]` is how many tiles hold a pixel of slot `k` (from
/// the frame's own G-buffer; an engine would use the previous frame's). With one BRDF there is no
/// BRDF field, and a slot left over takes the culling bit clear, which rejects tiles a light
/// marked wholly (surfaces behind its volume). So two BRDFs are culled hierarchically by their
/// id, the others per pixel only: the answer to "how many before pretests run out".
pub fn choose_pretests(
    layout: &StencilLayout,
    slot_tiles: &[usize],
) -> [Option<Pretest>; PRETEST_SLOTS] {
    let mut slots: Vec<usize> = if layout.brdf_mask() == 0 {
        Vec::new()
    } else {
        (0..slot_tiles.len()).collect()
    };
    // Fewest tiles first: those tiles' absence is what a pretest culls. Ties by slot.
    slots.sort_by_key(|&k| (slot_tiles[k], k));
    let by_id = slots.into_iter().map(|k| Pretest {
        compare: CompareOp::Equal,
        mask: layout.brdf_mask(),
        value: layout.brdf_reference(k as u32),
    });
    let unmarked = Pretest {
        compare: CompareOp::Equal,
        mask: layout.culling_mask(),
        value: 0,
    };
    let mut out = [None; PRETEST_SLOTS];
    for (o, p) in out.iter_mut().zip(by_id.chain(std::iter::repeat(unmarked))) {
        *o = Some(p);
    }
    out
}

/// How many tiles of `tiles` hold a pixel of each BRDF slot of `layout`, from `stencil`.
pub fn slot_tile_counts(
    layout: &StencilLayout,
    stencil: &[u8],
    width: u32,
    tiles: &TileSurface,
) -> Vec<usize> {
    let slots = layout.brdfs_in_use() as usize;
    let mut seen = vec![vec![false; tiles.tile_count()]; slots];
    for (i, &s) in stencil.iter().enumerate() {
        let slot = layout.brdf_slot(s) as usize;
        if slot < slots {
            seen[slot][tiles.tile_of(i as u32 % width, i as u32 / width)] = true;
        }
    }
    seen.iter()
        .map(|t| t.iter().filter(|&&b| b).count())
        .collect()
}

/// GFX12's per-tile AND and OR of the stencil values.
#[derive(Clone, Debug, Default)]
pub struct AndOrTiles {
    and: Vec<u8>,
    or: Vec<u8>,
    /// The rule broken on purpose (a known-wrong case): a test's read mask ignored, every
    /// bit compared, as the 360's hi-stencil did.
    unmasked: bool,
}

impl AndOrTiles {
    /// AND/OR tiles that honour each test's read mask, as GFX12 does.
    pub fn new() -> Self {
        Self::default()
    }

    /// AND/OR tiles that compare all 8 bits whatever a test's read mask: with engine bits in
    /// the preserved stencil bits, tiles are rejected that hold passing pixels (lights lost), the
    /// 360's failure on today's hierarchy. A known-wrong case, not a GPU.
    pub fn unmasked() -> Self {
        Self {
            unmasked: true,
            ..Self::default()
        }
    }

    /// Back to the full range (AND 0, OR 0xFF), as on return from a layout that does not keep
    /// the surface: nothing is known, nothing is rejected.
    pub fn reset(&mut self) {
        self.and.fill(0);
        self.or.fill(0xFF);
    }
}

impl TileHierarchy for AndOrTiles {
    fn name(&self) -> &'static str {
        "amd-andor"
    }

    fn reset_all(&mut self, tiles: usize) {
        self.and = vec![0; tiles];
        self.or = vec![0xFF; tiles];
    }

    fn may_pass(&self, tile: usize, face: &FaceStencil) -> bool {
        let m = if self.unmasked {
            0xFF
        } else {
            face.compare_mask
        };
        let (known_one, known_zero) = (self.and[tile] & m, !self.or[tile] & m);
        let reference = face.reference & m;
        match face.compare {
            // Equal needs every masked bit as the reference has it.
            CompareOp::Equal => reference & known_zero == 0 && !reference & m & known_one == 0,
            // NotEqual fails only where every masked bit is known and equals the reference.
            CompareOp::NotEqual => known_one | known_zero != m || known_one != reference,
            // The ordered compares: the masked value lies between the known ones (all unknown
            // bits zero) and the complement of the known zeros (all unknown bits one).
            op => {
                let (lo, hi) = (known_one, m & !known_zero);
                (lo..=hi).any(|v| op.test(reference, v))
            }
        }
    }

    fn written(&mut self, tile: usize, values: &[u8]) {
        self.and[tile] = values.iter().fold(0xFF, |a, v| a & v);
        self.or[tile] = values.iter().fold(0, |a, v| a | v);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::{Geometry, PassKind};
    use crate::state::{CullMode, DepthState, PassState};

    /// One decision for the simulator and the GPU: the faces a pass rasterises decide which
    /// stencil test the hierarchy applies; a test that cannot fail, a failing fragment that
    /// writes, or a volume drawing both face sets is not tested (the simulator panicked on the
    /// last where the GPU path said "not tested").
    #[test]
    fn the_hierarchy_tests_the_rasterised_faces_test_when_it_can_fail_and_keeps() {
        let back_only = FaceStencil {
            compare: CompareOp::NotEqual,
            ..equal(0x0F, 2)
        };
        let pass = |geometry, cull, front: Option<FaceStencil>, back: Option<FaceStencil>| Pass {
            kind: PassKind::Setup,
            geometry,
            state: PassState {
                cull,
                depth: DepthState::OFF,
                front,
                back,
                color_write: false,
                hi_stencil: None,
                depth_bounds: false,
            },
        };
        let (f, b) = (Some(equal(0x0F, 1)), Some(back_only));
        assert_eq!(
            hierarchy_test(&pass(Geometry::Volume, CullMode::Back, f, b)),
            f
        );
        assert_eq!(
            hierarchy_test(&pass(Geometry::Volume, CullMode::Front, f, b)),
            b
        );
        assert_eq!(
            hierarchy_test(&pass(Geometry::FullScreen, CullMode::Front, f, b)),
            f
        );
        assert_eq!(
            hierarchy_test(&pass(Geometry::Volume, CullMode::None, f, b)),
            None
        );
        let always = FaceStencil {
            compare: CompareOp::Always,
            ..equal(0, 0)
        };
        let writes_on_fail = FaceStencil {
            fail: StencilOp::Zero,
            ..equal(0x0F, 1)
        };
        for face in [None, Some(always), Some(writes_on_fail)] {
            let p = pass(Geometry::FullScreen, CullMode::Back, face, None);
            assert_eq!(hierarchy_test(&p), None, "{face:?}");
        }
    }

    fn equal(mask: u8, reference: u8) -> FaceStencil {
        FaceStencil {
            compare: CompareOp::Equal,
            compare_mask: mask,
            reference,
            write_mask: 0,
            pass: StencilOp::Keep,
            fail: StencilOp::Keep,
            depth_fail: StencilOp::Keep,
        }
    }

    /// Every tile the models reject holds no value passing the test: checked exhaustively over
    /// tiles of two values (every pair of bytes for a few masks and references).
    #[test]
    fn neither_model_rejects_a_tile_holding_a_passing_value() {
        let tiles = TileSurface::new(2, 1, 2);
        let layout = StencilLayout::new(3, 0).unwrap();
        let pretests = choose_pretests(&layout, &[5, 1, 2]);
        let faces: Vec<FaceStencil> = [(0x07, 0x03), (0x06, 0x04), (0xFF, 0xA1), (0x01, 0x01)]
            .into_iter()
            .map(|(m, r)| equal(m, r))
            .chain(
                [
                    CompareOp::NotEqual,
                    CompareOp::Less,
                    CompareOp::GreaterOrEqual,
                ]
                .map(|c| FaceStencil {
                    compare: c,
                    ..equal(0x06, 0x02)
                }),
            )
            .collect();
        for a in 0..=255u8 {
            for b in (0..=255u8).step_by(3) {
                let mut andor = AndOrTiles::new();
                begin(&mut andor, &[a, b], 2, &tiles);
                let mut pre = PretestTiles::new(pretests);
                begin(&mut pre, &[a, b], 2, &tiles);
                for face in &faces {
                    let passes = face.test(a) || face.test(b);
                    if passes {
                        assert!(
                            andor.may_pass(0, face),
                            "and/or rejects {a:#x},{b:#x} {face:?}"
                        );
                        assert!(
                            pre.may_pass(0, face),
                            "pretest rejects {a:#x},{b:#x} {face:?}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn and_or_rejects_masked_tests_that_contradict_known_bits_whatever_the_engine_bits() {
        let tiles = TileSurface::new(2, 1, 2);
        let mut t = AndOrTiles::new();
        // Slot 1 (bits 1-2 = 01) in both pixels, engine bits differing: 0xA2 and 0x22.
        begin(&mut t, &[0xA2, 0x22], 2, &tiles);
        assert!(
            !t.may_pass(0, &equal(0x07, 0x03)),
            "slot 1 but the culling bit known zero"
        );
        assert!(
            !t.may_pass(0, &equal(0x06, 0x04)),
            "slot 2: bit 2 is known zero"
        );
        // A light marks one pixel: the culling bit is unknown, slot 1's shade pass may pass.
        t.written(0, &[0xA3, 0x22]);
        assert!(t.may_pass(0, &equal(0x07, 0x03)));
        assert!(!t.may_pass(0, &equal(0x07, 0x05)), "slot 2 still rejected");
        // Cleanup clears it: known zero again.
        t.written(0, &[0xA2, 0x22]);
        assert!(!t.may_pass(0, &equal(0x01, 0x01)));
        t.reset();
        assert!(
            t.may_pass(0, &equal(0x06, 0x04)),
            "the full range rejects nothing"
        );
    }

    #[test]
    fn pretests_cull_only_the_tests_they_are_implied_by() {
        let layout = StencilLayout::new(3, 0).unwrap();
        // Slot 0 is in 5 tiles, slot 1 in 1, slot 2 in 2: slots 1 and 2 get the pretests.
        let pretests = choose_pretests(&layout, &[5, 1, 2]);
        let values: Vec<u8> = pretests.iter().map(|p| p.unwrap().value).collect();
        assert_eq!(
            values,
            vec![layout.brdf_reference(1), layout.brdf_reference(2)]
        );
        let tiles = TileSurface::new(1, 1, 1);
        let mut t = PretestTiles::new(pretests);
        // A shade pass: the BRDF field, and the culling bit clear.
        let shade = |slot| {
            let mask = layout.brdf_mask() | layout.culling_mask();
            equal(mask, layout.brdf_reference(slot))
        };
        begin(&mut t, &[layout.brdf_reference(0)], 1, &tiles);
        assert!(t.may_pass(0, &shade(0)), "slot 0 has no pretest");
        assert!(!t.may_pass(0, &shade(1)));
        assert!(!t.may_pass(0, &shade(2)));
        // Slot 2 written into the tile: may pass for slot 2's pretest.
        t.written(0, &[layout.brdf_reference(2)]);
        assert!(t.may_pass(0, &shade(2)));
        assert!(!t.may_pass(0, &shade(1)));
        // One BRDF: no BRDF field, so both slots take the culling bit clear.
        let one = StencilLayout::new(1, 0).unwrap();
        let p = choose_pretests(&one, &[4]);
        assert_eq!(p[0], p[1]);
        assert_eq!(
            (p[0].unwrap().mask, p[0].unwrap().value),
            (one.culling_mask(), 0)
        );
    }
}
