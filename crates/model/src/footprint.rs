//! What a light volume covers on screen: per pixel, the depths of its front and back faces.
//!
//! A convex volume crosses each pixel's ray at most once, so one [`Span`] per pixel describes it
//! completely. The simulator takes footprints as input; [`Footprint::ellipsoid`] rasterises one
//! analytically, and any other convex volume can be given through [`Footprint::from_fn`].

use crate::plan::LightCase;
use crate::view::DepthConvention;

/// Where a volume crosses one pixel's ray, in depth-buffer units of the footprint's
/// [`DepthConvention`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Span {
    /// `None` when the near plane clips the front face (viewer inside, or near crossing).
    pub front: Option<f32>,
    /// Clamped to the far depth (volume pipelines clamp depth).
    pub back: f32,
}

impl Span {
    /// The definition of "surface inside the light": strictly between the faces, nearer than
    /// the back face and farther than the front one. Sky (the far depth) is never inside.
    pub fn contains(&self, depth: DepthConvention, surface_depth: f32) -> bool {
        self.front.is_none_or(|f| depth.nearer(f, surface_depth))
            && depth.nearer(surface_depth, self.back)
    }
}

/// A light's coverage: a rectangle of the frame and one optional span per pixel in it.
#[derive(Clone, Debug, PartialEq)]
pub struct Footprint {
    /// Left edge of the rectangle, in pixels.
    pub x0: u32,
    /// Top edge of the rectangle, in pixels.
    pub y0: u32,
    /// Width of the rectangle, in pixels.
    pub width: u32,
    /// Height of the rectangle, in pixels.
    pub height: u32,
    spans: Vec<Option<Span>>,
    full_screen: bool,
    depth: DepthConvention,
}

impl Footprint {
    /// Spans (standard depth) from a function of the pixel, over
    /// `[x0, x0 + width) x [y0, y0 + height)`.
    pub fn from_fn(rect: (u32, u32, u32, u32), span: impl Fn(u32, u32) -> Option<Span>) -> Self {
        Self::from_fn_in(DepthConvention::Standard, rect, span)
    }

    /// Spans in `depth`'s convention from a function of the pixel.
    pub fn from_fn_in(
        depth: DepthConvention,
        (x0, y0, width, height): (u32, u32, u32, u32),
        span: impl Fn(u32, u32) -> Option<Span>,
    ) -> Self {
        let mut spans = Vec::with_capacity((width * height) as usize);
        for y in y0..y0 + height {
            for x in x0..x0 + width {
                spans.push(span(x, y));
            }
        }
        Self {
            x0,
            y0,
            width,
            height,
            spans,
            full_screen: false,
            depth,
        }
    }

    /// The same footprint in `depth`'s convention: standard depths as they are, reversed ones
    /// as `1 - d`, which is exact for the depths tests build (multiples of a power of two).
    pub fn in_convention(mut self, depth: DepthConvention) -> Self {
        if depth != self.depth {
            for span in self.spans.iter_mut().flatten() {
                span.front = span.front.map(|f| 1.0 - f);
                span.back = 1.0 - span.back;
            }
            self.depth = depth;
        }
        self
    }

    /// Spans of any function in the footprint's convention, e.g. to quantise depths.
    pub fn map_depths(mut self, f: impl Fn(f32) -> f32) -> Self {
        for span in self.spans.iter_mut().flatten() {
            span.front = span.front.map(&f);
            span.back = f(span.back);
        }
        self
    }

    /// The depth convention the spans are in.
    pub fn depth(&self) -> DepthConvention {
        self.depth
    }

    /// A light without a volume: the full-screen triangle at depth 1.
    pub fn full_screen(width: u32, height: u32) -> Self {
        Self {
            full_screen: true,
            ..Self::from_fn((0, 0, width, height), |_, _| {
                Some(Span {
                    front: None,
                    back: 1.0,
                })
            })
        }
    }

    /// An ellipsoid seen orthographically: a disc of `radius_px` around `center` (pixels) and a
    /// depth extent of `depth_radius` around `center_depth`. Parts before the near plane are
    /// clipped (front `None`), parts beyond the far plane clamped.
    pub fn ellipsoid(
        frame: (u32, u32),
        center: (f32, f32),
        radius_px: f32,
        center_depth: f32,
        depth_radius: f32,
    ) -> Self {
        let lo = |c: f32| (c - radius_px).floor().max(0.0) as u32;
        let hi = |c: f32, size: u32| ((c + radius_px).ceil().max(0.0) as u32).min(size);
        let (x0, y0) = (lo(center.0).min(frame.0), lo(center.1).min(frame.1));
        let (x1, y1) = (hi(center.0, frame.0), hi(center.1, frame.1));
        Self::from_fn((x0, y0, x1 - x0, y1 - y0), |x, y| {
            let dx = (x as f32 + 0.5 - center.0) / radius_px;
            let dy = (y as f32 + 0.5 - center.1) / radius_px;
            let r2 = dx * dx + dy * dy;
            if r2 >= 1.0 {
                return None;
            }
            let half = depth_radius * (1.0 - r2).sqrt();
            let (front, back) = (center_depth - half, center_depth + half);
            (back > 0.0).then_some(Span {
                front: (front >= 0.0).then_some(front),
                back: back.min(1.0),
            })
        })
    }

    /// Where the volume crosses pixel (x, y)'s ray; `None` outside the rectangle or the volume.
    pub fn span(&self, x: u32, y: u32) -> Option<Span> {
        if x < self.x0 || y < self.y0 || x >= self.x0 + self.width || y >= self.y0 + self.height {
            return None;
        }
        self.spans[((y - self.y0) * self.width + (x - self.x0)) as usize]
    }

    /// Whether the light shades a surface at `surface_depth` in pixel (x, y): strictly between
    /// its faces, or, for a viewer inside the volume ([`LightCase::ViewerInside`]), any surface
    /// in the footprint: the plan draws that light full-screen (see `shade_raster`), and the
    /// light's window gives exactly 0 beyond its range, so the shading count, not the light,
    /// grows by the surfaces behind the back face. Classifies the footprint on every call
    /// (linear in its size): an oracle for tests, not a per-pixel query for large frames.
    pub fn shades(&self, x: u32, y: u32, surface_depth: f32) -> bool {
        let Some(span) = self.span(x, y) else {
            return false;
        };
        if self.case() == LightCase::ViewerInside {
            self.depth.nearer(surface_depth, self.depth.far())
        } else {
            span.contains(self.depth, surface_depth)
        }
    }

    /// Which plan this footprint needs.
    pub fn case(&self) -> LightCase {
        if self.full_screen {
            LightCase::FullScreen
        } else if self.spans.iter().flatten().all(|s| s.front.is_some()) {
            LightCase::Outside
        } else if self.spans.iter().flatten().any(|s| s.front.is_some()) {
            LightCase::CrossesNear
        } else {
            LightCase::ViewerInside
        }
    }

    /// Whether the light has no volume (drawn as the full-screen triangle).
    pub fn is_full_screen(&self) -> bool {
        self.full_screen
    }

    /// Pixels with a span.
    pub fn covered_pixels(&self) -> usize {
        self.spans.iter().flatten().count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ellipsoid_cut_by_the_near_plane_is_an_inside_case() {
        let near = Footprint::ellipsoid((32, 32), (16.0, 16.0), 8.0, 0.1, 0.3);
        assert_eq!(near.case(), LightCase::CrossesNear);
        let around = Footprint::ellipsoid((32, 32), (16.0, 16.0), 64.0, 0.1, 0.5);
        assert_eq!(around.case(), LightCase::ViewerInside);
        let far = Footprint::ellipsoid((32, 32), (16.0, 16.0), 8.0, 0.9, 0.3);
        assert_eq!(far.case(), LightCase::Outside);
        assert_eq!(far.span(16, 16).unwrap().back, 1.0);
        assert!(far.span(0, 0).is_none());
    }

    #[test]
    fn ellipsoid_off_screen_is_empty() {
        let f = Footprint::ellipsoid((32, 32), (-40.0, 10.0), 8.0, 0.5, 0.1);
        assert_eq!(f.covered_pixels(), 0);
    }

    #[test]
    fn span_contains_is_strict() {
        let s = Span {
            front: Some(0.2),
            back: 0.6,
        };
        let standard = DepthConvention::Standard;
        assert!(s.contains(standard, 0.4));
        assert!(!s.contains(standard, 0.2) && !s.contains(standard, 0.6));
        let sky = Span {
            front: None,
            back: 1.0,
        };
        assert!(!sky.contains(standard, 1.0));
        let reversed = Span {
            front: Some(0.8),
            back: 0.4,
        };
        let r = DepthConvention::Reversed;
        assert!(reversed.contains(r, 0.6) && !reversed.contains(r, 0.8));
        assert!(!reversed.contains(r, 0.4) && !reversed.contains(r, 0.2));
    }
}
