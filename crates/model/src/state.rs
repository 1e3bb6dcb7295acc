//! Depth, stencil, cull and hi-stencil state of one pass, as plain data with the exact semantics
//! of Vulkan's per-pixel stencil test. Conversion to Vulkan lives in `histencil-vk`; the CPU
//! simulator executes these same values, so the two cannot drift apart silently.

/// A compare function, with Vulkan's operand order: `reference OP (stencil & compare_mask)` for
/// stencil, `fragment_depth OP stored_depth` for depth.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CompareOp {
    /// Fails every fragment.
    Never,
    /// `a < b`.
    Less,
    /// `a == b`: the stencil technique's BRDF and culling tests.
    Equal,
    /// `a <= b`.
    LessOrEqual,
    /// `a > b`.
    Greater,
    /// `a != b`.
    NotEqual,
    /// `a >= b`.
    GreaterOrEqual,
    /// Passes every fragment.
    Always,
}

impl CompareOp {
    /// `a OP b`.
    pub fn test<T: PartialOrd>(self, a: T, b: T) -> bool {
        match self {
            Self::Never => false,
            Self::Less => a < b,
            Self::Equal => a == b,
            Self::LessOrEqual => a <= b,
            Self::Greater => a > b,
            Self::NotEqual => a != b,
            Self::GreaterOrEqual => a >= b,
            Self::Always => true,
        }
    }
}

/// What a stencil update writes (before the write mask is applied).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum StencilOp {
    /// Leaves the value.
    Keep,
    /// Writes 0: the cleanup clears the culling bit with it, 360-like plans the preserved bits.
    Zero,
    /// Writes the reference: how the setup sets the culling bit.
    Replace,
    /// Adds one, stopping at 255.
    IncrementAndClamp,
}

impl StencilOp {
    /// The new value of the whole byte, before masking.
    pub fn apply(self, stencil: u8, reference: u8) -> u8 {
        match self {
            Self::Keep => stencil,
            Self::Zero => 0,
            Self::Replace => reference,
            Self::IncrementAndClamp => stencil.saturating_add(1),
        }
    }
}

/// Per-pixel stencil state of one face.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct FaceStencil {
    /// How the reference compares with the masked stencil.
    pub compare: CompareOp,
    /// The bits of the stencil the test reads.
    pub compare_mask: u8,
    /// The bits a stencil op may change; the others keep their value whatever the op.
    pub write_mask: u8,
    /// The value compared with and written by [`StencilOp::Replace`].
    pub reference: u8,
    /// Stencil and depth tests pass.
    pub pass: StencilOp,
    /// Stencil test fails.
    pub fail: StencilOp,
    /// Stencil test passes, depth test fails.
    pub depth_fail: StencilOp,
}

impl FaceStencil {
    /// Passes everywhere and writes nothing.
    pub const DISABLED: Self = Self {
        compare: CompareOp::Always,
        compare_mask: 0,
        write_mask: 0,
        reference: 0,
        pass: StencilOp::Keep,
        fail: StencilOp::Keep,
        depth_fail: StencilOp::Keep,
    };

    /// Passes everywhere and writes `pass` where the depth test passes and `depth_fail` where it
    /// fails, into the bits of `write_mask` (`Replace` writes `reference`).
    pub const fn writing(
        write_mask: u8,
        reference: u8,
        pass: StencilOp,
        depth_fail: StencilOp,
    ) -> Self {
        Self {
            compare: CompareOp::Always,
            compare_mask: 0,
            write_mask,
            reference,
            pass,
            fail: StencilOp::Keep,
            depth_fail,
        }
    }

    /// Vulkan's stencil test: `(reference & mask) OP (stencil & mask)`.
    pub fn test(&self, stencil: u8) -> bool {
        self.compare.test(
            self.reference & self.compare_mask,
            stencil & self.compare_mask,
        )
    }

    /// The stencil after this face's update; only bits in `write_mask` change.
    pub fn update(&self, stencil: u8, stencil_passed: bool, depth_passed: bool) -> u8 {
        let op = match (stencil_passed, depth_passed) {
            (false, _) => self.fail,
            (true, false) => self.depth_fail,
            (true, true) => self.pass,
        };
        let written = op.apply(stencil, self.reference);
        (stencil & !self.write_mask) | (written & self.write_mask)
    }

    /// True when some outcome of the test can change a bit.
    pub fn writes(&self) -> bool {
        self.write_mask != 0
            && [self.pass, self.fail, self.depth_fail]
                .iter()
                .any(|op| *op != StencilOp::Keep)
    }
}

/// Which rasterised faces are discarded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CullMode {
    /// Keeps both faces.
    None,
    /// Discards front faces, for passes that draw a volume's back faces.
    Front,
    /// Discards back faces.
    Back,
}

/// Depth test and write.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct DepthState {
    /// `None`: no depth test (every fragment passes).
    pub compare: Option<CompareOp>,
    /// Whether a fragment that passes writes its depth; light passes never do.
    pub write: bool,
}

impl DepthState {
    /// No depth test and no depth write.
    pub const OFF: Self = Self {
        compare: None,
        write: false,
    };

    /// Tests without writing: light passes never write depth.
    pub const fn test(compare: CompareOp) -> Self {
        Self {
            compare: Some(compare),
            write: false,
        }
    }

    /// `fragment OP stored`.
    pub fn passes(&self, fragment: f32, stored: f32) -> bool {
        self.compare.is_none_or(|op| op.test(fragment, stored))
    }
}

/// The coarse (per-tile) stencil test of consoles: a compare of the pixel's stencil against a
/// reference, evaluated per tile when written and used to reject whole tiles when tested.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct HiStencilState {
    /// How the masked stencil compares with the reference.
    pub compare: CompareOp,
    /// The value compared with.
    pub reference: u8,
    /// `None` on hardware without a hi-stencil read mask (360-like): all 8 bits are compared.
    pub read_mask: Option<u8>,
    /// The draw re-evaluates the tiles it covers into the pending surface.
    pub write: bool,
    /// The draw rejects fragments in tiles the active surface marks as failing.
    pub test: bool,
}

impl HiStencilState {
    /// The hi-stencil compare of one pixel: `(stencil & read_mask) OP reference`.
    pub fn compare_passes(&self, stencil: u8) -> bool {
        let mask = self.read_mask.unwrap_or(0xFF);
        self.compare.test(stencil & mask, self.reference)
    }
}

/// Everything a pass sets besides its shader and geometry.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PassState {
    /// Which faces are discarded; the others run with their face's stencil state
    /// ([`PassState::stencil_for`]).
    pub cull: CullMode,
    /// Depth test and write.
    pub depth: DepthState,
    /// `None` disables the stencil test and writes.
    pub front: Option<FaceStencil>,
    /// Stencil state of back faces; `None` disables the stencil test and writes.
    pub back: Option<FaceStencil>,
    /// Colour writes: only light-shading passes have them.
    pub color_write: bool,
    /// `None` on platforms without hi-stencil, or when the pass neither tests nor writes it.
    pub hi_stencil: Option<HiStencilState>,
    /// The device's depth bounds test confines the pass to its light's depth range
    /// ([`crate::PlannedLight::depth_range`]; [`crate::FramePlan::with_depth_bounds`]).
    pub depth_bounds: bool,
}

impl PassState {
    /// The stencil state of the faces this pass rasterises (the other face set is culled).
    pub fn stencil_for(&self, front_facing: bool) -> Option<FaceStencil> {
        if front_facing {
            self.front
        } else {
            self.back
        }
    }

    /// True when the pass can change per-pixel stencil.
    pub fn writes_stencil(&self) -> bool {
        [self.front, self.back]
            .iter()
            .flatten()
            .any(FaceStencil::writes)
    }

    /// True when the pass re-evaluates hi-stencil tiles into the pending surface.
    pub fn writes_hi_stencil(&self) -> bool {
        self.hi_stencil.is_some_and(|h| h.write)
    }

    /// True when the pass rejects fragments in tiles the active surface marks as failing.
    pub fn tests_hi_stencil(&self) -> bool {
        self.hi_stencil.is_some_and(|h| h.test)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn write_mask_limits_the_update() {
        let zero_all_but_brdf = FaceStencil {
            compare: CompareOp::Always,
            compare_mask: 0,
            write_mask: !0x0E,
            reference: 0,
            pass: StencilOp::Zero,
            fail: StencilOp::Keep,
            depth_fail: StencilOp::Keep,
        };
        assert_eq!(zero_all_but_brdf.update(0xFB, true, true), 0x0A);
        assert_eq!(zero_all_but_brdf.update(0xFB, true, false), 0xFB);
    }

    #[test]
    fn stencil_test_masks_both_sides() {
        let shade = FaceStencil {
            compare: CompareOp::Equal,
            compare_mask: 0x0F,
            reference: 0x0A,
            ..FaceStencil::DISABLED
        };
        assert!(shade.test(0xFA));
        assert!(!shade.test(0xFB));
        assert!(!shade.test(0x0C));
    }

    #[test]
    fn hi_stencil_without_read_mask_sees_preserved_bits() {
        let hi = HiStencilState {
            compare: CompareOp::Equal,
            reference: 0x0A,
            read_mask: None,
            write: true,
            test: false,
        };
        assert!(hi.compare_passes(0x0A));
        assert!(!hi.compare_passes(0xFA));
        let with_mask = HiStencilState {
            read_mask: Some(0x0F),
            ..hi
        };
        assert!(with_mask.compare_passes(0xFA));
    }

    #[test]
    fn depth_off_always_passes() {
        assert!(DepthState::OFF.passes(1.0, 0.0));
        assert!(!DepthState::test(CompareOp::Less).passes(0.5, 0.5));
    }
}
