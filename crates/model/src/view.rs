//! The view a frame is rendered with, as plain data: the engine's own matrices and depth
//! convention, standard or reversed Z, finite or infinite far plane.
//!
//! The planner asks the view three things, all in f64 so that a far plane at infinity or a near
//! plane a millimetre from the eye costs no precision: where the near-plane rectangle lies (every
//! pixel's ray starts on it, which decides how a light volume must be drawn), which spheres the
//! frustum cannot see, and how much of the screen a sphere covers.

use crate::state::CompareOp;
use glam::{DMat4, DVec3, DVec4, Mat4};

/// Which end of the depth range is near.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum DepthConvention {
    /// Depth 0 at the near plane, 1 at the far plane; the depth buffer clears to 1.
    #[default]
    Standard,
    /// Depth 1 at the near plane, 0 at the far plane (or at infinity); the depth buffer clears
    /// to 0. Floating-point depth keeps its precision far away.
    Reversed,
}

impl DepthConvention {
    /// The depth of the near plane.
    pub fn near(self) -> f32 {
        match self {
            Self::Standard => 0.0,
            Self::Reversed => 1.0,
        }
    }

    /// The depth of the far plane: where the sky is and where full-screen passes are drawn.
    pub fn far(self) -> f32 {
        1.0 - self.near()
    }

    /// `op`, written for standard depth (`Less` means nearer), as this convention spells it.
    pub fn orient(self, op: CompareOp) -> CompareOp {
        match (self, op) {
            (Self::Standard, op) => op,
            (Self::Reversed, CompareOp::Less) => CompareOp::Greater,
            (Self::Reversed, CompareOp::LessOrEqual) => CompareOp::GreaterOrEqual,
            (Self::Reversed, CompareOp::Greater) => CompareOp::Less,
            (Self::Reversed, CompareOp::GreaterOrEqual) => CompareOp::LessOrEqual,
            (Self::Reversed, op) => op,
        }
    }

    /// Whether depth `a` lies strictly nearer the eye than depth `b`.
    pub fn nearer(self, a: f32, b: f32) -> bool {
        self.orient(CompareOp::Less).test(a, b)
    }
}

/// Where the far plane of a [`Perspective`] lies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FarPlane {
    /// A far plane at this view-space distance.
    Finite(f32),
    /// No far plane: depth tends to the far value at infinity.
    Infinite,
}

/// A right-handed perspective camera (looking down -Z in view space, Vulkan clip space with y
/// down), for callers without matrices of their own.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Perspective {
    /// World position of the camera.
    pub eye: [f32; 3],
    /// World point the camera looks at.
    pub target: [f32; 3],
    /// World direction that is up on screen.
    pub up: [f32; 3],
    /// Vertical field of view, radians.
    pub fov_y_radians: f32,
    /// Width over height of the viewport.
    pub aspect: f32,
    /// Distance to the near plane, above 0.
    pub near: f32,
    /// Where the far plane lies.
    pub far: FarPlane,
    /// Which end of depth is near.
    pub depth: DepthConvention,
}

impl Perspective {
    /// The view's matrices.
    pub fn desc(&self) -> ViewDesc {
        let view = glam::camera::rh::view::look_at_mat4(
            self.eye.into(),
            self.target.into(),
            self.up.into(),
        );
        let f = 1.0 / (0.5 * self.fov_y_radians).tan();
        let n = self.near;
        // Clip z for view-space z (negative in front), w = -z: depth = z_clip / w.
        let (z_scale, z_offset) = match (self.depth, self.far) {
            (DepthConvention::Standard, FarPlane::Finite(far)) => {
                (far / (n - far), n * far / (n - far))
            }
            (DepthConvention::Standard, FarPlane::Infinite) => (-1.0, -n),
            (DepthConvention::Reversed, FarPlane::Finite(far)) => {
                (n / (far - n), n * far / (far - n))
            }
            (DepthConvention::Reversed, FarPlane::Infinite) => (0.0, n),
        };
        let projection = Mat4::from_cols_array_2d(&[
            [f / self.aspect, 0.0, 0.0, 0.0],
            [0.0, -f, 0.0, 0.0],
            [0.0, 0.0, z_scale, -1.0],
            [0.0, 0.0, z_offset, 0.0],
        ]);
        ViewDesc {
            world_to_view: view.to_cols_array_2d(),
            view_to_clip: projection.to_cols_array_2d(),
            depth: self.depth,
        }
    }
}

/// An engine's view: column-major matrices (`m[column][row]`, glam's `to_cols_array_2d`) into
/// Vulkan clip space (depth in `[0, w]`), and which end of depth is near.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewDesc {
    /// World to view space: the camera's transform inverted.
    pub world_to_view: [[f32; 4]; 4],
    /// View to Vulkan clip space: the projection.
    pub view_to_clip: [[f32; 4]; 4],
    /// Which end of depth is near, as the projection maps it.
    pub depth: DepthConvention,
}

/// A view that cannot be planned with.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ViewError {
    /// A matrix holds NaN or an infinity; the name says which.
    #[error("the view's {0} matrix has an element that is not finite")]
    NotFinite(&'static str),
    /// The two matrices multiply to a matrix without an inverse.
    #[error(
        "the view's world-to-clip matrix is singular: it does not map the world onto the screen"
    )]
    Singular,
    /// The near plane's corners do not unproject to a finite rectangle of positive area.
    #[error("the view's near plane does not map to a finite rectangle in the world")]
    DegenerateNearPlane,
}

/// A checked view, with what the planner derives from it.
#[derive(Clone, Debug, PartialEq)]
pub struct View {
    world_to_clip: DMat4,
    clip_to_world: DMat4,
    depth: DepthConvention,
    /// The near-plane rectangle's corners, counter-clockwise on screen from (-1, -1).
    near_corners: [DVec3; 4],
    infinite_far: bool,
    /// The matrices it was made from: what a plan records it was made for.
    desc: ViewDesc,
}

impl View {
    /// Checks the engine's matrices and derives what the planner classifies lights against:
    /// the near-plane rectangle in the world, and whether the far plane lies at infinity.
    ///
    /// # Errors
    /// [`ViewError`] when the matrices are not finite, are singular, or map no near plane.
    pub fn new(desc: &ViewDesc) -> Result<Self, ViewError> {
        let matrix = |m: &[[f32; 4]; 4], name| {
            if m.iter().flatten().all(|v| v.is_finite()) {
                Ok(Mat4::from_cols_array_2d(m).as_dmat4())
            } else {
                Err(ViewError::NotFinite(name))
            }
        };
        let world_to_clip = matrix(&desc.view_to_clip, "view-to-clip")?
            * matrix(&desc.world_to_view, "world-to-view")?;
        let det = world_to_clip.determinant();
        if !det.is_finite() || det == 0.0 {
            return Err(ViewError::Singular);
        }
        let clip_to_world = world_to_clip.inverse();
        if !clip_to_world.is_finite() {
            return Err(ViewError::Singular);
        }
        let near = f64::from(desc.depth.near());
        let unproject = |x: f64, y: f64, z: f64| -> Option<DVec3> {
            let p = clip_to_world * DVec4::new(x, y, z, 1.0);
            let point = p.truncate() / p.w;
            (p.w != 0.0 && point.is_finite()).then_some(point)
        };
        let mut near_corners = [DVec3::ZERO; 4];
        for (corner, (x, y)) in
            near_corners
                .iter_mut()
                .zip([(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)])
        {
            *corner = unproject(x, y, near).ok_or(ViewError::DegenerateNearPlane)?;
        }
        let area = (near_corners[1] - near_corners[0])
            .cross(near_corners[3] - near_corners[0])
            .length();
        if area.is_nan() || area <= 0.0 {
            return Err(ViewError::DegenerateNearPlane);
        }
        let far = clip_to_world * DVec4::new(0.0, 0.0, f64::from(desc.depth.far()), 1.0);
        let infinite_far = far.w.abs() <= 1e-9 * far.truncate().length();
        Ok(Self {
            world_to_clip,
            clip_to_world,
            depth: desc.depth,
            near_corners,
            infinite_far,
            desc: *desc,
        })
    }

    /// The engine's matrices this view was made from.
    pub fn desc(&self) -> &ViewDesc {
        &self.desc
    }

    /// World space to Vulkan clip space: the projection times the view.
    pub(crate) fn world_to_clip(&self) -> DMat4 {
        self.world_to_clip
    }

    /// Which end of depth is near.
    pub fn depth(&self) -> DepthConvention {
        self.depth
    }

    /// Whether the far plane lies at infinity.
    pub fn infinite_far(&self) -> bool {
        self.infinite_far
    }

    /// Normalised device coordinates and depth of a world point, or `None` behind the eye.
    pub fn project(&self, world: [f64; 3]) -> Option<[f64; 3]> {
        let clip = self.world_to_clip * DVec3::from(world).extend(1.0);
        (clip.w > 0.0).then(|| (clip.truncate() / clip.w).into())
    }

    /// The ray through a point of the screen (normalised device coordinates): its origin on the
    /// near plane and a direction away from the eye (not normalised).
    pub fn ray(&self, ndc: [f64; 2]) -> ([f64; 3], [f64; 3]) {
        let near = f64::from(self.depth.near());
        // Half way to the far plane in depth, which is finite even for an infinite far plane.
        let between = 0.5;
        let at = |z: f64| {
            let p = self.clip_to_world * DVec4::new(ndc[0], ndc[1], z, 1.0);
            p.truncate() / p.w
        };
        let origin = at(near);
        (origin.into(), (at(between) - origin).into())
    }

    /// Distance from `point` to the near-plane rectangle.
    pub(crate) fn distance_to_near_plane(&self, point: DVec3) -> f64 {
        let c = &self.near_corners;
        let normal = (c[1] - c[0]).cross(c[3] - c[0]).normalize();
        let on_plane = point - normal * normal.dot(point - c[0]);
        // The corners wind counter-clockwise about `normal`, which they define.
        let inside = (0..4).all(|i| {
            let (a, b) = (c[i], c[(i + 1) % 4]);
            (b - a).cross(on_plane - a).dot(normal) >= 0.0
        });
        if inside {
            return (point - on_plane).length();
        }
        (0..4)
            .map(|i| {
                let (a, b) = (c[i], c[(i + 1) % 4]);
                let t = ((point - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
                (point - (a + (b - a) * t)).length()
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Whether every corner of the near-plane rectangle lies strictly inside the sphere, so
    /// every pixel's ray starts inside it.
    pub(crate) fn near_plane_inside(&self, centre: DVec3, radius: f64) -> bool {
        self.near_corners
            .iter()
            .all(|c| (*c - centre).length() < radius)
    }

    /// Whether the sphere lies wholly outside one plane of the frustum (the far plane's
    /// equation degenerates to a constant for an infinite far plane and culls nothing).
    pub(crate) fn culls_sphere(&self, centre: DVec3, radius: f64) -> bool {
        let m = self.world_to_clip;
        let (x, y, z, w) = (m.row(0), m.row(1), m.row(2), m.row(3));
        [w + x, w - x, w + y, w - y, z, w - z].iter().any(|plane| {
            let normal = plane.truncate();
            normal.dot(centre) + plane.w < -radius * normal.length()
        })
    }

    /// The exact screen bounding rectangle of a sphere in normalised device coordinates (not
    /// clipped to the screen); `None` when the sphere reaches the eye plane, where its
    /// projection is unbounded. Every point of the sphere projects inside it, so it bounds
    /// whatever a volume inside the sphere rasterises, near-plane clipping or not.
    pub(crate) fn sphere_rect(&self, centre: DVec3, radius: f64) -> Option<NdcRect> {
        let m = self.world_to_clip;
        let w = m.row(3);
        let centre4 = centre.extend(1.0);
        let extent = |row: DVec4| -> Option<[f64; 2]> {
            // The planes through the sphere's tangents where clip row / w = t: solve
            // (u - t v)^2 = r^2 |a - t b|^2 for t.
            let (a, b) = (row.truncate(), w.truncate());
            let (u, v) = (row.dot(centre4), w.dot(centre4));
            let r2 = radius * radius;
            let qa = v * v - r2 * b.length_squared();
            if v <= 0.0 || qa <= 0.0 {
                return None;
            }
            let qb = u * v - r2 * a.dot(b);
            let qc = u * u - r2 * a.length_squared();
            let root = (qb * qb - qa * qc).max(0.0).sqrt();
            Some([(qb - root) / qa, (qb + root) / qa])
        };
        let x = extent(m.row(0))?;
        let y = extent(m.row(1))?;
        Some(NdcRect {
            min: [x[0], y[0]],
            max: [x[1], y[1]],
        })
    }

    /// The fraction of the screen a sphere covers: the ellipse inscribed in its exact screen
    /// bounding rectangle, clipped to the screen; 1 when the sphere reaches the eye plane.
    pub(crate) fn sphere_coverage(&self, centre: DVec3, radius: f64) -> f64 {
        let Some(rect) = self.sphere_rect(centre, radius) else {
            return 1.0;
        };
        let clipped = |axis: usize| (rect.max[axis].min(1.0) - rect.min[axis].max(-1.0)).max(0.0);
        (std::f64::consts::FRAC_PI_4 * clipped(0) * clipped(1) / 4.0).min(1.0)
    }
}

/// A rectangle in normalised device coordinates: x from -1 (left) to 1 (right), y from -1 (the
/// framebuffer's first row) to 1, as Vulkan's viewport maps them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NdcRect {
    /// The corner with the smallest x and y: left, towards the first row.
    pub min: [f64; 2],
    /// The corner with the largest x and y: right, towards the last row.
    pub max: [f64; 2],
}

/// Depth-buffer values `[min, max]` (in `[0, 1]`, the frame's convention) that hold every point
/// of a light's bounding sphere the view can see.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DepthRange {
    /// The smallest depth value, whichever end of depth is near.
    pub min: f32,
    /// The largest.
    pub max: f32,
}

impl DepthRange {
    /// Whether a stored depth passes the test (`min <= d <= max`, as Vulkan's test keeps it).
    pub fn contains(&self, depth: f32) -> bool {
        self.min <= depth && depth <= self.max
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Looking down -Z from z = 5, 1 radian high, 1.5 wide over high, near plane at 0.1.
    pub(crate) fn perspective(depth: DepthConvention, far: FarPlane) -> Perspective {
        Perspective {
            eye: [0.0, 0.0, 5.0],
            target: [0.0; 3],
            up: [0.0, 1.0, 0.0],
            fov_y_radians: 1.0,
            aspect: 1.5,
            near: 0.1,
            far,
            depth,
        }
    }

    pub(crate) fn camera(depth: DepthConvention, far: FarPlane) -> View {
        View::new(&perspective(depth, far).desc()).unwrap()
    }

    pub(crate) const CONVENTIONS: [(DepthConvention, FarPlane); 4] = [
        (DepthConvention::Standard, FarPlane::Finite(100.0)),
        (DepthConvention::Standard, FarPlane::Infinite),
        (DepthConvention::Reversed, FarPlane::Finite(100.0)),
        (DepthConvention::Reversed, FarPlane::Infinite),
    ];

    #[test]
    fn depth_runs_from_near_to_far_in_every_convention() {
        for (depth, far) in CONVENTIONS {
            let view = camera(depth, far);
            assert_eq!(view.infinite_far(), far == FarPlane::Infinite);
            let near = view.project([0.0, 0.0, 4.9]).unwrap()[2];
            assert!(
                (near - f64::from(depth.near())).abs() < 1e-6,
                "{depth:?} {near}"
            );
            let a = view.project([0.0, 0.0, 0.0]).unwrap()[2] as f32;
            let b = view.project([0.0, 0.0, -50.0]).unwrap()[2] as f32;
            assert!(depth.nearer(a, b), "{depth:?} {far:?}: {a} {b}");
            if let FarPlane::Finite(f) = far {
                let at_far = view.project([0.0, 0.0, 5.0 - f64::from(f)]).unwrap()[2];
                assert!((at_far - f64::from(depth.far())).abs() < 1e-6, "{at_far}");
            }
            assert!(view.project([0.0, 0.0, 6.0]).is_none(), "behind the eye");
        }
    }

    #[test]
    fn rays_start_on_the_near_plane_and_point_away_from_the_eye() {
        for (depth, far) in CONVENTIONS {
            let view = camera(depth, far);
            let (origin, direction) = view.ray([0.0, 0.0]);
            assert!((origin[2] - 4.9).abs() < 1e-6, "{origin:?}");
            assert!(direction[2] < 0.0);
            let (corner, _) = view.ray([1.0, -1.0]);
            // Vulkan's y is down: the top right corner of the screen.
            assert!(corner[0] > 0.0 && corner[1] > 0.0, "{corner:?}");
        }
    }

    /// Every point of a sphere in front of the eye plane projects inside its rectangle, and
    /// each side of the rectangle is reached (it is the tight bound); a sphere reaching the eye
    /// plane has none.
    #[test]
    fn sphere_rectangles_hold_the_sphere_tightly() {
        for (depth, far) in CONVENTIONS {
            let view = camera(depth, far);
            let cases = [
                (DVec3::new(0.0, 0.0, -5.0), 1.0),
                (DVec3::new(3.0, -1.0, 2.0), 2.5),
                // Crosses the near plane (z = 4.9) but not the eye plane (z = 5).
                (DVec3::new(0.2, 0.1, 4.0), 0.95),
                (DVec3::new(-8.0, 6.0, -30.0), 4.0),
            ];
            for (centre, radius) in cases {
                let rect = view
                    .sphere_rect(centre, radius)
                    .expect("in front of the eye");
                let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
                for i in 0..200 {
                    for j in 0..=100 {
                        let (theta, phi) = (i as f64 * 0.031_415_9, j as f64 * 0.031_415_9);
                        let dir =
                            DVec3::new(phi.sin() * theta.cos(), phi.sin() * theta.sin(), phi.cos());
                        let clip = view.world_to_clip * (centre + dir * radius).extend(1.0);
                        let ndc = [clip.x / clip.w, clip.y / clip.w];
                        for a in 0..2 {
                            let slack = 1e-9 * (1.0 + ndc[a].abs());
                            assert!(ndc[a] >= rect.min[a] - slack && ndc[a] <= rect.max[a] + slack);
                            lo[a] = lo[a].min(ndc[a]);
                            hi[a] = hi[a].max(ndc[a]);
                        }
                    }
                }
                for a in 0..2 {
                    let size = rect.max[a] - rect.min[a];
                    assert!(lo[a] - rect.min[a] < 0.01 * size, "{centre} axis {a}");
                    assert!(rect.max[a] - hi[a] < 0.01 * size, "{centre} axis {a}");
                }
            }
            assert!(view.sphere_rect(DVec3::new(0.0, 0.0, 4.5), 0.6).is_none());
        }
    }

    #[test]
    fn culling_and_coverage_agree_with_the_frustum() {
        for (depth, far) in CONVENTIONS {
            let view = camera(depth, far);
            let ahead = DVec3::new(0.0, 0.0, -5.0);
            assert!(!view.culls_sphere(ahead, 1.0));
            assert!(view.culls_sphere(DVec3::new(0.0, 0.0, 7.0), 1.0), "behind");
            assert!(view.culls_sphere(DVec3::new(40.0, 0.0, -5.0), 1.0), "right");
            let beyond_far = DVec3::new(0.0, 0.0, -500.0);
            assert_eq!(
                view.culls_sphere(beyond_far, 1.0),
                far != FarPlane::Infinite
            );
            let near = view.sphere_coverage(DVec3::new(0.0, 0.0, 2.0), 0.5);
            let far_away = view.sphere_coverage(ahead, 0.5);
            assert!(far_away < near && far_away > 0.0, "{near} {far_away}");
            // Radius 0.5 at distance 10, fov 1 rad: half-height tan(0.5) * 10 = 5.46.
            let expected = std::f64::consts::PI * 0.5 * 0.5 / (4.0 * 1.5 * 5.4630 * 5.4630);
            assert!(
                (far_away / expected - 1.0).abs() < 0.01,
                "{far_away} {expected}"
            );
            assert_eq!(view.sphere_coverage(DVec3::new(0.0, 0.0, 5.0), 1.0), 1.0);
            // Centred on the screen's right edge: half of it is clipped, and perspective
            // stretches the rest (the ellipse grows off-axis by about 1 / cos^2 across).
            let half_off = view.sphere_coverage(DVec3::new(5.4630 * 1.5, 0.0, -5.0), 0.5);
            let ratio = half_off / far_away;
            assert!(ratio > 0.55 && ratio < 0.7, "{ratio}");
        }
    }

    #[test]
    fn near_plane_distance_is_to_the_rectangle_not_its_plane() {
        let view = camera(DepthConvention::Standard, FarPlane::Finite(100.0));
        assert!(view.distance_to_near_plane(DVec3::new(0.0, 0.0, 4.9)) < 1e-6);
        assert!((view.distance_to_near_plane(DVec3::new(0.0, 0.0, 3.9)) - 1.0).abs() < 1e-6);
        // Beside the rectangle, in its plane: the distance to its edge.
        let half_width = 0.1 * (0.5f64).tan() * 1.5;
        let d = view.distance_to_near_plane(DVec3::new(half_width + 2.0, 0.0, 4.9));
        assert!((d - 2.0).abs() < 1e-6, "{d}");
        assert!(view.near_plane_inside(DVec3::new(0.0, 0.0, 4.9), 0.2));
        assert!(!view.near_plane_inside(DVec3::new(0.0, 0.0, 4.9), 0.05));
    }

    #[test]
    fn broken_matrices_are_errors() {
        let mut desc = perspective(DepthConvention::Reversed, FarPlane::Infinite).desc();
        desc.world_to_view[3][0] = f32::NAN;
        assert_eq!(View::new(&desc), Err(ViewError::NotFinite("world-to-view")));
        desc.world_to_view = [[0.0; 4]; 4];
        assert_eq!(View::new(&desc), Err(ViewError::Singular));
    }

    #[test]
    fn orient_mirrors_ordering_only() {
        let r = DepthConvention::Reversed;
        assert_eq!(r.orient(CompareOp::Less), CompareOp::Greater);
        assert_eq!(r.orient(CompareOp::GreaterOrEqual), CompareOp::LessOrEqual);
        assert_eq!(r.orient(CompareOp::Equal), CompareOp::Equal);
        assert!(r.nearer(0.9, 0.1) && !r.nearer(0.1, 0.9) && !r.nearer(0.5, 0.5));
        assert_eq!((r.near(), r.far()), (1.0, 0.0));
    }
}
