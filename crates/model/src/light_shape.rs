//! What a frame plan is planned from and for: each light's shape ([`LightShape`], with the
//! bounds the planner and the light-volume meshes share), the boxes of the BRDFs' objects
//! ([`Aabb`]), and the record a plan keeps of its inputs ([`PlannedFor`]). Below both the
//! planner and the plan (`frame.rs`), which each name these; neither names the other's module
//! for them.

use crate::layout::StencilLayout;
use crate::view::ViewDesc;
use glam::DVec3;

/// How far histencil's light-volume meshes may reach beyond the light's range: they contain the
/// range sphere (points) or the range cone closed by its cap (spots), and no vertex lies farther
/// than this factor of it (for spots, along the axis and across it). The planner bounds volumes
/// with it; `histencil-scene` tests its meshes against it.
pub const VOLUME_OVERSHOOT: f64 = 1.05;

/// The widest spot cone the volume mesh is built for (half-angle, radians): 80 degrees.
pub const MAX_SPOT_ANGLE: f32 = 80.0 * std::f32::consts::PI / 180.0;

/// An axis-aligned box in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// The corner with the smallest coordinates.
    pub min: [f32; 3],
    /// The corner with the largest coordinates; no coordinate below `min`'s.
    pub max: [f32; 3],
}

impl Aabb {
    /// Whether the sphere reaches strictly into the box.
    fn reached_by_sphere(&self, centre: DVec3, radius: f64) -> bool {
        let lo = DVec3::from(self.min.map(f64::from));
        let hi = DVec3::from(self.max.map(f64::from));
        centre.clamp(lo, hi).distance(centre) < radius
    }

    pub(crate) fn problem(&self) -> Option<&'static str> {
        let finite = self.min.iter().chain(&self.max).all(|v| v.is_finite());
        if !finite {
            Some("a corner is not finite")
        } else if (0..3).any(|i| self.min[i] > self.max[i]) {
            Some("min exceeds max")
        } else {
            None
        }
    }
}

/// What the planner needs of a light: where its volume is. Colours and intensities do not
/// change the plan.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightShape {
    /// Lights the sphere of `range` around `position`.
    Point {
        /// World position.
        position: [f32; 3],
        /// World distance past which the light gives nothing; above 0.
        range: f32,
    },
    /// Lights the cone from `position` along `direction` (need not be unit length) with
    /// half-angle `outer_angle` (radians, below [`MAX_SPOT_ANGLE`]), up to `range`.
    Spot {
        /// World position of the apex.
        position: [f32; 3],
        /// The cone's axis, any non-zero length.
        direction: [f32; 3],
        /// World distance along the axis past which the light gives nothing; above 0.
        range: f32,
        /// Half-angle of the cone, radians, above 0 and below [`MAX_SPOT_ANGLE`].
        outer_angle: f32,
    },
    /// Lights everything; drawn full-screen.
    Directional,
}

impl LightShape {
    pub(crate) fn problem(&self) -> Option<&'static str> {
        let finite = |v: &[f32]| v.iter().all(|c| c.is_finite());
        if let Some((position, range)) = match *self {
            LightShape::Point { position, range }
            | LightShape::Spot {
                position, range, ..
            } => Some((position, range)),
            LightShape::Directional => None,
        } {
            if !finite(&position) {
                return Some("position is not finite");
            }
            if !(range > 0.0 && range.is_finite()) {
                return Some("range must be positive and finite");
            }
        }
        if let LightShape::Spot {
            direction,
            outer_angle,
            ..
        } = *self
        {
            let length = DVec3::from(direction.map(f64::from)).length();
            if !(length > 0.0 && length.is_finite()) {
                return Some("direction must be finite and not zero");
            }
            if !(outer_angle > 0.0 && outer_angle < MAX_SPOT_ANGLE) {
                return Some("outer angle must lie between 0 and 80 degrees");
            }
        }
        None
    }

    /// Whether the light can add anything inside `bounds`: its range sphere reaches into the box
    /// (always, for a directional light). Exact culling: a light's falloff is zero at and beyond
    /// its range.
    pub fn reaches(&self, bounds: &Aabb) -> bool {
        self.reach()
            .is_none_or(|(centre, radius)| bounds.reached_by_sphere(centre, radius))
    }

    /// The range sphere: what the light can reach.
    fn reach(&self) -> Option<(DVec3, f64)> {
        match *self {
            LightShape::Point { position, range }
            | LightShape::Spot {
                position, range, ..
            } => Some((DVec3::from(position.map(f64::from)), f64::from(range))),
            LightShape::Directional => None,
        }
    }

    /// The sphere (centre, radius) that holds the volume mesh histencil draws for the light:
    /// what the planner culls by and takes its screen rectangle from
    /// ([`PlannedLight::screen_rect`](crate::PlannedLight::screen_rect)). `None` for a
    /// directional light, which is drawn full-screen.
    pub fn volume_sphere(&self) -> Option<([f64; 3], f64)> {
        self.volume_bound()
            .map(|(centre, radius)| (centre.into(), radius))
    }

    /// A sphere containing the volume mesh histencil draws for the light.
    pub(crate) fn volume_bound(&self) -> Option<(DVec3, f64)> {
        match *self {
            LightShape::Point { position, range } => Some((
                DVec3::from(position.map(f64::from)),
                f64::from(range) * VOLUME_OVERSHOOT,
            )),
            LightShape::Spot {
                position,
                direction,
                range,
                outer_angle,
            } => {
                // The cone is the hull of its apex and its cap disc (radius rho at height h):
                // the smallest sphere holding both.
                let h = f64::from(range) * VOLUME_OVERSHOOT;
                let rho = h * f64::from(outer_angle).tan();
                let axis = DVec3::from(direction.map(f64::from)).normalize();
                let apex = DVec3::from(position.map(f64::from));
                let (along, radius) = if rho >= h {
                    (h, rho)
                } else {
                    let z = (h * h + rho * rho) / (2.0 * h);
                    (z, z)
                };
                Some((apex + axis * along, radius))
            }
            LightShape::Directional => None,
        }
    }
}

/// What [`crate::plan_frame`] made a plan for: the view, every light's shape in input order, and the
/// stencil layout. A plan's passes, volumes and light cases are right for these only: a plan
/// made before the camera moved or a light was added, recorded with the new view, lit the frame
/// wrong without any error. The lighting compares every frame with this
/// ([`PlannedFor::difference`]) and refuses one that differs.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedFor {
    /// The view's matrices and depth convention.
    pub view: ViewDesc,
    /// Every light's shape, in the order of [`crate::PlanInputs::lights`].
    pub lights: Vec<LightShape>,
    /// The stencil layout the passes' masks and references come from.
    pub layout: StencilLayout,
}

impl PlannedFor {
    /// The first way a frame's view, lights or layout differ from what the plan was made for,
    /// in words; `None` when they are the same bit for bit. Costs a comparison per matrix
    /// element and per light: nothing next to recording the frame.
    pub fn difference(
        &self,
        view: &ViewDesc,
        lights: impl ExactSizeIterator<Item = LightShape>,
        layout: &StencilLayout,
    ) -> Option<String> {
        let replan = "plan again with the frame's view and lights";
        if *layout != self.layout {
            return Some(format!(
                "the plan was made for stencil layout {:?}, the lighting has {layout:?}",
                self.layout
            ));
        }
        if view.depth != self.view.depth {
            return Some(format!(
                "the plan was made for {:?} depth, the frame's view is {:?}",
                self.view.depth, view.depth
            ));
        }
        if view.world_to_view != self.view.world_to_view {
            return Some(format!(
                "the plan was made for another camera position or orientation (its \
                 world-to-view matrix differs): {replan}"
            ));
        }
        if view.view_to_clip != self.view.view_to_clip {
            return Some(format!(
                "the plan was made for another projection (its view-to-clip matrix differs): \
                 {replan}"
            ));
        }
        if lights.len() != self.lights.len() {
            return Some(format!(
                "the plan was made for {} lights, the frame has {}: {replan}",
                self.lights.len(),
                lights.len()
            ));
        }
        for (index, (light, planned)) in lights.zip(&self.lights).enumerate() {
            if light != *planned {
                return Some(format!(
                    "light {index} moved or changed shape since the plan was made \
                     ({light:?}, planned as {planned:?}): {replan}"
                ));
            }
        }
        None
    }
}
