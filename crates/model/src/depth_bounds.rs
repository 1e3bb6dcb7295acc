//! The depth bounds test as a light's culling: the depth-buffer values a light's volume can
//! reach, for the device's depth bounds test (`VkPhysicalDeviceFeatures::depthBounds`), which
//! discards a fragment whose *stored* depth lies outside a range before any stencil or shading
//! work. A light contributes nothing beyond its range, so a shade pass confined to the depth
//! range of its bounding sphere loses nothing, and skips every pixel in the volume's screen
//! footprint whose surface lies far in front of or behind the light: the ones a plain
//! depth-culled volume or a full-screen pass would otherwise shade for nothing.
//!
//! The range is computed from the view's projection, not assumed: with clip depth an affine
//! function of clip w (every perspective and orthographic projection, standard, reversed or
//! infinite), depth = a + b / w is monotonic in w, and w is affine over the sphere, so the
//! sphere's extreme depths lie at its extreme w. A projection whose depth depends on screen
//! position as well (an oblique near plane) gets no range and the light takes the path without
//! the test.

use crate::frame::{FramePlan, Step};
use crate::plan::PassKind;
use crate::view::View;
use glam::DVec3;

pub use crate::view::DepthRange;

/// How much the sphere is grown before its range is taken: the stored depth of a surface point
/// and the position its lighting is computed at come from the same interpolation, but round
/// differently (D24's 24 bits, float division), and a light's contribution only falls to zero at
/// its range, so a surface just inside must not be cut. Relative to the radius.
const RADIUS_MARGIN: f64 = 1e-3;

/// Widening of the range itself, in depth-buffer units: more than D24's step (2^-24) and f32's
/// rounding of values near 1.
const DEPTH_MARGIN: f64 = 1.0 / (1u64 << 20) as f64;

/// The depth range of the sphere (`centre`, `radius`, world space) seen by `view`; `None` when the
/// sphere lies wholly behind the eye, or the projection's depth is not a function of w alone.
pub fn sphere_depth_range(view: &View, centre: [f64; 3], radius: f64) -> Option<DepthRange> {
    let m = view.world_to_clip();
    let (z_row, w_row) = (m.row(2), m.row(3));
    let c = DVec3::from(centre).extend(1.0);
    let r = radius * (1.0 + RADIUS_MARGIN) + f64::EPSILON;
    let (zc, wc) = (z_row.dot(c), w_row.dot(c));
    let (zn, wn) = (z_row.truncate(), w_row.truncate());
    let (lo, hi) = if wn.length() <= 1e-12 * z_row.length() {
        // Orthographic: w is constant and depth affine over the sphere.
        if wc <= 0.0 {
            return None;
        }
        let reach = r * zn.length();
        ((zc - reach) / wc, (zc + reach) / wc)
    } else {
        // Clip z = a w + b: depth = a + b / w; z's direction must be w's.
        let a = zn.dot(wn) / wn.length_squared();
        if (zn - a * wn).length() > 1e-9 * zn.length().max(wn.length()) {
            return None;
        }
        let b = z_row.w - a * w_row.w;
        let depth_at = |w: f64| a + b / w;
        let reach = r * wn.length();
        let (w_lo, w_hi) = (wc - reach, wc + reach);
        if w_hi <= 0.0 {
            return None;
        }
        // A sphere reaching the eye plane is seen from the near plane on.
        let near = f64::from(view.depth().near());
        let first = if w_lo > 0.0 { depth_at(w_lo) } else { near };
        let last = depth_at(w_hi);
        (first.min(last), first.max(last))
    };
    let clamp = |d: f64| d.clamp(0.0, 1.0) as f32;
    let range = DepthRange {
        min: clamp(lo - DEPTH_MARGIN),
        max: clamp(hi + DEPTH_MARGIN),
    };
    (range.min <= range.max).then_some(range)
}

/// Whether the test can cut anything: a range holding every depth value is no better than no
/// test.
pub fn cuts(range: &DepthRange) -> bool {
    range.min > 0.0 || range.max < 1.0
}

impl FramePlan {
    /// The same plan with every shade pass of a light with a volume confined to the depth range
    /// of its bounding sphere by the device's depth bounds test: for a device with
    /// `depthBounds` enabled. The image does not change (a light adds nothing beyond its range);
    /// the pixels the test rejects are the ones shaded for nothing. Only shade passes: they
    /// write no stencil, so the stencil every other pass leaves, and the hi-stencil it feeds,
    /// stay as the platform's plan has them.
    ///
    /// A plan built from bare requests (no view: [`FramePlan::made_for`] is `None`), a
    /// full-screen light, and a projection without a range ([`sphere_depth_range`]) are left
    /// as they are.
    pub fn with_depth_bounds(self) -> Self {
        let Some(made_for) = self.made_for.as_deref() else {
            return self;
        };
        let Ok(view) = View::new(&made_for.view) else {
            return self;
        };
        let ranges: Vec<Option<DepthRange>> = self
            .lights
            .iter()
            .map(|light| {
                made_for.lights[light.input]
                    .volume_bound()
                    .and_then(|(centre, radius)| sphere_depth_range(&view, centre.into(), radius))
                    .filter(cuts)
            })
            .collect();
        self.confined(&ranges)
    }

    /// The plan with light `i` given `ranges[i]` and its shade passes confined to it.
    fn confined(mut self, ranges: &[Option<DepthRange>]) -> Self {
        for (light, range) in self.lights.iter_mut().zip(ranges) {
            light.depth_range = *range;
        }
        for step in &mut self.steps {
            if let Step::Pass { light, pass } = step {
                if matches!(pass.kind, PassKind::Shade(_))
                    && self.lights[*light].depth_range.is_some()
                {
                    pass.state.depth_bounds = true;
                }
            }
        }
        self
    }

    /// Whether any pass is confined by the depth bounds test: the device must have it enabled.
    pub fn uses_depth_bounds(&self) -> bool {
        self.steps
            .iter()
            .any(|s| matches!(s, Step::Pass { pass, .. } if pass.state.depth_bounds))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::view::tests::{camera as view, perspective, CONVENTIONS};
    use crate::view::{DepthConvention, FarPlane};

    /// Points of the sphere, its surface and inside, on a deterministic spiral.
    fn sphere_points(centre: [f64; 3], radius: f64) -> Vec<[f64; 3]> {
        let n = 4000;
        (0..n)
            .map(|i| {
                let t = (i as f64 + 0.5) / n as f64;
                let z = 1.0 - 2.0 * t;
                let phi = i as f64 * 2.399_963;
                let s = (1.0 - z * z).sqrt() * if i % 3 == 0 { 0.5 } else { 1.0 };
                let k = if i % 3 == 0 { 0.5 } else { 1.0 };
                [
                    centre[0] + radius * s * phi.cos(),
                    centre[1] + radius * s * phi.sin(),
                    centre[2] + radius * z * k,
                ]
            })
            .collect()
    }

    #[test]
    fn every_visible_point_of_the_sphere_is_in_range_and_the_range_is_tight() {
        for (depth, far) in CONVENTIONS {
            let v = view(depth, far);
            for (centre, radius) in [
                ([0.0, 0.0, 0.0], 1.0),
                ([3.0, -1.0, -20.0], 4.0),
                ([0.2, 0.1, 4.5], 1.0), // holds the eye: seen from the near plane on
                ([0.0, 0.0, -60.0], 0.5),
            ] {
                let range = sphere_depth_range(&v, centre, radius).unwrap();
                let depths: Vec<f32> = sphere_points(centre, radius)
                    .iter()
                    .filter_map(|p| v.project(*p))
                    .map(|p| p[2] as f32)
                    .filter(|d| (0.0..=1.0).contains(d))
                    .collect();
                assert!(!depths.is_empty());
                for d in &depths {
                    assert!(
                        range.contains(*d),
                        "{depth:?} {far:?} {centre:?}: {d} not in {range:?}"
                    );
                }
                let seen_min = depths.iter().copied().fold(f32::INFINITY, f32::min);
                let seen_max = depths.iter().copied().fold(f32::NEG_INFINITY, f32::max);
                let slack = 0.02 * (seen_max - seen_min) + 1e-5;
                assert!(
                    range.min >= seen_min - slack && range.max <= seen_max + slack,
                    "{depth:?} {far:?} {centre:?}: {range:?} loose around [{seen_min}, {seen_max}]"
                );
            }
        }
    }

    #[test]
    fn a_sphere_behind_the_eye_has_no_range() {
        for (depth, far) in CONVENTIONS {
            assert_eq!(
                sphere_depth_range(&view(depth, far), [0.0, 0.0, 20.0], 1.0),
                None
            );
        }
    }

    #[test]
    fn an_oblique_projection_takes_the_path_without_the_test() {
        let mut desc = perspective(DepthConvention::Standard, FarPlane::Finite(100.0)).desc();
        // Clip z gains a term in view x: depth then varies across the screen at one distance.
        desc.view_to_clip[0][2] = 0.3;
        let v = View::new(&desc).unwrap();
        assert_eq!(sphere_depth_range(&v, [0.0, 0.0, 0.0], 1.0), None);
    }

    /// On synthetic frames of every platform: confining shade passes to each light's depth
    /// range (here the range its footprint's faces span) leaves the stencil and the hi-stencil
    /// statistics as they were, shades every pixel the light shades inside its range exactly
    /// as before, and rejects only pixels whose surface lies outside it.
    #[test]
    fn the_simulator_rejects_only_surfaces_outside_the_range() {
        use crate::{
            FlushPolicy, FramePlan, Native, PlannedLight, PlatformBackend, Ps3Like, Simulator,
            StencilLayout, SyntheticDesc, SyntheticFrame, X360Like,
        };
        let layout = StencilLayout::new(3, 0).unwrap();
        let x360 = X360Like::default();
        let platforms: [&dyn PlatformBackend; 3] = [&Native, &Ps3Like, &x360];
        let mut rejected = 0;
        for (seed, platform) in platforms.iter().enumerate() {
            let frame = SyntheticFrame::generate(&SyntheticDesc {
                size: 48,
                lights: 12,
                layout,
                preserved: 0,
                radius_px: (4.0, 20.0),
                seed: 7 + seed as u64,
            });
            let lights = PlannedLight::numbered(frame.requests.clone());
            let depth = frame.footprints[0].depth();
            let plan =
                FramePlan::build(&layout, &platform.caps(), depth, lights, FlushPolicy::Auto)
                    .unwrap();
            let ranges: Vec<Option<DepthRange>> = plan
                .lights
                .iter()
                .map(|l| {
                    let f = &frame.footprints[l.input];
                    let spans = (f.y0..f.y0 + f.height)
                        .flat_map(|y| (f.x0..f.x0 + f.width).map(move |x| (x, y)))
                        .filter_map(|(x, y)| f.span(x, y));
                    let (lo, hi) = spans.fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), s| {
                        (lo.min(s.front.unwrap_or(0.0)), hi.max(s.back))
                    });
                    (lo <= hi).then_some(DepthRange { min: lo, max: hi })
                })
                .collect();
            let bounded = plan.clone().confined(&ranges);
            assert!(bounded.uses_depth_bounds());
            let sim = Simulator {
                layout,
                tile_size: 8,
            };
            let (mut a, mut b) = (frame.target.clone(), frame.target.clone());
            let plain = sim.run(&mut a, &plan, &frame.footprints);
            let confined = sim.run(&mut b, &bounded, &frame.footprints);
            assert_eq!(a.stencil, b.stencil, "the stencil every pass leaves");
            assert_eq!(plain.stats.tiles_tested, confined.stats.tiles_tested);
            assert_eq!(plain.stats.tiles_culled, confined.stats.tiles_culled);
            assert_eq!(plain.culling_bit_left, confined.culling_bit_left);
            for (i, light) in plan.lights.iter().enumerate() {
                let f = &frame.footprints[light.input];
                let range = ranges[i].unwrap();
                for (k, (&before, &after)) in plain.lights[i]
                    .count
                    .iter()
                    .zip(&confined.lights[i].count)
                    .enumerate()
                {
                    let (x, y) = (f.x0 + k as u32 % f.width, f.y0 + k as u32 / f.width);
                    let d = frame.target.depth[frame.target.index(x, y)];
                    if range.contains(d) {
                        assert_eq!(before, after, "light {i} at ({x}, {y}) inside its range");
                    } else {
                        assert_eq!(after, 0, "light {i} shaded ({x}, {y}) outside its range");
                    }
                }
            }
            assert_eq!(
                plain.stats.fragments_shaded, confined.stats.fragments_shaded,
                "a footprint's own faces hold no surface outside its range to shade"
            );
            rejected += confined.depth_bounds_rejected;
        }
        assert!(
            rejected > 0,
            "the test rejected nothing: the frames test nothing"
        );
    }

    #[test]
    fn the_range_cuts_unless_it_spans_every_depth() {
        let v = view(DepthConvention::Standard, FarPlane::Finite(100.0));
        let r = sphere_depth_range(&v, [0.0, 0.0, 0.0], 1.0).unwrap();
        assert!(cuts(&r));
        assert!(!cuts(&DepthRange { min: 0.0, max: 1.0 }));
    }
}
