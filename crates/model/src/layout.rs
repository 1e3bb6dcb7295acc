//! Where the culling bit, the BRDF id and the engine's own bits sit in the 8-bit stencil.
//!
//! histencil's own renderer puts the culling bit at bit 0 and the BRDF field right above it
//! ([`StencilLayout::new`]); an engine that already uses some stencil bits places both where its
//! bits are not ([`StencilLayout::with_positions`]) and declares its own bits, which the plans
//! keep (PS3-like, native), or zero and restore (360-like with save and restore).

/// A stencil byte split into histencil's bits and the engine's.
///
/// Invariants: the culling bit, the BRDF field and the engine's bits are disjoint; the BRDF
/// field is `brdf_bits` contiguous bits from `brdf_shift`, wide enough for `brdfs_in_use`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StencilLayout {
    brdfs_in_use: u32,
    brdf_bits: u32,
    brdf_shift: u32,
    culling_mask: u8,
    engine_mask: u8,
}

/// Where an engine wants histencil's bits, and which bits are its own.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct StencilBits {
    /// The culling bit's index, 0..=7.
    pub culling_bit: u32,
    /// The lowest bit of the BRDF field; the field is `ceil(log2(brdfs))` bits wide.
    pub brdf_shift: u32,
    /// The bits the engine keeps its own data in. They must not overlap histencil's bits; the
    /// bits that are in neither are free, and histencil may leave them zeroed.
    pub engine_mask: u8,
}

/// A layout that cannot be built.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum LayoutError {
    /// No BRDF in use: there would be nothing to light.
    #[error("a scene must use at least one BRDF")]
    NoBrdfs,
    /// The culling bit, the BRDF field and the bits the engine reserved need more than 8 bits.
    #[error(
        "stencil layout needs {requested_bits} bits (1 culling + {brdf_bits} BRDF for {brdfs} BRDFs \
         + {reserved} reserved preserved), but stencil has 8"
    )]
    TooManyBits {
        /// Bits asked for in all.
        requested_bits: u32,
        /// Bits the BRDF field needs.
        brdf_bits: u32,
        /// BRDFs in use.
        brdfs: u32,
        /// Bits the engine asked to keep.
        reserved: u32,
    },
    /// The engine placed the culling bit outside the byte.
    #[error("the culling bit must be one of bits 0 to 7, got bit {0}")]
    CullingBitOutsideByte(u32),
    /// The BRDF field, placed from the engine's shift, does not fit in the byte.
    #[error(
        "{brdfs} BRDFs need {brdf_bits} BRDF bits, which from bit {shift} run past bit 7 of the \
         stencil byte"
    )]
    BrdfFieldOutsideByte {
        /// BRDFs in use.
        brdfs: u32,
        /// Bits the BRDF field needs.
        brdf_bits: u32,
        /// The field's lowest bit, as the engine placed it.
        shift: u32,
    },
    /// The engine placed the culling bit inside the BRDF field.
    #[error("the culling bit {culling_bit} lies inside the BRDF field {brdf_mask:#04x}")]
    CullingInBrdfField {
        /// The culling bit's index.
        culling_bit: u32,
        /// The BRDF field, as a mask.
        brdf_mask: u8,
    },
    /// The engine declared bits of its own that histencil's bits use.
    #[error(
        "the engine's bits {engine_mask:#04x} overlap histencil's: culling {culling_mask:#04x}, \
         BRDF {brdf_mask:#04x}"
    )]
    EngineBitsOverlap {
        /// The bits the engine declared its own.
        engine_mask: u8,
        /// Where the culling bit sits.
        culling_mask: u8,
        /// Where the BRDF field sits.
        brdf_mask: u8,
    },
}

/// `ceil(log2(n))` for `n >= 1`: the bits that tell `n` values apart.
fn bits_for(brdfs: u32) -> u32 {
    u32::BITS - (brdfs - 1).leading_zeros()
}

impl StencilLayout {
    /// histencil's default culling bit: bit 0.
    pub const CULLING_MASK: u8 = 0x01;
    /// histencil's default BRDF field starts right above the culling bit.
    pub const BRDF_SHIFT: u32 = 1;

    /// The talk's layout for `brdfs_in_use` BRDFs: culling bit 0, `ceil(log2(n))` BRDF bits from
    /// bit 1, and every bit above them the engine's. The engine asks that at least
    /// `reserved_preserved_bits` bits stay its own; not fitting is an error.
    ///
    /// ```
    /// use histencil_model::StencilLayout;
    ///
    /// // Five BRDFs need three bits: culling at bit 0, the BRDF field at bits 1 to 3, and the
    /// // engine keeps bits 4 to 7 (it asked for at least two).
    /// let layout = StencilLayout::new(5, 2)?;
    /// assert_eq!(layout.culling_mask(), 0x01);
    /// assert_eq!(layout.brdf_mask(), 0x0e);
    /// assert_eq!(layout.engine_mask(), 0xf0);
    /// // The G-buffer pass writes BRDF slot 3 as stencil 0x06; the lighting reads it back.
    /// assert_eq!(layout.brdf_reference(3), 0x06);
    /// assert_eq!(layout.brdf_slot(0xf6), 3);
    /// // Nine BRDFs need four bits: with five of the engine's, the byte overflows.
    /// assert!(StencilLayout::new(9, 5).is_err());
    /// # Ok::<(), histencil_model::LayoutError>(())
    /// ```
    pub fn new(brdfs_in_use: u32, reserved_preserved_bits: u32) -> Result<Self, LayoutError> {
        if brdfs_in_use == 0 {
            return Err(LayoutError::NoBrdfs);
        }
        let brdf_bits = bits_for(brdfs_in_use);
        let requested_bits = 1 + brdf_bits + reserved_preserved_bits;
        if requested_bits > 8 {
            return Err(LayoutError::TooManyBits {
                requested_bits,
                brdf_bits,
                brdfs: brdfs_in_use,
                reserved: reserved_preserved_bits,
            });
        }
        let brdf_mask = Self::field(brdf_bits, Self::BRDF_SHIFT);
        Ok(Self {
            brdfs_in_use,
            brdf_bits,
            brdf_shift: Self::BRDF_SHIFT,
            culling_mask: Self::CULLING_MASK,
            engine_mask: !(Self::CULLING_MASK | brdf_mask),
        })
    }

    /// A layout at the engine's bit positions: the culling bit and the BRDF field anywhere in
    /// the byte, the engine's own bits declared.
    pub fn with_positions(brdfs_in_use: u32, bits: StencilBits) -> Result<Self, LayoutError> {
        if brdfs_in_use == 0 {
            return Err(LayoutError::NoBrdfs);
        }
        if bits.culling_bit >= 8 {
            return Err(LayoutError::CullingBitOutsideByte(bits.culling_bit));
        }
        let brdf_bits = bits_for(brdfs_in_use);
        if bits.brdf_shift.saturating_add(brdf_bits) > 8 {
            return Err(LayoutError::BrdfFieldOutsideByte {
                brdfs: brdfs_in_use,
                brdf_bits,
                shift: bits.brdf_shift,
            });
        }
        let culling_mask = 1u8 << bits.culling_bit;
        let brdf_mask = Self::field(brdf_bits, bits.brdf_shift);
        if culling_mask & brdf_mask != 0 {
            return Err(LayoutError::CullingInBrdfField {
                culling_bit: bits.culling_bit,
                brdf_mask,
            });
        }
        if bits.engine_mask & (culling_mask | brdf_mask) != 0 {
            return Err(LayoutError::EngineBitsOverlap {
                engine_mask: bits.engine_mask,
                culling_mask,
                brdf_mask,
            });
        }
        Ok(Self {
            brdfs_in_use,
            brdf_bits,
            brdf_shift: bits.brdf_shift,
            culling_mask,
            engine_mask: bits.engine_mask,
        })
    }

    fn field(bits: u32, shift: u32) -> u8 {
        (((1u32 << bits) - 1) << shift) as u8
    }

    /// How many BRDFs the field tells apart.
    pub fn brdfs_in_use(&self) -> u32 {
        self.brdfs_in_use
    }

    /// Width of the BRDF field: `ceil(log2(brdfs_in_use))`, 0 for one BRDF.
    pub fn brdf_bits(&self) -> u32 {
        self.brdf_bits
    }

    /// The lowest bit of the BRDF field.
    pub fn brdf_shift(&self) -> u32 {
        self.brdf_shift
    }

    /// True when more than one BRDF is in use, so BRDF bits and per-BRDF passes exist.
    pub fn has_brdf_bits(&self) -> bool {
        self.brdf_bits > 0
    }

    /// The culling bit, as a mask.
    pub fn culling_mask(&self) -> u8 {
        self.culling_mask
    }

    /// The BRDF field, as a mask.
    pub fn brdf_mask(&self) -> u8 {
        Self::field(self.brdf_bits, self.brdf_shift)
    }

    /// Bits histencil does not own (the talk's "garbage"): the engine's bits and the free ones.
    /// Lighting never changes them on PS3-like and native backends.
    pub fn preserved_mask(&self) -> u8 {
        !(self.culling_mask | self.brdf_mask())
    }

    /// The bits the engine declared its own: the ones a 360-like save and restore brings back
    /// (one full-screen pass per bit, so undeclared free bits cost nothing).
    pub fn engine_mask(&self) -> u8 {
        self.engine_mask
    }

    /// The stencil value of BRDF slot `slot` (its index among the BRDFs in use).
    ///
    /// # Panics
    /// If `slot` is not below [`StencilLayout::brdfs_in_use`]: that is a caller bug.
    pub fn brdf_reference(&self, slot: u32) -> u8 {
        assert!(slot < self.brdfs_in_use, "BRDF slot {slot} out of range");
        (slot << self.brdf_shift) as u8
    }

    /// The BRDF slot stored in a stencil value.
    pub fn brdf_slot(&self, stencil: u8) -> u32 {
        u32::from(stencil & self.brdf_mask()) >> self.brdf_shift
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
        assert_eq!(l.engine_mask(), 0xF0);
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

    /// An engine with its own data in bits 0 and 1 puts the BRDF field at bits 4-6 and the
    /// culling bit at 7; bits 2 and 3 stay free.
    #[test]
    fn engine_positions_move_every_mask() {
        let bits = StencilBits {
            culling_bit: 7,
            brdf_shift: 4,
            engine_mask: 0x03,
        };
        let l = StencilLayout::with_positions(6, bits).unwrap();
        assert_eq!(l.culling_mask(), 0x80);
        assert_eq!(l.brdf_mask(), 0x70);
        assert_eq!(l.engine_mask(), 0x03);
        assert_eq!(l.preserved_mask(), 0x0F);
        assert_eq!(l.brdf_reference(5), 0x50);
        assert_eq!(l.brdf_slot(0xD3), 5);
    }

    #[test]
    fn every_placement_partitions_the_byte_or_says_why_not() {
        for brdfs in 1..=128 {
            for culling_bit in 0..9 {
                for brdf_shift in 0..9 {
                    for engine_mask in [0u8, 0x01, 0x0C, 0x80, 0xF0] {
                        let bits = StencilBits {
                            culling_bit,
                            brdf_shift,
                            engine_mask,
                        };
                        let Ok(l) = StencilLayout::with_positions(brdfs, bits) else {
                            continue;
                        };
                        assert_eq!(l.culling_mask() & l.brdf_mask(), 0);
                        assert_eq!(l.engine_mask() & !l.preserved_mask(), 0);
                        for slot in 0..brdfs {
                            assert_eq!(l.brdf_slot(l.brdf_reference(slot)), slot);
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn bad_placements_are_errors() {
        let at = |culling_bit, brdf_shift, engine_mask| StencilBits {
            culling_bit,
            brdf_shift,
            engine_mask,
        };
        assert_eq!(
            StencilLayout::with_positions(2, at(8, 0, 0)),
            Err(LayoutError::CullingBitOutsideByte(8))
        );
        assert!(matches!(
            StencilLayout::with_positions(8, at(0, 6, 0)),
            Err(LayoutError::BrdfFieldOutsideByte { brdf_bits: 3, .. })
        ));
        assert!(matches!(
            StencilLayout::with_positions(4, at(2, 1, 0)),
            Err(LayoutError::CullingInBrdfField { .. })
        ));
        let err = StencilLayout::with_positions(4, at(0, 1, 0x04)).unwrap_err();
        assert!(err.to_string().contains("overlap"), "{err}");
        // Shifts past the byte do not overflow: the field is simply outside it.
        assert!(StencilLayout::with_positions(2, at(0, u32::MAX, 0)).is_err());
    }
}
