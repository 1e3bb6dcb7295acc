//! Planning alpha entities end to end: each one's slices and side from the error estimate
//! ([`crate::choose_parameters`]), then their regions packed ([`crate::plan_regions`]); for an
//! engine's entities ([`plan_entities`]) and for a histencil scene's ([`plan_layout`]).

use crate::entity::{scene_alpha_entities, AlphaEntity, AlphaEntityKind, ProbeMeshes};
use crate::estimate::{choose_parameters, Parameters};
use crate::layout::{
    check_forced_side, plan_regions, ribbon_length_px, EntityDesc, EntityKind, LayoutError,
    LightmapLayout, Viewer,
};
use histencil_scene::{Light, ParticleLayout, Scene};

/// A lightmap plan: the regions, and what each entity was given and why.
#[derive(Debug)]
pub struct AlphaPlan {
    /// The atlas and every entity's region in it.
    pub layout: LightmapLayout,
    /// Per entity, in order: its slices and side and the error estimate behind them.
    pub parameters: Vec<Parameters>,
}

/// How [`plan_entities`] chooses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChoiceSettings {
    /// Every region's side, as an author forces it (2..=[`crate::MAX_FORCED_SIDE`]); `None`: chosen.
    pub forced_side: Option<u32>,
    /// The estimated mean error (8-bit steps) the choice keeps each entity under.
    pub target: f32,
}

impl Default for ChoiceSettings {
    fn default() -> Self {
        Self {
            forced_side: None,
            target: crate::estimate::DEFAULT_TARGET,
        }
    }
}

/// Plans `entities` seen by `viewer` on a `viewport_height`-pixel view and lit by `lights`:
/// each one's slices and side from the error estimate ([`choose_parameters`]), then their
/// regions packed into an atlas of at most `max_side` ([`plan_regions`]). Regions and
/// parameters come back in entity order.
///
/// A puff of smoke beside a point light, its slices chosen by the estimate:
/// ```
/// use glam::Vec3;
/// use histencil_alpha::*;
/// use histencil_scene::{Camera, Light, Material, Particle, ParticleLayout};
///
/// let camera = Camera {
///     eye: Vec3::new(0.0, 1.0, 6.0),
///     target: Vec3::ZERO,
///     up: Vec3::Y,
///     fov_y_radians: 1.0,
///     near: 0.1,
///     far: 100.0,
/// };
/// let particles: Vec<Particle> = (0..16)
///     .map(|i| {
///         let a = i as f32 * 0.4;
///         Particle { position: Vec3::new(a.cos(), 0.4 * a.sin(), a.sin()) * 0.6, size: 0.3 }
///     })
///     .collect();
/// let smoke = AlphaEntity {
///     kind: AlphaEntityKind::Particles { layout: ParticleLayout::Auto, particles: &particles },
///     material: Material::lambert(Vec3::splat(0.8)),
///     opacity: 0.5,
/// };
/// let lights = [Light::point(Vec3::new(1.5, 1.0, 0.0), 4.0, Vec3::ONE)];
/// let settings = ChoiceSettings::default();
/// let viewer = Viewer::from_camera(&camera);
/// let plan = plan_entities(&[smoke], &viewer, &lights, 720, MAX_ATLAS_SIDE, &settings)?;
///
/// let (chosen, placed) = (plan.parameters[0], plan.layout.regions[0]);
/// // The cheapest slices and side whose estimated error stays under the target, never more
/// // texels than the smoke's size on screen can show.
/// assert_eq!(chosen.kind, ParameterKind::Slices);
/// assert!(chosen.estimate.mean <= settings.target);
/// assert!(chosen.side <= chosen.coverage_side);
/// // One tile per slice in its region, which the atlas granted in full.
/// assert_eq!(placed.shape.tiles, chosen.slices);
/// assert_eq!((placed.shape.tile_width, placed.shape.tile_height), (chosen.side, chosen.side));
/// assert_eq!((placed.region.width, placed.region.height), placed.shape.size());
/// assert!(!placed.downgraded);
///
/// // A light made NaN is refused, as the lighting refuses it when it records.
/// let nan = [Light::point(Vec3::new(f32::NAN, 1.0, 0.0), 4.0, Vec3::ONE)];
/// let refused = plan_entities(&[], &viewer, &nan, 720, MAX_ATLAS_SIDE, &settings);
/// assert!(matches!(refused, Err(LayoutError::BadLight { index: 0, .. })));
/// # Ok::<(), LayoutError>(())
/// ```
///
/// # Errors
/// [`LayoutError::BadEntity`] for an entity [`AlphaEntity::problem`] refuses,
/// [`LayoutError::BadLight`] for a light [`histencil_scene::Light::problem`] refuses,
/// [`LayoutError::BadResolution`] for a forced side outside 2..=[`crate::MAX_FORCED_SIDE`], and
/// [`LayoutError::AtlasFull`] when the regions do not fit even halved.
pub fn plan_entities(
    entities: &[AlphaEntity],
    viewer: &Viewer,
    lights: &[Light],
    viewport_height: u32,
    max_side: u32,
    settings: &ChoiceSettings,
) -> Result<AlphaPlan, LayoutError> {
    if let Some(side) = settings.forced_side {
        check_forced_side(side)?;
    }
    if let Some((index, reason)) = entities
        .iter()
        .enumerate()
        .find_map(|(i, e)| e.problem().map(|r| (i, r)))
    {
        return Err(LayoutError::BadEntity { index, reason });
    }
    // A light made NaN would weigh every entity's choice by nothing; refused as the lighting
    // refuses it at record time.
    if let Some((index, reason)) = lights
        .iter()
        .enumerate()
        .find_map(|(i, l)| l.problem().map(|r| (i, r)))
    {
        return Err(LayoutError::BadLight { index, reason });
    }
    let parameters: Vec<Parameters> = entities
        .iter()
        .map(|e| {
            choose_parameters(
                e,
                viewer,
                lights,
                viewport_height,
                settings.forced_side,
                settings.target,
            )
        })
        .collect();
    let descs: Vec<EntityDesc> = entities
        .iter()
        .zip(&parameters)
        .map(|(e, p)| resolved_desc(e, p, viewer, viewport_height, settings.forced_side))
        .collect();
    let layout = plan_regions(&descs, viewer, viewport_height, max_side)?;
    Ok(AlphaPlan { layout, parameters })
}

/// `entity`'s description with its chosen parameters: an automatic system's slices made
/// explicit, the side fixed (dust keeps its grid; a ribbon its length in pixels unless forced).
fn resolved_desc(
    entity: &AlphaEntity,
    parameters: &Parameters,
    viewer: &Viewer,
    viewport_height: u32,
    forced_side: Option<u32>,
) -> EntityDesc {
    let desc = entity.desc();
    match entity.kind {
        AlphaEntityKind::Particles { layout, particles } => match layout {
            ParticleLayout::Dust => desc,
            ParticleLayout::Ribbon => EntityDesc {
                coverage_px: Some(ribbon_length_px(viewer, particles, viewport_height)),
                side: forced_side,
                ..desc
            },
            _ => {
                let layout = match parameters.slices {
                    1 => ParticleLayout::Billboard,
                    count => ParticleLayout::Slices { count },
                };
                let count = u32::try_from(particles.len()).unwrap_or(u32::MAX);
                EntityDesc {
                    kind: EntityKind::Particles { layout, count },
                    side: Some(parameters.side),
                    ..desc
                }
            }
        },
        AlphaEntityKind::Object { .. } => EntityDesc {
            side: Some(parameters.side),
            ..desc
        },
    }
}

/// Plans `scene`'s alpha entities ([`plan_entities`] on [`scene_alpha_entities`], seen by its
/// camera, lit by its lights); every side forced to `forced_side` if given. Regions and
/// parameters in [`crate::entities`] order.
///
/// # Errors
/// As [`plan_entities`].
pub fn plan_layout(
    scene: &Scene,
    viewport_height: u32,
    forced_side: Option<u32>,
    max_side: u32,
) -> Result<AlphaPlan, LayoutError> {
    let meshes = ProbeMeshes::new(scene);
    let entities = scene_alpha_entities(scene, &meshes);
    let settings = ChoiceSettings {
        forced_side,
        ..ChoiceSettings::default()
    };
    let viewer = Viewer::from_camera(&scene.camera);
    plan_entities(
        &entities,
        &viewer,
        &scene.lights,
        viewport_height,
        max_side,
        &settings,
    )
}
