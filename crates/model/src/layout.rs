/// Where the culling bit, the BRDF id and the engine's preserved bits sit in the 8-bit stencil.
///
/// Invariant: the three masks are disjoint and their union is `0xFF`; the culling bit is bit 0
/// and the BRDF id starts at [`StencilLayout::BRDF_SHIFT`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StencilLayout {
    brdfs_in_use: u32,
    brdf_bits: u32,
}

/// A layout that cannot be built.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum LayoutError {
    #[error("a scene must use at least one BRDF")]
    NoBrdfs,
    #[error(
        "stencil layout needs {requested_bits} bits (1 culling + {brdf_bits} BRDF for {brdfs} BRDFs \
         + {reserved} reserved preserved), but stencil has 8"
    )]
    TooManyBits {
        requested_bits: u32,
        brdf_bits: u32,
        brdfs: u32,
        reserved: u32,
    },
}

impl StencilLayout {
    /// The culling bit is bit 0.
    pub const CULLING_MASK: u8 = 0x01;
    /// The BRDF id starts right above the culling bit.
    pub const BRDF_SHIFT: u32 = 1;

    /// Derives the layout for `brdfs_in_use` BRDFs: `ceil(log2(n))` BRDF bits. The engine asks that
    /// at least `reserved_preserved_bits` bits stay its own; not fitting is an error.
    pub fn new(brdfs_in_use: u32, reserved_preserved_bits: u32) -> Result<Self, LayoutError> {
        if brdfs_in_use == 0 {
            return Err(LayoutError::NoBrdfs);
        }
        let brdf_bits = u32::BITS - (brdfs_in_use - 1).leading_zeros();
        let requested_bits = 1 + brdf_bits + reserved_preserved_bits;
        if requested_bits > 8 {
            return Err(LayoutError::TooManyBits {
                requested_bits,
                brdf_bits,
                brdfs: brdfs_in_use,
                reserved: reserved_preserved_bits,
            });
        }
        Ok(Self {
            brdfs_in_use,
            brdf_bits,
        })
    }

    pub fn brdfs_in_use(&self) -> u32 {
        self.brdfs_in_use
    }

    pub fn brdf_bits(&self) -> u32 {
        self.brdf_bits
    }

    /// True when more than one BRDF is in use, so BRDF bits and per-BRDF passes exist.
    pub fn has_brdf_bits(&self) -> bool {
        self.brdf_bits > 0
    }

    pub fn culling_mask(&self) -> u8 {
        Self::CULLING_MASK
    }

    pub fn brdf_mask(&self) -> u8 {
        (((1u32 << self.brdf_bits) - 1) << Self::BRDF_SHIFT) as u8
    }

    /// Bits the engine owns (the talk's "garbage"): everything not culling or BRDF.
    pub fn preserved_mask(&self) -> u8 {
        !(self.culling_mask() | self.brdf_mask())
    }

    /// The stencil value of BRDF slot `slot` (its index among the BRDFs in use).
    ///
    /// # Panics
    /// If `slot` is not below [`StencilLayout::brdfs_in_use`]: that is a caller bug.
    pub fn brdf_reference(&self, slot: u32) -> u8 {
        assert!(slot < self.brdfs_in_use, "BRDF slot {slot} out of range");
        (slot << Self::BRDF_SHIFT) as u8
    }

    /// The BRDF slot stored in a stencil value.
    pub fn brdf_slot(&self, stencil: u8) -> u32 {
        u32::from(stencil & self.brdf_mask()) >> Self::BRDF_SHIFT
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn talks_case_eight_brdfs() {
        let l = StencilLayout::new(8, 0).unwrap();
        assert_eq!(l.culling_mask(), 0x01);
        assert_eq!(l.brdf_mask(), 0x0E);
        assert_eq!(l.preserved_mask(), 0xF0);
        assert_eq!(l.brdf_reference(5), 0x0A);
        assert_eq!(l.brdf_slot(0xFB), 5);
    }

    #[test]
    fn one_brdf_has_no_brdf_bits() {
        let l = StencilLayout::new(1, 0).unwrap();
        assert!(!l.has_brdf_bits());
        assert_eq!(l.brdf_mask(), 0);
        assert_eq!(l.preserved_mask(), 0xFE);
    }

    #[test]
    fn bit_counts_follow_ceil_log2() {
        for (n, bits) in [
            (1, 0),
            (2, 1),
            (3, 2),
            (4, 2),
            (5, 3),
            (8, 3),
            (9, 4),
            (128, 7),
        ] {
            assert_eq!(
                StencilLayout::new(n, 0).unwrap().brdf_bits(),
                bits,
                "{n} BRDFs"
            );
        }
    }

    #[test]
    fn masks_partition_the_byte() {
        for n in 1..=128 {
            let l = StencilLayout::new(n, 0).unwrap();
            assert_eq!(l.culling_mask() & l.brdf_mask(), 0);
            assert_eq!(l.culling_mask() | l.brdf_mask() | l.preserved_mask(), 0xFF);
        }
    }

    #[test]
    fn overflow_is_a_typed_error_naming_the_bits() {
        let err = StencilLayout::new(129, 0).unwrap_err();
        assert!(matches!(
            err,
            LayoutError::TooManyBits {
                requested_bits: 9,
                ..
            }
        ));
        assert!(err.to_string().contains("needs 9 bits"));
        assert!(StencilLayout::new(8, 4).is_ok());
        assert!(StencilLayout::new(8, 5).is_err());
        assert_eq!(StencilLayout::new(0, 0), Err(LayoutError::NoBrdfs));
    }
}
