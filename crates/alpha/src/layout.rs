//! Which lightmap region each alpha entity gets: its texel layout (from the talk's
//! parameterisations) and its size (from screen coverage), packed into one atlas whose size is
//! derived from what the scene needs.

use crate::{side_for_coverage, Atlas, AtlasError, Region, MIN_SIDE};
use glam::Vec3;
use histencil_scene::{Camera, ParticleLayout, ParticleSystem, Scene};

/// An alpha entity of a scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum EntityKey {
    /// `scene.alpha_objects[i]`
    Object(usize),
    /// `scene.particle_systems[i]`
    System(usize),
}

impl EntityKey {
    /// The entity's world-space box in `scene`.
    pub fn world_bounds(self, scene: &Scene) -> (Vec3, Vec3) {
        match self {
            EntityKey::Object(i) => scene.alpha_objects[i].world_bounds(),
            EntityKey::System(i) => scene.particle_systems[i].world_bounds(),
        }
    }
}

/// How an entity's probes sit in its region: `tiles` tiles of `tile_width x tile_height` texels
/// side by side (a slice each for sliced systems, one otherwise).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RegionShape {
    pub tiles: u32,
    pub tile_width: u32,
    pub tile_height: u32,
    /// Whether a full atlas may halve the tiles (not for dust: one texel per mote is the layout).
    pub downgradable: bool,
}

/// An entity's place in the atlas.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EntityRegion {
    pub entity: EntityKey,
    /// The whole region: `shape.tiles` tiles side by side.
    pub region: Region,
    /// The tiles as granted (halved when the atlas was full).
    pub shape: RegionShape,
    pub downgraded: bool,
}

/// Every entity's region, and the atlas they were packed into.
pub struct LightmapLayout {
    pub atlas: Atlas,
    pub regions: Vec<EntityRegion>,
}

/// The smallest atlas tried; it doubles until everything fits.
pub const START_ATLAS_SIDE: u32 = 256;
/// Texels of guard band around every region.
pub const ATLAS_PADDING: u32 = 1;

#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LayoutError {
    #[error("lightmap resolution {0} is out of range (2..={max} texels a side)", max = MAX_FORCED_SIDE)]
    BadResolution(u32),
    /// `reason` is in the message, so it is not also the error's source (a chain would
    /// print it twice).
    #[error("the lightmap atlas is full even at {side}x{side} texels with every region halved down to {min}: {reason}", min = MIN_SIDE)]
    AtlasFull { side: u32, reason: AtlasError },
}

/// Diameter in pixels that a sphere of `radius` at `centre` covers on a `viewport_height`-pixel
/// tall view from `camera` (at least the near plane away).
pub fn projected_diameter(camera: &Camera, centre: Vec3, radius: f32, viewport_height: u32) -> f32 {
    let distance = (centre - camera.eye).length().max(camera.near);
    let tan = (camera.fov_y_radians * 0.5).tan();
    2.0 * radius / (2.0 * distance * tan) * viewport_height as f32
}

/// Centre and radius of a sphere containing the box `lo..hi`.
pub fn bounding_sphere((lo, hi): (Vec3, Vec3)) -> (Vec3, f32) {
    ((lo + hi) * 0.5, (hi - lo).length() * 0.5)
}

/// The texel layout of `entity`: its size from screen coverage, or `forced_side` texels.
pub fn region_shape(
    scene: &Scene,
    entity: EntityKey,
    viewport_height: u32,
    forced_side: Option<u32>,
) -> RegionShape {
    let side = || {
        let (centre, radius) = bounding_sphere(entity.world_bounds(scene));
        forced_side.unwrap_or_else(|| {
            side_for_coverage(projected_diameter(
                &scene.camera,
                centre,
                radius,
                viewport_height,
            ))
        })
    };
    let square = |tiles, side| RegionShape {
        tiles,
        tile_width: side,
        tile_height: side,
        downgradable: true,
    };
    match entity {
        EntityKey::Object(_) => square(1, side()),
        EntityKey::System(i) => {
            let system = &scene.particle_systems[i];
            match system.layout {
                ParticleLayout::Billboard => square(1, side()),
                ParticleLayout::Slices { count } => square(count, side()),
                ParticleLayout::Dust => {
                    let (w, h) = dust_grid(system.particles.len() as u32);
                    RegionShape {
                        tiles: 1,
                        tile_width: w,
                        tile_height: h,
                        downgradable: false,
                    }
                }
                ParticleLayout::Ribbon => RegionShape {
                    tiles: 1,
                    tile_width: forced_side
                        .unwrap_or_else(|| ribbon_texels(scene, system, viewport_height)),
                    tile_height: 1,
                    downgradable: true,
                },
            }
        }
    }
}

/// The texel grid of `motes` dust motes: as square as possible, row by row.
pub fn dust_grid(motes: u32) -> (u32, u32) {
    let w = (motes as f64).sqrt().ceil().max(1.0) as u32;
    (w, motes.div_ceil(w).max(1))
}

/// Texels along a ribbon: one per [`crate::PIXELS_PER_TEXEL`] pixels of its projected length,
/// as for a region side.
fn ribbon_texels(scene: &Scene, system: &ParticleSystem, viewport_height: u32) -> u32 {
    let length_px: f32 = system
        .particles
        .windows(2)
        .map(|w| {
            let mid = (w[0].position + w[1].position) * 0.5;
            let half = (w[1].position - w[0].position).length() * 0.5;
            projected_diameter(&scene.camera, mid, half, viewport_height)
        })
        .sum();
    side_for_coverage(length_px)
}

/// Every alpha entity of `scene`, objects first.
pub fn entities(scene: &Scene) -> impl Iterator<Item = EntityKey> {
    (0..scene.alpha_objects.len())
        .map(EntityKey::Object)
        .chain((0..scene.particle_systems.len()).map(EntityKey::System))
}

/// The forced lightmap sides [`plan_layout`] and the renderer take.
/// Largest atlas side a renderer tries before regions are halved: 4096^2 texels is 256 MiB per
/// f32 atlas, and every Vulkan 1.3 device allows 4096-texel images.
pub const MAX_ATLAS_SIDE: u32 = 4096;

/// The largest forced side: one region of it, with its guard band on both sides, fills the
/// largest atlas. (4096 itself cannot fit a 4096-texel atlas once the guard band is added.)
pub const MAX_FORCED_SIDE: u32 = MAX_ATLAS_SIDE - 2 * ATLAS_PADDING;
const FORCED_SIDES: std::ops::RangeInclusive<u32> = 2..=MAX_FORCED_SIDE;

/// Checks a forced lightmap side (2..=[`MAX_FORCED_SIDE`] texels).
///
/// # Errors
/// [`LayoutError::BadResolution`] outside the range.
pub fn check_forced_side(side: u32) -> Result<(), LayoutError> {
    if FORCED_SIDES.contains(&side) {
        Ok(())
    } else {
        Err(LayoutError::BadResolution(side))
    }
}

/// Packs every entity's region into the smallest square atlas from [`START_ATLAS_SIDE`]
/// (doubling) up to `max_side` that holds them all at full size. When even `max_side` does not,
/// regions are halved where they allow it ([`Atlas::allocate_downgrading`]; the result says
/// which were).
///
/// # Errors
/// [`LayoutError::BadResolution`] for a forced side outside 2..=[`MAX_FORCED_SIDE`], and
/// [`LayoutError::AtlasFull`] when the entities do not fit even halved.
pub fn plan_layout(
    scene: &Scene,
    viewport_height: u32,
    forced_side: Option<u32>,
    max_side: u32,
) -> Result<LightmapLayout, LayoutError> {
    if let Some(side) = forced_side {
        check_forced_side(side)?;
    }
    let shapes: Vec<(EntityKey, RegionShape)> = entities(scene)
        .map(|e| (e, region_shape(scene, e, viewport_height, forced_side)))
        .collect();
    let max_side = max_side.clamp(1, Atlas::MAX_SIDE);
    let mut side = START_ATLAS_SIDE.min(max_side);
    loop {
        let downgrade = side >= max_side;
        match pack(&shapes, side, downgrade) {
            Ok(layout) => return Ok(layout),
            Err(reason) if downgrade => return Err(LayoutError::AtlasFull { side, reason }),
            Err(_) => side = (side * 2).min(max_side),
        }
    }
}

fn pack(
    shapes: &[(EntityKey, RegionShape)],
    side: u32,
    downgrade: bool,
) -> Result<LightmapLayout, AtlasError> {
    let mut atlas = Atlas::new(side, side, ATLAS_PADDING)?;
    // Largest first: shelf packing wastes less, and the order (hence the layout) is fixed.
    let mut order: Vec<usize> = (0..shapes.len()).collect();
    order.sort_by_key(|&i| {
        let s = shapes[i].1;
        (
            std::cmp::Reverse(s.tile_height),
            std::cmp::Reverse(s.tiles * s.tile_width),
            i,
        )
    });
    let mut regions = vec![None; shapes.len()];
    for i in order {
        let (entity, shape) = shapes[i];
        let (w, h) = (shape.tiles * shape.tile_width, shape.tile_height);
        let allocation = if downgrade && shape.downgradable {
            // A row of slices can be wider than the whole atlas: halve it until it could fit
            // (the allocation below halves further while there is no room).
            let (mut w, mut h) = (w, h);
            let min_side = MIN_SIDE.min(w.max(h));
            while w.max(h) + 2 * ATLAS_PADDING > side && w.max(h) / 2 >= min_side {
                (w, h) = (w.div_ceil(2), h.div_ceil(2));
            }
            atlas.allocate_downgrading(w, h, min_side)?
        } else {
            atlas.allocate(w, h)?
        };
        let region = allocation.region;
        regions[i] = Some(EntityRegion {
            entity,
            region,
            shape: RegionShape {
                tile_width: region.width / shape.tiles,
                tile_height: region.height,
                ..shape
            },
            downgraded: (region.width, region.height) != (w, h),
        });
    }
    Ok(LightmapLayout {
        atlas,
        regions: regions
            .into_iter()
            .map(|r| r.expect("every entity placed"))
            .collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(name: &str) -> Scene {
        histencil_scene::embedded(name).unwrap()
    }

    #[test]
    fn every_entity_gets_a_region_and_none_overlap() {
        for name in ["alpha", "dust", "ribbon", "volume", "alpha-many"] {
            let s = scene(name);
            let layout = plan_layout(&s, 720, None, 4096).unwrap();
            assert_eq!(layout.regions.len(), s.alpha_entity_count(), "{name}");
            for (i, a) in layout.regions.iter().enumerate() {
                assert!(!a.downgraded);
                for b in &layout.regions[i + 1..] {
                    assert!(
                        !a.region.expanded(ATLAS_PADDING).overlaps(&b.region),
                        "{name}"
                    );
                }
            }
        }
    }

    #[test]
    fn region_shapes_follow_the_layouts() {
        let s = scene("volume");
        let shape = region_shape(&s, EntityKey::System(0), 720, Some(32));
        assert_eq!(
            (shape.tiles, shape.tile_width, shape.tile_height),
            (8, 32, 32)
        );
        let s = scene("dust");
        let shape = region_shape(&s, EntityKey::System(0), 720, Some(32));
        assert_eq!((shape.tile_width, shape.tile_height), (25, 24));
        assert!(shape.tile_width * shape.tile_height >= 600 && !shape.downgradable);
        let s = scene("ribbon");
        assert_eq!(
            region_shape(&s, EntityKey::System(0), 720, None).tile_height,
            1
        );
        // Coverage: the same sphere seen on a taller viewport gets at least as many texels.
        let s = scene("alpha");
        let small = region_shape(&s, EntityKey::Object(0), 180, None).tile_width;
        let large = region_shape(&s, EntityKey::Object(0), 1440, None).tile_width;
        assert!(small < large, "{small} {large}");
    }

    #[test]
    fn the_atlas_grows_then_downgrades_then_fails_clearly() {
        let mut s = scene("alpha-many");
        let grown = plan_layout(&s, 720, Some(128), 4096).unwrap();
        assert!(grown.atlas.size().0 > START_ATLAS_SIDE);
        let capped = plan_layout(&s, 720, Some(128), 256).unwrap();
        assert!(capped.regions.iter().any(|r| r.downgraded));
        s.particle_systems[0].layout = ParticleLayout::Dust;
        s.particle_systems[0].particles = s.particle_systems[0].particles.repeat(400);
        let err = plan_layout(&s, 720, Some(128), 256)
            .err()
            .expect("too many motes");
        assert!(matches!(err, LayoutError::AtlasFull { .. }), "{err}");
        let bad = plan_layout(&s, 720, Some(1), 256).err();
        assert_eq!(bad, Some(LayoutError::BadResolution(1)));
    }

    /// The documented largest side fits one entity (every layout kind), and one more does not
    /// parse.
    #[test]
    fn the_largest_forced_side_fits() {
        for name in ["alpha", "dust", "ribbon", "volume"] {
            let mut s = histencil_scene::embedded(name).unwrap();
            s.alpha_objects.truncate(1);
            s.particle_systems
                .truncate(usize::from(s.alpha_objects.is_empty()));
            let layout = plan_layout(&s, 720, Some(MAX_FORCED_SIDE), MAX_ATLAS_SIDE)
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(layout.regions.len(), 1);
            let r = layout.regions[0];
            assert_eq!(r.downgraded, r.shape.tiles > 1, "{name}: {r:?}");
        }
        assert!(check_forced_side(MAX_FORCED_SIDE + 1).is_err());
        assert!(check_forced_side(1).is_err());
    }
}
