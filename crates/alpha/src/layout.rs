//! Which lightmap region each alpha entity gets: its texel layout (from the talk's
//! parameterisations) and its size (from screen coverage), packed into one atlas whose size is
//! derived from what the entities need.
//!
//! The planner works on plain values ([`EntityDesc`]: what an entity is, its world bounds, its
//! coverage on screen if the caller knows better, a forced side), so an engine plans its own
//! entities the way histencil plans a scene's ([`crate::plan_layout`]).

use crate::{side_for_coverage, Atlas, AtlasError, Region, MIN_SIDE};
use glam::{Mat4, Vec3};
use histencil_model::ViewDesc;
use histencil_scene::{Camera, Particle, ParticleLayout, Scene, MAX_SLICES};

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

/// What an alpha entity is, as far as its lightmap's texel layout goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EntityKind {
    /// A translucent mesh: one square region in its lightmap UV layout.
    Surface,
    /// A particle system of `count` particles laid out as `layout` says.
    Particles {
        /// How the system's probes are laid out.
        layout: ParticleLayout,
        /// How many particles (dust: motes, one texel each).
        count: u32,
    },
}

/// One alpha entity, as the planner needs it: plain values an engine has.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EntityDesc {
    /// A surface or a particle system, which decides the region's shape.
    pub kind: EntityKind,
    /// World-space box around everything the entity draws.
    pub bounds: (Vec3, Vec3),
    /// How many pixels the entity spans on screen; `None`: the diameter its bounds' sphere
    /// projects to. (A ribbon's scene entry gives its projected length.)
    pub coverage_px: Option<f32>,
    /// A forced region side (a ribbon: texels along it), 2..=[`MAX_FORCED_SIDE`]; `None`: from
    /// coverage.
    pub side: Option<u32>,
}

/// Where the camera is and how it sees: what sizing and the probe frames need from a view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Viewer {
    /// World position of the camera.
    pub eye: Vec3,
    /// Unit camera axes: right, up, and forward (the view direction).
    pub right: Vec3,
    /// Unit camera axis pointing up on screen.
    pub up: Vec3,
    /// Unit camera axis along the view direction.
    pub forward: Vec3,
    /// `tan(fov_y / 2)`.
    pub tan_half_fov_y: f32,
    /// Distances below this count as this (an entity around the eye is as large as it gets).
    pub near: f32,
}

impl Viewer {
    /// A scene camera's viewer.
    pub fn from_camera(camera: &Camera) -> Self {
        let forward = (camera.target - camera.eye).normalize();
        let right = forward.cross(camera.up).normalize();
        Self {
            eye: camera.eye,
            right,
            up: right.cross(forward),
            forward,
            tan_half_fov_y: (camera.fov_y_radians * 0.5).tan(),
            near: camera.near,
        }
    }

    /// The viewer of an engine's view: axes and eye from the inverse of `world_to_view` (a
    /// rigid transform), the field of view from the projection's `P11`. `None` when the view
    /// matrix cannot be inverted or `P11` is not a finite non-zero scale.
    pub fn from_view(view: &ViewDesc) -> Option<Self> {
        let world_to_view = Mat4::from_cols_array_2d(&view.world_to_view);
        let p11 = view.view_to_clip[1][1];
        let det = world_to_view.determinant();
        if !(det.is_normal() && p11.is_normal()) {
            return None;
        }
        let inv = world_to_view.inverse();
        let axis = |v: glam::Vec4| v.truncate().normalize_or_zero();
        let viewer = Self {
            eye: inv.w_axis.truncate(),
            right: axis(inv.x_axis),
            up: axis(inv.y_axis),
            forward: -axis(inv.z_axis),
            tan_half_fov_y: 1.0 / p11.abs(),
            near: 1e-3,
        };
        let finite = [viewer.eye, viewer.right, viewer.up, viewer.forward]
            .iter()
            .all(|v| v.is_finite());
        (finite && viewer.forward != Vec3::ZERO && viewer.tan_half_fov_y.is_finite())
            .then_some(viewer)
    }
}

/// How an entity's probes sit in its region: `tiles` tiles of `tile_width x tile_height` texels
/// (a slice each for sliced systems, one otherwise), `columns` to a row, row by row: tile `k` at
/// `(k % columns, k / columns)`. Slices are laid out as square as their count allows, so a stack
/// of them does not stretch the atlas into a long strip.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RegionShape {
    /// How many tiles: the slice count of a sliced system, 1 otherwise.
    pub tiles: u32,
    /// Tiles to a row.
    pub columns: u32,
    /// Texels across one tile.
    pub tile_width: u32,
    /// Texels down one tile.
    pub tile_height: u32,
    /// Whether a full atlas may halve the tiles (not for dust: one texel per mote is the layout).
    pub downgradable: bool,
}

impl RegionShape {
    /// Rows of tiles.
    pub fn rows(&self) -> u32 {
        self.tiles.div_ceil(self.columns.max(1))
    }

    /// The texels the tiles span: `(columns * tile_width, rows * tile_height)`.
    pub fn size(&self) -> (u32, u32) {
        (
            self.columns * self.tile_width,
            self.rows() * self.tile_height,
        )
    }
}

/// An entity's place in the atlas.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EntityRegion {
    /// The whole region: its tiles laid out as `shape` says.
    pub region: Region,
    /// The tiles as granted (halved when the atlas was full).
    pub shape: RegionShape,
    /// Whether the tiles are smaller than asked for: the entity is lit coarser this frame.
    pub downgraded: bool,
}

/// Every entity's region (in the order the entities were given), and the atlas they were packed
/// into.
pub struct LightmapLayout {
    /// The atlas, sized to fit, with every region allocated.
    pub atlas: Atlas,
    /// One per entity, in the entities' order.
    pub regions: Vec<EntityRegion>,
}

impl std::fmt::Debug for LightmapLayout {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LightmapLayout")
            .field("atlas_size", &self.atlas.size())
            .field("regions", &self.regions)
            .finish()
    }
}

/// The smallest atlas tried; it doubles until everything fits.
pub const START_ATLAS_SIDE: u32 = 256;
/// Texels of guard band around every region.
pub const ATLAS_PADDING: u32 = 1;

/// Why the entities could not be laid out.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LayoutError {
    /// A forced side outside `2..=`[`MAX_FORCED_SIDE`].
    #[error("lightmap resolution {0} is out of range (2..={max} texels a side)", max = MAX_FORCED_SIDE)]
    BadResolution(u32),
    /// `reason` is in the message, so it is not also the error's source (a chain would
    /// print it twice).
    #[error("the lightmap atlas is full even at {side}x{side} texels with every region halved down to {min}: {reason}", min = MIN_SIDE)]
    AtlasFull {
        /// The largest atlas side tried.
        side: u32,
        /// The allocation that failed there.
        reason: AtlasError,
    },
    /// An entity that cannot be laid out (bounds not finite, no particles, ...).
    #[error("alpha entity {index}: {reason}")]
    BadEntity {
        /// Its index in the entities given.
        index: usize,
        /// What is wrong with it.
        reason: String,
    },
    /// A light the plan cannot weigh (a NaN or infinity, ...), as a scene's validation refuses
    /// it ([`histencil_scene::Light::problem`]).
    #[error("light {index}: {reason}")]
    BadLight {
        /// Its index in the lights given.
        index: usize,
        /// What is wrong with it.
        reason: String,
    },
}

/// Diameter in pixels that a sphere of `radius` at `centre` covers on a `viewport_height`-pixel
/// tall view from `viewer` (at least the near plane away).
pub fn projected_diameter(viewer: &Viewer, centre: Vec3, radius: f32, viewport_height: u32) -> f32 {
    let distance = (centre - viewer.eye).length().max(viewer.near);
    2.0 * radius / (2.0 * distance * viewer.tan_half_fov_y) * viewport_height as f32
}

/// Centre and radius of a sphere containing the box `lo..hi`.
pub fn bounding_sphere((lo, hi): (Vec3, Vec3)) -> (Vec3, f32) {
    ((lo + hi) * 0.5, (hi - lo).length() * 0.5)
}

/// What is wrong with `desc`, if anything: bounds that are not finite or inside out, a forced
/// side out of range, a particle system without particles, a slice count outside
/// 2..=`MAX_SLICES`, a ribbon of fewer than two points.
pub fn entity_problem(desc: &EntityDesc) -> Option<&'static str> {
    let (lo, hi) = desc.bounds;
    if !(lo.is_finite() && hi.is_finite()) || lo.cmpgt(hi).any() {
        return Some("its bounds must be finite with min <= max on every axis");
    }
    if desc.coverage_px.is_some_and(|c| !c.is_finite() || c < 0.0) {
        return Some("its coverage must be finite and not negative");
    }
    if desc.side.is_some_and(|s| check_forced_side(s).is_err()) {
        return Some("its forced side is outside 2..=4094 texels");
    }
    match desc.kind {
        EntityKind::Surface => None,
        EntityKind::Particles { count: 0, .. } => Some("a particle system needs a particle"),
        EntityKind::Particles {
            layout: ParticleLayout::Slices { count },
            ..
        } if !(2..=MAX_SLICES).contains(&count) => Some("slices need 2 to 32 slices"),
        EntityKind::Particles {
            layout: ParticleLayout::Ribbon,
            count: 1,
        } => Some("a ribbon needs at least two control points"),
        EntityKind::Particles { .. } => None,
    }
}

/// The texel layout of `desc`: its size from screen coverage, or its forced side.
pub fn region_shape(desc: &EntityDesc, viewer: &Viewer, viewport_height: u32) -> RegionShape {
    let side = || {
        desc.side.unwrap_or_else(|| {
            let coverage = desc.coverage_px.unwrap_or_else(|| {
                let (centre, radius) = bounding_sphere(desc.bounds);
                projected_diameter(viewer, centre, radius, viewport_height)
            });
            side_for_coverage(coverage)
        })
    };
    let square = |tiles: u32, side| RegionShape {
        tiles,
        columns: (tiles as f64).sqrt().ceil() as u32,
        tile_width: side,
        tile_height: side,
        downgradable: true,
    };
    match desc.kind {
        EntityKind::Surface => square(1, side()),
        EntityKind::Particles { layout, count } => match layout {
            // An unresolved Auto is a billboard: `plan_entities` resolves it first.
            ParticleLayout::Billboard | ParticleLayout::Auto => square(1, side()),
            ParticleLayout::Slices { count } => square(count, side()),
            ParticleLayout::Dust => {
                let (w, h) = dust_grid(count);
                RegionShape {
                    tiles: 1,
                    columns: 1,
                    tile_width: w,
                    tile_height: h,
                    downgradable: false,
                }
            }
            ParticleLayout::Ribbon => RegionShape {
                tiles: 1,
                columns: 1,
                tile_width: side(),
                tile_height: 1,
                downgradable: true,
            },
        },
    }
}

/// The texel grid of `motes` dust motes: as square as possible, row by row.
pub fn dust_grid(motes: u32) -> (u32, u32) {
    let w = (motes as f64).sqrt().ceil().max(1.0) as u32;
    (w, motes.div_ceil(w).max(1))
}

/// A ribbon's projected length in pixels: the sum of its segments' projected lengths.
pub(crate) fn ribbon_length_px(
    viewer: &Viewer,
    particles: &[Particle],
    viewport_height: u32,
) -> f32 {
    particles
        .windows(2)
        .map(|w| {
            let mid = (w[0].position + w[1].position) * 0.5;
            let half = (w[1].position - w[0].position).length() * 0.5;
            projected_diameter(viewer, mid, half, viewport_height)
        })
        .sum()
}

/// Every alpha entity of `scene`, objects first.
pub fn entities(scene: &Scene) -> impl Iterator<Item = EntityKey> {
    (0..scene.alpha_objects.len())
        .map(EntityKey::Object)
        .chain((0..scene.particle_systems.len()).map(EntityKey::System))
}

/// Largest atlas side a renderer tries before regions are halved: 4096^2 RGBA16F texels are
/// 128 MiB, and every Vulkan 1.3 device allows 4096-texel images.
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
/// which were). Regions come back in `descs` order.
///
/// # Errors
/// [`LayoutError::BadEntity`] for a description [`entity_problem`] refuses, and
/// [`LayoutError::AtlasFull`] when the entities do not fit even halved.
pub fn plan_regions(
    descs: &[EntityDesc],
    viewer: &Viewer,
    viewport_height: u32,
    max_side: u32,
) -> Result<LightmapLayout, LayoutError> {
    if let Some((index, reason)) = descs
        .iter()
        .enumerate()
        .find_map(|(i, d)| entity_problem(d).map(|r| (i, r)))
    {
        let reason = reason.to_owned();
        return Err(LayoutError::BadEntity { index, reason });
    }
    let shapes: Vec<RegionShape> = descs
        .iter()
        .map(|d| region_shape(d, viewer, viewport_height))
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

fn pack(shapes: &[RegionShape], side: u32, downgrade: bool) -> Result<LightmapLayout, AtlasError> {
    let mut atlas = Atlas::new(side, side, ATLAS_PADDING)?;
    // Largest first: shelf packing wastes less, and the order (hence the layout) is fixed.
    let mut order: Vec<usize> = (0..shapes.len()).collect();
    order.sort_by_key(|&i| {
        let (w, h) = shapes[i].size();
        (std::cmp::Reverse(h), std::cmp::Reverse(w), i)
    });
    let mut regions = vec![None; shapes.len()];
    for i in order {
        let shape = shapes[i];
        let (w, h) = shape.size();
        let allocation = if downgrade && shape.downgradable {
            // A stack of slices can be wider than the whole atlas: halve it until it could fit
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
            region,
            shape: RegionShape {
                tile_width: region.width / shape.columns,
                tile_height: region.height / shape.rows(),
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
    use crate::plan_layout;

    fn scene(name: &str) -> Scene {
        histencil_scene::embedded(name).unwrap()
    }

    #[test]
    fn every_entity_gets_a_region_and_none_overlap() {
        for name in ["alpha", "dust", "ribbon", "volume", "alpha-many"] {
            let s = scene(name);
            let layout = plan_layout(&s, 720, None, 4096).unwrap().layout;
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
        let shape_of = |s: &Scene, index: usize, height: u32, forced: Option<u32>| {
            let viewer = Viewer::from_camera(&s.camera);
            let meshes = crate::ProbeMeshes::new(s);
            let desc = EntityDesc {
                side: forced,
                ..crate::scene_alpha_entities(s, &meshes)[index].desc()
            };
            region_shape(&desc, &viewer, height)
        };
        let mut s = scene("volume");
        s.particle_systems[0].layout = ParticleLayout::Slices { count: 8 };
        let shape = shape_of(&s, 0, 720, Some(32));
        assert_eq!(
            (shape.tiles, shape.tile_width, shape.tile_height),
            (8, 32, 32)
        );
        // Eight slices as a 3 x 3 grid, not a strip.
        assert_eq!(
            (shape.columns, shape.rows(), shape.size()),
            (3, 3, (96, 96))
        );
        let s = scene("dust");
        let shape = shape_of(&s, 0, 720, Some(32));
        assert_eq!((shape.tile_width, shape.tile_height), (25, 24));
        assert!(shape.tile_width * shape.tile_height >= 600 && !shape.downgradable);
        let s = scene("ribbon");
        assert_eq!(shape_of(&s, 0, 720, None).tile_height, 1);
        // Coverage: the same sphere seen on a taller viewport gets at least as many texels.
        let s = scene("alpha");
        let small = shape_of(&s, 0, 180, None).tile_width;
        let large = shape_of(&s, 0, 1440, None).tile_width;
        assert!(small < large, "{small} {large}");
    }

    #[test]
    fn the_atlas_grows_then_downgrades_then_fails_clearly() {
        let mut s = scene("alpha-many");
        let grown = plan_layout(&s, 720, Some(128), 4096).unwrap().layout;
        assert!(grown.atlas.size().0 > START_ATLAS_SIDE);
        let capped = plan_layout(&s, 720, Some(128), 256).unwrap().layout;
        assert!(capped.regions.iter().any(|r| r.downgraded));
        s.particle_systems[0].layout = ParticleLayout::Dust;
        s.particle_systems[0].particles = s.particle_systems[0].particles.repeat(400);
        let err = plan_layout(&s, 720, Some(128), 256).expect_err("too many motes");
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
                .unwrap_or_else(|e| panic!("{name}: {e}"))
                .layout;
            assert_eq!(layout.regions.len(), 1);
            let r = layout.regions[0];
            assert_eq!(r.downgraded, r.shape.tiles > 1, "{name}: {r:?}");
        }
        assert!(check_forced_side(MAX_FORCED_SIDE + 1).is_err());
        assert!(check_forced_side(1).is_err());
    }
}
