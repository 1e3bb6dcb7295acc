//! The shared atlas of lightmap regions. "For performance reasons we pack all position maps to a
//! single texture. Every entity that needs alpha lighting will allocate and use a region inside
//! the texture" (the talk). Entities come and go every frame (particle systems spawn and die),
//! so regions are freed and reused: etagere's shelf allocator does the packing.
//!
//! Each region is surrounded by a guard band of `padding` texels that no other region uses, so
//! bilinear sampling at a region's edge (and the conservative rasterisation of a UV-space bake)
//! never reads or writes a neighbour.
//!
//! # When the atlas is full
//! [`Atlas::allocate`] asks for exactly the given size. [`Atlas::allocate_downgrading`] halves
//! the side until the region fits or would fall below the minimum; the returned
//! [`Allocation::side`] says what was granted, so the caller knows its lighting is coarser this
//! frame. Only when even the minimum does not fit is it an error ([`AtlasError::Full`]); nothing
//! already allocated moves or changes.

use etagere::{size2, AllocId, AtlasAllocator};
use std::collections::HashMap;

/// A rectangle of the atlas, in texels: the entity's own texels, guard band excluded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Region {
    /// Left edge, in texels from the atlas's left.
    pub x: u32,
    /// Top edge, in texels from the atlas's first row.
    pub y: u32,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
}

impl Region {
    /// True when the two share a texel.
    pub fn overlaps(&self, other: &Region) -> bool {
        self.x < other.x + other.width
            && other.x < self.x + self.width
            && self.y < other.y + other.height
            && other.y < self.y + self.height
    }

    /// The region grown by `by` texels on every side (saturating at 0).
    pub fn expanded(&self, by: u32) -> Region {
        Region {
            x: self.x.saturating_sub(by),
            y: self.y.saturating_sub(by),
            width: self.width + 2 * by,
            height: self.height + 2 * by,
        }
    }

    /// How many texels the region holds: what lighting it costs.
    pub fn texels(&self) -> u64 {
        u64::from(self.width) * u64::from(self.height)
    }
}

/// A region's handle, never reused within an atlas: a stale handle cannot free a region
/// allocated later in the same place (etagere's own ids can repeat).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct RegionId(u64);

/// What an allocation granted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Allocation {
    /// The handle that frees it ([`Atlas::free`]).
    pub id: RegionId,
    /// Where it lies: the texels granted, perhaps fewer than asked for.
    pub region: Region,
    /// The size asked for; larger than `region`'s when the atlas was too full for it.
    pub requested: (u32, u32),
}

impl Allocation {
    /// Whether the atlas granted less than was asked for: the entity is lit coarser this frame.
    pub fn downgraded(&self) -> bool {
        (self.region.width, self.region.height) != self.requested
    }
}

/// Why an atlas could not be made, or a region allocated or freed.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum AtlasError {
    /// An atlas side is 0 or above [`Atlas::MAX_SIDE`].
    #[error("atlas size {width}x{height} is out of range (1..={max} per side)", max = Atlas::MAX_SIDE)]
    BadSize {
        /// The width asked for.
        width: u32,
        /// The height asked for.
        height: u32,
    },
    /// A region that no atlas of this size could hold: a side of 0, or larger than the atlas
    /// less its guard band. A caller bug, unlike [`AtlasError::Full`].
    #[error("a {width}x{height} region cannot be allocated: sides must be at least 1 and fit the {atlas_width}x{atlas_height} atlas with its padding")]
    BadRequest {
        /// The width asked for.
        width: u32,
        /// The height asked for.
        height: u32,
        /// The atlas's width.
        atlas_width: u32,
        /// The atlas's height.
        atlas_height: u32,
    },
    /// The live regions leave no room ([`Atlas::allocate_downgrading`]: not even at the minimum
    /// side).
    #[error("lightmap atlas full: no room for {width}x{height} texels (after downgrading to the minimum); {live} regions hold {used} of {total} texels")]
    Full {
        /// The width asked for.
        width: u32,
        /// The height asked for.
        height: u32,
        /// Regions allocated and not freed.
        live: usize,
        /// Texels those regions hold.
        used: u64,
        /// Texels in the atlas.
        total: u64,
    },
    /// The handle names no live region.
    #[error("region {0:?} is not allocated (freed twice, or from another atlas)")]
    UnknownRegion(RegionId),
}

/// The atlas: its size, guard band and live regions.
pub struct Atlas {
    allocator: AtlasAllocator,
    width: u32,
    height: u32,
    padding: u32,
    live: HashMap<RegionId, (AllocId, Region)>,
    next_id: u64,
}

impl Atlas {
    /// The largest atlas side: 16384 is the image size limit of most Vulkan devices.
    pub const MAX_SIDE: u32 = 16384;

    /// An empty `width` x `height` atlas whose regions keep `padding` texels of guard band.
    pub fn new(width: u32, height: u32, padding: u32) -> Result<Self, AtlasError> {
        let range = 1..=Self::MAX_SIDE;
        if !range.contains(&width) || !range.contains(&height) {
            return Err(AtlasError::BadSize { width, height });
        }
        Ok(Self {
            allocator: AtlasAllocator::new(size2(width as i32, height as i32)),
            width,
            height,
            padding,
            live: HashMap::new(),
            next_id: 0,
        })
    }

    /// `(width, height)` in texels.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The guard band, in texels, kept around every region.
    pub fn padding(&self) -> u32 {
        self.padding
    }

    /// A region of exactly `width` x `height` texels.
    pub fn allocate(&mut self, width: u32, height: u32) -> Result<Allocation, AtlasError> {
        self.check_request(width, height)?;
        self.try_allocate(width, height)
            .ok_or_else(|| self.full(width, height))
    }

    /// A region of `width` x `height` texels, or, when the atlas has no room, of half that
    /// (rounded up) and so on while the larger side stays at least `min_side`.
    pub fn allocate_downgrading(
        &mut self,
        width: u32,
        height: u32,
        min_side: u32,
    ) -> Result<Allocation, AtlasError> {
        self.check_request(width, height)?;
        let (mut w, mut h) = (width, height);
        loop {
            if let Some(a) = self.try_allocate(w, h) {
                return Ok(Allocation {
                    requested: (width, height),
                    ..a
                });
            }
            if w.max(h) / 2 < min_side.max(1) {
                return Err(self.full(w, h));
            }
            (w, h) = (w.div_ceil(2), h.div_ceil(2));
        }
    }

    /// Frees a region; its texels (and guard band) can be allocated again at once.
    pub fn free(&mut self, id: RegionId) -> Result<(), AtlasError> {
        let (alloc, _) = self.live.remove(&id).ok_or(AtlasError::UnknownRegion(id))?;
        self.allocator.deallocate(alloc);
        Ok(())
    }

    /// The live regions.
    pub fn regions(&self) -> impl Iterator<Item = (RegionId, Region)> + '_ {
        self.live.iter().map(|(id, (_, r))| (*id, *r))
    }

    /// Texels held by live regions, guard bands excluded.
    pub fn used_texels(&self) -> u64 {
        self.live.values().map(|(_, r)| r.texels()).sum()
    }

    fn check_request(&self, width: u32, height: u32) -> Result<(), AtlasError> {
        let fits = |side: u32, atlas: u32| {
            side >= 1
                && side
                    .checked_add(2 * self.padding)
                    .is_some_and(|s| s <= atlas)
        };
        if fits(width, self.width) && fits(height, self.height) {
            Ok(())
        } else {
            Err(AtlasError::BadRequest {
                width,
                height,
                atlas_width: self.width,
                atlas_height: self.height,
            })
        }
    }

    fn try_allocate(&mut self, width: u32, height: u32) -> Option<Allocation> {
        let (pw, ph) = (width + 2 * self.padding, height + 2 * self.padding);
        let a = self.allocator.allocate(size2(pw as i32, ph as i32))?;
        // The shelf may hand out a taller rectangle than asked; the region is the requested
        // size at its corner, inside the guard band, so it never reaches past what was granted.
        let region = Region {
            x: a.rectangle.min.x as u32 + self.padding,
            y: a.rectangle.min.y as u32 + self.padding,
            width,
            height,
        };
        let id = RegionId(self.next_id);
        self.next_id += 1;
        self.live.insert(id, (a.id, region));
        Some(Allocation {
            id,
            region,
            requested: (width, height),
        })
    }

    fn full(&self, width: u32, height: u32) -> AtlasError {
        AtlasError::Full {
            width,
            height,
            live: self.live.len(),
            used: self.used_texels(),
            total: u64::from(self.width) * u64::from(self.height),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Live regions are inside the atlas, and no region's guard band touches another region.
    fn assert_disjoint(atlas: &Atlas) {
        let regions: Vec<Region> = atlas.regions().map(|(_, r)| r).collect();
        let (w, h) = atlas.size();
        for (i, a) in regions.iter().enumerate() {
            assert!(a.x >= atlas.padding() && a.y >= atlas.padding(), "{a:?}");
            assert!(a.x + a.width + atlas.padding() <= w, "{a:?}");
            assert!(a.y + a.height + atlas.padding() <= h, "{a:?}");
            for b in &regions[i + 1..] {
                assert!(
                    !a.expanded(atlas.padding()).overlaps(b),
                    "{a:?} and {b:?} overlap (padding {})",
                    atlas.padding()
                );
            }
        }
    }

    #[derive(Clone, Debug)]
    enum Op {
        Allocate(u32, u32),
        Downgrading(u32, u32),
        Free(usize),
    }

    fn op() -> impl Strategy<Value = Op> {
        prop_oneof![
            (1u32..=96, 1u32..=96).prop_map(|(w, h)| Op::Allocate(w, h)),
            (1u32..=160, 1u32..=160).prop_map(|(w, h)| Op::Downgrading(w, h)),
            (0usize..64).prop_map(Op::Free),
        ]
    }

    proptest! {
        #[test]
        fn regions_never_overlap(ops in prop::collection::vec(op(), 1..200), padding in 0u32..3) {
            let mut atlas = Atlas::new(256, 256, padding).unwrap();
            let mut ids = Vec::new();
            for op in ops {
                match op {
                    Op::Allocate(w, h) => {
                        if let Ok(a) = atlas.allocate(w, h) {
                            prop_assert_eq!((a.region.width, a.region.height), (w, h));
                            ids.push(a.id);
                        }
                    }
                    Op::Downgrading(w, h) => {
                        if let Ok(a) = atlas.allocate_downgrading(w, h, 8) {
                            prop_assert!(a.region.width <= w && a.region.height <= h);
                            ids.push(a.id);
                        }
                    }
                    Op::Free(i) if !ids.is_empty() => {
                        let id = ids.swap_remove(i % ids.len());
                        atlas.free(id).unwrap();
                    }
                    Op::Free(_) => {}
                }
                assert_disjoint(&atlas);
                prop_assert_eq!(atlas.regions().count(), ids.len());
            }
        }
    }

    #[test]
    fn freed_regions_are_reused() {
        let mut atlas = Atlas::new(64, 64, 1).unwrap();
        let mut ids = Vec::new();
        while let Ok(a) = atlas.allocate(14, 14) {
            ids.push(a.id);
        }
        assert_eq!(ids.len(), 16, "a 64x64 atlas holds 16 padded 14x14 regions");
        let freed = ids[5];
        atlas.free(freed).unwrap();
        let again = atlas.allocate(14, 14).expect("the freed room is reused");
        assert_disjoint(&atlas);
        assert_eq!(atlas.regions().count(), 16);
        assert!(atlas.allocate(14, 14).is_err());
        assert_eq!(
            atlas.free(freed),
            Err(AtlasError::UnknownRegion(freed)),
            "freeing twice is an error"
        );
        atlas.free(again.id).unwrap();
    }

    #[test]
    fn a_full_atlas_downgrades_then_errors() {
        let mut atlas = Atlas::new(64, 64, 0).unwrap();
        let big = atlas.allocate(64, 48).unwrap();
        assert!(!big.downgraded());
        // 64x16 left: a 32x32 request gets 16x16.
        let a = atlas.allocate_downgrading(32, 32, 8).unwrap();
        assert!(a.downgraded());
        assert_eq!((a.region.width, a.region.height), (16, 16));
        assert_eq!(a.requested, (32, 32));
        // Exact allocation does not downgrade.
        assert!(matches!(
            atlas.allocate(32, 32),
            Err(AtlasError::Full { .. })
        ));
        while atlas.allocate_downgrading(16, 16, 8).is_ok() {}
        let e = atlas.allocate_downgrading(16, 16, 8).unwrap_err();
        assert!(
            matches!(
                e,
                AtlasError::Full {
                    width: 8,
                    height: 8,
                    ..
                }
            ),
            "{e}"
        );
        assert!(e.to_string().contains("full"), "{e}");
        assert_disjoint(&atlas);
    }

    #[test]
    fn bad_sizes_are_errors() {
        assert!(matches!(
            Atlas::new(0, 64, 0),
            Err(AtlasError::BadSize { .. })
        ));
        assert!(Atlas::new(64, Atlas::MAX_SIDE + 1, 0).is_err());
        let mut atlas = Atlas::new(64, 64, 2).unwrap();
        for (w, h) in [(0, 4), (4, 0), (61, 4), (u32::MAX, 1)] {
            assert!(
                matches!(atlas.allocate(w, h), Err(AtlasError::BadRequest { .. })),
                "{w}x{h}"
            );
            assert!(atlas.allocate_downgrading(w, h, 1).is_err(), "{w}x{h}");
        }
        assert!(atlas.allocate(60, 60).is_ok());
    }
}
