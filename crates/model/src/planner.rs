//! The frame planner on plain inputs: an engine's lights, the world bounds of each BRDF's
//! objects and its view in, the [`FramePlan`] out. Pure and without a GPU, so an engine can
//! plan on any thread and a test can check every decision on the CPU.
//!
//! Per light, in order:
//! 1. **Reach**: the BRDF slots whose boxes the light's range sphere reaches (every slot with
//!    objects, for a directional light). A light that reaches none is not drawn.
//! 2. **Visibility**: a volume the frustum cannot see is not drawn.
//! 3. **Case** ([`LightCase`]): a point light whose range sphere holds the whole near-plane
//!    rectangle is drawn full-screen (every pixel's ray starts inside it); a volume that may
//!    touch the near-plane rectangle crosses the near plane; any other volume is outside. Where
//!    it cannot be sure the planner takes the case that is correct for any volume
//!    ([`LightCase::CrossesNear`]).
//! 4. **Coverage**: the screen fraction of the volume's bounding sphere (an estimate: the
//!    ellipse inscribed in its exact screen rectangle), 1 for lights reaching the near plane.
//! 5. **Technique**: the caller's, or per light from a [`CostModel`] on coverage and BRDF count.

use crate::backend::PlatformCaps;
use crate::chooser::CostModel;
use crate::frame::{FlushPolicy, FramePlan, PlannedLight};
use crate::layout::StencilLayout;
pub use crate::light_shape::PlannedFor;
pub use crate::light_shape::{Aabb, LightShape, MAX_SPOT_ANGLE, VOLUME_OVERSHOOT};
use crate::plan::{LightCase, LightRequest, LightTechnique, PlanError};
use crate::view::View;
use glam::DVec3;

/// How the BRDFs of the frame's lights are separated.
// The cost model is plain `Copy` data (a few hundred bytes with its intervals), made once per
// plan: boxing it would cost the settings their `Copy` for nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TechniqueChoice {
    /// The talk's technique for every light.
    Stencil,
    /// One branching shader per light.
    Branching,
    /// Per light, whichever the cost model predicts cheaper for its coverage and BRDF count.
    Adaptive(CostModel),
}

/// Everything the planner reads: plain values an engine has at hand.
#[derive(Clone, Copy, Debug)]
pub struct PlanInputs<'a> {
    /// Every light's volume, in the engine's order: [`PlannedLight::input`] and the lighting's
    /// per-light data refer to this order.
    pub lights: &'a [LightShape],
    /// Per BRDF slot (the layout's), the world boxes of the objects with that BRDF: one box per
    /// object, or one around them all. Slots past the end have no objects.
    pub brdf_bounds: &'a [Vec<Aabb>],
    /// The camera the frame is drawn with: the frustum culls lights and decides each one's case.
    pub view: &'a View,
}

/// How the frame is to be drawn: plain values, one per frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanSettings {
    /// How each light's BRDFs are separated: stencil, branching or per light by cost.
    pub technique: TechniqueChoice,
    /// The platform whose stencil and hi-stencil behaviour the passes follow.
    pub caps: PlatformCaps,
    /// When hi-stencil flushes go in; [`FlushPolicy::Auto`] unless studying what breaks.
    pub flush: FlushPolicy,
}

/// How a light's volume meets the near-plane rectangle. Conservative: the margins only ever
/// move a light towards [`LightCase::CrossesNear`], whose plan is right for any volume.
fn classify(view: &View, shape: &LightShape, bound: (DVec3, f64)) -> LightCase {
    const MARGIN: f64 = 1e-5;
    if let LightShape::Point { position, range } = *shape {
        // The mesh contains the range sphere, so the near plane inside it is inside the mesh.
        let centre = DVec3::from(position.map(f64::from));
        if view.near_plane_inside(centre, f64::from(range) * (1.0 - MARGIN)) {
            return LightCase::ViewerInside;
        }
    }
    let (centre, radius) = bound;
    if view.distance_to_near_plane(centre) <= radius * (1.0 + MARGIN) {
        LightCase::CrossesNear
    } else {
        LightCase::Outside
    }
}

/// Plans a frame on plain inputs.
///
/// An engine with its data in stencil bits 0 and 1, a reversed-Z camera with an infinite far
/// plane, two BRDFs and two lights, on the PS3-like platform:
/// ```
/// use histencil_model::*;
///
/// let layout = StencilLayout::with_positions(
///     2,
///     StencilBits { culling_bit: 7, brdf_shift: 6, engine_mask: 0x03 },
/// )?;
/// let camera = Perspective {
///     eye: [0.0, 2.0, 10.0],
///     target: [0.0; 3],
///     up: [0.0, 1.0, 0.0],
///     fov_y_radians: 1.0,
///     aspect: 16.0 / 9.0,
///     near: 0.1,
///     far: FarPlane::Infinite,
///     depth: DepthConvention::Reversed,
/// };
/// let view = View::new(&camera.desc())?; // or ViewDesc { the engine's own matrices }
/// let floor = Aabb { min: [-10.0, -1.0, -10.0], max: [10.0, 0.0, 10.0] };
/// let statue = Aabb { min: [-1.0, 0.0, -1.0], max: [1.0, 3.0, 1.0] };
/// let lights = [
///     LightShape::Point { position: [0.0, 1.0, 2.0], range: 3.0 },
///     LightShape::Point { position: [8.0, 1.0, -8.0], range: 2.0 },
/// ];
/// let plan = plan_frame(
///     &layout,
///     &PlanInputs { lights: &lights, brdf_bounds: &[vec![floor], vec![statue]], view: &view },
///     &PlanSettings {
///         technique: TechniqueChoice::Stencil,
///         caps: Ps3Like.caps(),
///         flush: FlushPolicy::Auto,
///     },
/// )?;
/// // The first light touches both BRDFs and is drawn once per BRDF; the second only the floor.
/// assert_eq!(plan.lights[0].request.affected, [0, 1]);
/// assert_eq!(plan.lights[1].request.affected, [0]);
/// assert_eq!(plan.lights[0].request.case, LightCase::Outside);
/// // Reversed Z: the shade passes test "nearer" as GREATER.
/// let shade = plan.passes().find(|p| matches!(p.kind, PassKind::Shade(_))).unwrap();
/// assert_eq!(shade.state.depth.compare, Some(CompareOp::Greater));
/// print!("{}", plan.describe());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
///
/// # Errors
/// [`PlanError::BadLight`] and [`PlanError::BadBounds`] name the input that cannot be planned
/// with; [`PlanError::BoundsCount`] unless the bounds hold exactly one list per BRDF of the
/// layout (an engine that passed too few used to get surfaces silently left unlit).
pub fn plan_frame(
    layout: &StencilLayout,
    inputs: &PlanInputs,
    settings: &PlanSettings,
) -> Result<FramePlan, PlanError> {
    if inputs.brdf_bounds.len() != layout.brdfs_in_use() as usize {
        return Err(PlanError::BoundsCount {
            bounds: inputs.brdf_bounds.len(),
            brdfs: layout.brdfs_in_use(),
        });
    }
    for (slot, boxes) in inputs.brdf_bounds.iter().enumerate() {
        for (index, bounds) in boxes.iter().enumerate() {
            if let Some(problem) = bounds.problem() {
                return Err(PlanError::BadBounds {
                    slot: slot as u32,
                    index,
                    problem,
                });
            }
        }
    }
    let view = inputs.view;
    // Sized once: grown light by light, its reallocations were the first larger allocations
    // after the driver freed the last frame's commands (lavapipe allocates each command), and
    // glibc sorted all that was freed in them (plan + record of 256 lights through C, which
    // plans right after the reset, took 4 % longer than through Rust on lavapipe; sized, the
    // two are within about 2 %).
    let mut lights = Vec::with_capacity(inputs.lights.len());
    for (index, shape) in inputs.lights.iter().enumerate() {
        if let Some(problem) = shape.problem() {
            return Err(PlanError::BadLight { index, problem });
        }
        let affected: Vec<u32> = (0..inputs.brdf_bounds.len() as u32)
            .filter(|&slot| {
                inputs.brdf_bounds[slot as usize]
                    .iter()
                    .any(|b| shape.reaches(b))
            })
            .collect();
        if affected.is_empty() {
            continue;
        }
        let (case, coverage, screen_rect) = match shape.volume_bound() {
            None => (LightCase::FullScreen, 1.0, None),
            Some(bound) => {
                if view.culls_sphere(bound.0, bound.1) {
                    continue;
                }
                let case = classify(view, shape, bound);
                let coverage = match case {
                    LightCase::Outside => view.sphere_coverage(bound.0, bound.1),
                    _ => 1.0,
                };
                (case, coverage, view.sphere_rect(bound.0, bound.1))
            }
        };
        let technique = match settings.technique {
            // One BRDF needs neither technique (`plan_light` would say the same).
            _ if affected.len() == 1 => LightTechnique::SingleBrdf,
            TechniqueChoice::Stencil => LightTechnique::Stencil,
            TechniqueChoice::Branching => LightTechnique::Branching,
            TechniqueChoice::Adaptive(costs) => costs.choose_for(coverage, &affected),
        };
        lights.push(PlannedLight {
            input: index,
            coverage: Some(coverage),
            screen_rect,
            depth_range: None,
            request: LightRequest {
                case,
                affected,
                technique,
            },
        });
    }
    let mut plan = FramePlan::build(layout, &settings.caps, view.depth(), lights, settings.flush)?;
    plan.made_for = Some(Box::new(PlannedFor {
        view: *view.desc(),
        lights: inputs.lights.to_vec(),
        layout: *layout,
    }));
    Ok(plan)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::{Native, PlatformBackend};
    use crate::view::{DepthConvention, FarPlane, Perspective};

    fn view() -> View {
        let camera = Perspective {
            eye: [0.0, 0.0, 10.0],
            target: [0.0; 3],
            up: [0.0, 1.0, 0.0],
            fov_y_radians: 1.0,
            aspect: 1.0,
            near: 0.1,
            far: FarPlane::Infinite,
            depth: DepthConvention::Reversed,
        };
        View::new(&camera.desc()).unwrap()
    }

    fn plan(lights: &[LightShape], bounds: &[Vec<Aabb>]) -> Result<FramePlan, PlanError> {
        let view = view();
        plan_frame(
            &StencilLayout::new(2, 0).unwrap(),
            &PlanInputs {
                lights,
                brdf_bounds: bounds,
                view: &view,
            },
            &PlanSettings {
                technique: TechniqueChoice::Stencil,
                caps: Native.caps(),
                flush: FlushPolicy::Auto,
            },
        )
    }

    const UNIT: Aabb = Aabb {
        min: [-1.0; 3],
        max: [1.0; 3],
    };

    /// A plan knows what it was made for, and names the first way a frame differs from it.
    #[test]
    fn a_plan_names_how_a_frame_differs_from_what_it_was_made_for() {
        let light = LightShape::Point {
            position: [0.0, 0.0, 0.0],
            range: 2.0,
        };
        let bounds = [vec![UNIT], vec![]];
        let plan = plan(&[light, light], &bounds).unwrap();
        let made_for = plan.made_for.as_deref().expect("plan_frame records it");
        let (desc, layout) = (*view().desc(), StencilLayout::new(2, 0).unwrap());
        let same = || [light, light].into_iter();
        assert_eq!(made_for.difference(&desc, same(), &layout), None);
        let mut moved = desc;
        moved.world_to_view[3][2] -= 1.0;
        let mut zoomed = desc;
        zoomed.view_to_clip[1][1] *= 2.0;
        let far = LightShape::Point {
            position: [0.0, 0.0, 1.0],
            range: 2.0,
        };
        let other_layout = StencilLayout::new(3, 0).unwrap();
        let cases = [
            (
                made_for.difference(&moved, same(), &layout),
                "camera position",
            ),
            (made_for.difference(&zoomed, same(), &layout), "projection"),
            (
                made_for.difference(&desc, [light].into_iter(), &layout),
                "made for 2 lights, the frame has 1",
            ),
            (
                made_for.difference(&desc, [light, far].into_iter(), &layout),
                "light 1 moved",
            ),
            (
                made_for.difference(&desc, same(), &other_layout),
                "stencil layout",
            ),
        ];
        for (difference, expected) in cases {
            let text = difference.unwrap_or_else(|| panic!("{expected}: no difference seen"));
            assert!(text.contains(expected), "{expected}: {text}");
        }
        // A plan built by hand names no view: nothing to hold a frame to.
        let hand = FramePlan::from_requests(&layout, &Native, &[], FlushPolicy::Auto).unwrap();
        assert!(hand.made_for.is_none());
    }

    /// Every kind of bad light and bad box is an error naming it, never a panic or a plan.
    #[test]
    fn bad_inputs_are_errors_that_name_them() {
        let point = |position: [f32; 3], range| LightShape::Point { position, range };
        let spot = |direction: [f32; 3], outer_angle| LightShape::Spot {
            position: [0.0; 3],
            direction,
            range: 1.0,
            outer_angle,
        };
        let bad_lights = [
            point([f32::NAN, 0.0, 0.0], 1.0),
            point([0.0; 3], 0.0),
            point([0.0; 3], -1.0),
            point([0.0; 3], f32::INFINITY),
            point([0.0; 3], f32::NAN),
            spot([0.0; 3], 0.5),
            spot([f32::NAN, 0.0, 1.0], 0.5),
            spot([0.0, 0.0, 1.0], 0.0),
            spot([0.0, 0.0, 1.0], MAX_SPOT_ANGLE),
            spot([0.0, 0.0, 1.0], f32::NAN),
        ];
        for light in bad_lights {
            let lights = [point([0.0; 3], 1.0), light];
            let err = plan(&lights, &[vec![UNIT], vec![]]).unwrap_err();
            assert!(
                matches!(err, PlanError::BadLight { index: 1, .. }),
                "{light:?}: {err}"
            );
            assert!(err.to_string().starts_with("light 1: "), "{err}");
        }
        let bad_boxes = [
            Aabb {
                min: [1.0, 0.0, 0.0],
                max: [0.0, 1.0, 1.0],
            },
            Aabb {
                min: [f32::NEG_INFINITY; 3],
                max: [0.0; 3],
            },
            Aabb {
                min: [0.0; 3],
                max: [f32::NAN; 3],
            },
        ];
        for bounds in bad_boxes {
            let err = plan(&[], &[vec![], vec![UNIT, bounds]]).unwrap_err();
            assert!(
                matches!(
                    err,
                    PlanError::BadBounds {
                        slot: 1,
                        index: 1,
                        ..
                    }
                ),
                "{bounds:?}: {err}"
            );
        }
        for bounds in [vec![], vec![vec![UNIT]], vec![vec![], vec![], vec![UNIT]]] {
            let err = plan(&[], &bounds).unwrap_err();
            assert_eq!(
                err,
                PlanError::BoundsCount {
                    bounds: bounds.len(),
                    brdfs: 2
                }
            );
            assert!(err
                .to_string()
                .contains(&format!("has {} entries", bounds.len())));
            assert!(err.to_string().contains("has 2 BRDFs"));
        }
    }

    /// Light 0 reaches slot 0's box only, light 1 both, light 2 nothing; the directional light
    /// every slot with objects; the spot is bounded around its cone, not its apex.
    #[test]
    fn reach_follows_the_range_sphere() {
        let far_box = Aabb {
            min: [4.0, -1.0, -1.0],
            max: [6.0, 1.0, 1.0],
        };
        let lights = [
            LightShape::Point {
                position: [0.0; 3],
                range: 2.0,
            },
            LightShape::Point {
                position: [2.5, 0.0, 0.0],
                range: 2.0,
            },
            LightShape::Point {
                position: [0.0, 5.0, 0.0],
                range: 1.0,
            },
            LightShape::Directional,
        ];
        let plan = plan(&lights, &[vec![UNIT], vec![far_box]]).unwrap();
        let reach: Vec<(usize, Vec<u32>)> = plan
            .lights
            .iter()
            .map(|l| (l.input, l.request.affected.clone()))
            .collect();
        assert_eq!(
            reach,
            [(0, vec![0]), (1, vec![0, 1]), (3, vec![0, 1])],
            "{}",
            plan.describe()
        );
        let narrow = LightShape::Spot {
            position: [0.0; 3],
            direction: [0.0, 0.0, -2.0],
            range: 10.0,
            outer_angle: 0.1,
        };
        let (centre, radius) = narrow.volume_bound().unwrap();
        // Half way down a narrow cone, a little more than half its length in radius.
        assert!(
            (centre.z + 5.3).abs() < 0.1 && radius < 5.4,
            "{centre} {radius}"
        );
        let wide = LightShape::Spot {
            position: [0.0; 3],
            direction: [0.0, 0.0, -2.0],
            range: 10.0,
            outer_angle: 1.2,
        };
        let (centre, radius) = wide.volume_bound().unwrap();
        assert!(
            (centre.z + 10.5).abs() < 1e-9 && radius > 10.5,
            "{centre} {radius}"
        );
    }
}
