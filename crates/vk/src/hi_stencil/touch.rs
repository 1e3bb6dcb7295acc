//! Which tiles a hi-stencil write touched, planned without a GPU: how each write learns them
//! ([`plan_touches`]), the rectangle of tiles its light can reach ([`tile_rect`]) and the touch
//! image's markers ([`next_marker`]). Pure, so every rule is unit-tested here; the surface that
//! records them is in the parent module.

use crate::shader_consts::HI_STENCIL_TILE;
use ash::vk;
use histencil_model::{CullMode, FramePlan, Geometry, NdcRect, Step};

/// Markers are codes of the 16-bit touch image four apart. Vulkan lets a device store a depth
/// as either neighbouring code of its exact value, so marker `m` is stored as `m - 1`, `m` or
/// `m + 1`, and the update takes a code within one of `m` as `m`'s: no two markers, nor a marker
/// and the cleared image's 0, can then be taken for each other.
const MARKER_STEP: u32 = 4;
const MAX_MARKER: u32 = (u16::MAX as u32 - 1) / MARKER_STEP * MARKER_STEP;

/// The marker after `marker` (0: none yet this frame), and whether the touch image must be
/// cleared whole first: before the frame's first marker, and when they run out and start again.
pub(super) fn next_marker(marker: u32) -> (u32, bool) {
    if marker == 0 || marker >= MAX_MARKER {
        (MARKER_STEP, true)
    } else {
        (marker + MARKER_STEP, false)
    }
}

/// Which tiles a hi-stencil write touched, for its update.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TouchedTiles {
    /// Those its volume rasterises, drawn again into the touch image: a light volume's.
    Drawn,
    /// Those the light's previous write touched: the same volume with the same faces
    /// rasterises the same pixels whatever its depth and stencil tests, so its marker serves
    /// (the talk's mask pass per BRDF of one light).
    Kept,
    /// Every tile: a full-screen draw rasterises every pixel (a console's mask pass has no
    /// fragment shader either).
    All,
}

/// Per step of `plan`, how its hi-stencil write learns its tiles (`None` where the step writes
/// none): a full-screen write touches all; a volume write draws its own unless the light's
/// previous write drew the same volume with the same faces, whose tiles it keeps.
pub fn plan_touches(plan: &FramePlan) -> Vec<Option<TouchedTiles>> {
    let mut touches = vec![None; plan.steps.len()];
    // The light and culled faces of the last volume write since the last full-screen one.
    let mut last: Option<(usize, CullMode)> = None;
    for (index, step) in plan.steps.iter().enumerate() {
        let Step::Pass { light, pass } = step else {
            continue;
        };
        if !pass.state.writes_hi_stencil() {
            continue;
        }
        touches[index] = Some(match pass.geometry {
            Geometry::FullScreen => {
                last = None;
                TouchedTiles::All
            }
            Geometry::Volume => {
                let raster = (*light, pass.state.cull);
                let previous = last.replace(raster);
                if previous == Some(raster) {
                    TouchedTiles::Kept
                } else {
                    TouchedTiles::Drawn
                }
            }
        });
    }
    touches
}

/// The tiles a hi-stencil write touched: how its update learns them, and the rectangle they lie
/// in (the light's on screen, or the frame).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WriteTiles {
    pub touched: TouchedTiles,
    pub rect: TileRect,
}

/// A rectangle of tiles: the first tile's column and row, and the size in tiles.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TileRect {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

impl TileRect {
    /// Every tile of a frame of `extent`.
    pub fn frame(extent: vk::Extent2D) -> Self {
        Self {
            width: extent.width.div_ceil(HI_STENCIL_TILE),
            height: extent.height.div_ceil(HI_STENCIL_TILE),
            ..Self::default()
        }
    }

    pub fn is_empty(self) -> bool {
        self.width == 0 || self.height == 0
    }

    /// Its pixels in a frame of `extent`.
    pub fn pixels(self, extent: vk::Extent2D) -> vk::Rect2D {
        let (x, y) = (self.x * HI_STENCIL_TILE, self.y * HI_STENCIL_TILE);
        let width = (self.width * HI_STENCIL_TILE).min(extent.width.saturating_sub(x));
        let height = (self.height * HI_STENCIL_TILE).min(extent.height.saturating_sub(y));
        vk::Rect2D {
            offset: vk::Offset2D {
                x: x as i32,
                y: y as i32,
            },
            extent: vk::Extent2D { width, height },
        }
    }
}

/// The tiles of a frame of `extent` that hold every pixel inside `ndc` (the whole frame for
/// `None`), with a pixel to spare on each side for the GPU's single-precision transforms.
pub fn tile_rect(extent: vk::Extent2D, ndc: Option<NdcRect>) -> TileRect {
    let frame = TileRect::frame(extent);
    let Some(ndc) = ndc.filter(|r| r.min.iter().chain(&r.max).all(|v| v.is_finite())) else {
        return frame;
    };
    let size = [extent.width, extent.height].map(f64::from);
    let tiles = [frame.width, frame.height];
    let span = |axis: usize| -> (u32, u32) {
        let pixel = |v: f64| (v + 1.0) * 0.5 * size[axis];
        let (lo, hi) = (pixel(ndc.min[axis]) - 1.0, pixel(ndc.max[axis]) + 1.0);
        if !(lo < size[axis] && hi >= 0.0) {
            return (0, 0);
        }
        let tile = |p: f64| (p.max(0.0) as u32 / HI_STENCIL_TILE).min(tiles[axis] - 1);
        let (first, last) = (tile(lo), tile(hi));
        (first, last + 1 - first)
    };
    let ((x, width), (y, height)) = (span(0), span(1));
    let rect = TileRect {
        x,
        y,
        width,
        height,
    };
    if rect.is_empty() {
        TileRect::default()
    } else {
        rect
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use histencil_model::{FlushPolicy, LightCase, LightRequest, LightTechnique, Ps3Like};
    use histencil_model::{StencilLayout, X360Like};

    fn writes(plan: &FramePlan) -> Vec<(usize, CullMode, Geometry, TouchedTiles)> {
        plan.steps
            .iter()
            .zip(plan_touches(plan))
            .filter_map(|(step, touch)| match step {
                Step::Pass { light, pass } => {
                    assert_eq!(touch.is_some(), pass.state.writes_hi_stencil());
                    touch.map(|t| (*light, pass.state.cull, pass.geometry, t))
                }
                _ => {
                    assert!(touch.is_none());
                    None
                }
            })
            .collect()
    }

    /// A volume write draws its tiles unless the light's previous write drew the same faces,
    /// whose tiles it keeps; a full-screen write touches all.
    #[test]
    fn writes_keep_tiles_only_for_the_same_lights_same_faces() {
        let layout = StencilLayout::new(3, 0).unwrap();
        let request = |case| LightRequest {
            case,
            affected: vec![0, 1, 2],
            technique: LightTechnique::Stencil,
        };
        let requests = [
            request(LightCase::Outside),
            request(LightCase::Outside),
            request(LightCase::ViewerInside),
        ];
        for plan in [
            FramePlan::from_requests(&layout, &Ps3Like, &requests, FlushPolicy::Auto).unwrap(),
            FramePlan::from_requests(&layout, &X360Like::default(), &requests, FlushPolicy::Auto)
                .unwrap(),
        ] {
            let writes = writes(&plan);
            assert!(writes.iter().any(|w| w.3 == TouchedTiles::Kept));
            for (i, &(light, cull, geometry, touch)) in writes.iter().enumerate() {
                let expected = match geometry {
                    Geometry::FullScreen => TouchedTiles::All,
                    Geometry::Volume => {
                        let previous = i.checked_sub(1).map(|p| writes[p]);
                        let same = previous
                            .is_some_and(|w| (w.0, w.1, w.2) == (light, cull, Geometry::Volume));
                        if same {
                            TouchedTiles::Kept
                        } else {
                            TouchedTiles::Drawn
                        }
                    }
                };
                assert_eq!(touch, expected, "write {i}");
            }
        }
    }

    /// Markers are 16-bit codes four apart, never within one of 0 or of 65535's overflow, each
    /// new until they run out, and the image is cleared whole exactly when a code could come
    /// round again.
    #[test]
    fn markers_are_new_codes_until_a_whole_clear() {
        let (mut marker, mut clears, mut count) = (0, 0, 0);
        let mut seen = std::collections::HashSet::new();
        while clears < 2 {
            let (next, clear) = next_marker(marker);
            if clear {
                clears += 1;
                seen.clear();
            }
            assert!(next > 1 && next < u32::from(u16::MAX) && next % MARKER_STEP == 0);
            assert!(seen.insert(next), "{next} came round without a clear");
            (marker, count) = (next, count + 1);
        }
        assert_eq!(count, MAX_MARKER / MARKER_STEP + 1);
    }

    fn ndc(min: [f64; 2], max: [f64; 2]) -> Option<NdcRect> {
        Some(NdcRect { min, max })
    }

    /// Tile rectangles hold every pixel of their NDC rectangle with a pixel to spare, clamp to
    /// the frame, and are empty only off screen; unknown or broken rectangles mean the frame.
    #[test]
    fn tile_rectangles_hold_their_pixels_and_clamp_to_the_frame() {
        let extent = vk::Extent2D {
            width: 100,
            height: 60,
        };
        let frame = TileRect {
            x: 0,
            y: 0,
            width: 13,
            height: 8,
        };
        assert_eq!(tile_rect(extent, None), frame);
        assert_eq!(tile_rect(extent, ndc([f64::NAN, 0.0], [1.0, 1.0])), frame);
        assert_eq!(tile_rect(extent, ndc([-5.0, -5.0], [5.0, 5.0])), frame);
        // Pixels 50..=58 across (NDC 0 to 0.16), rows 30..=33: with a pixel to spare, tiles
        // 6..=7 across and 3..=4 down.
        let r = tile_rect(extent, ndc([0.0, 0.0], [0.16, 0.1]));
        assert_eq!((r.x, r.width, r.y, r.height), (6, 2, 3, 2));
        // Exactly on a tile edge: the spare pixel reaches the tile before.
        let r = tile_rect(extent, ndc([-0.68, -1.0], [-0.6, -0.9]));
        assert_eq!((r.x, r.width, r.y, r.height), (1, 2, 0, 1));
        let off = tile_rect(extent, ndc([1.1, 0.0], [2.0, 0.5]));
        assert_eq!(off.width * off.height, 0);
        let above = tile_rect(extent, ndc([0.0, -3.0], [0.5, -1.1]));
        assert_eq!(above.width * above.height, 0);
        // In pixels, the last column and row of tiles stop at the frame's edge.
        let edge = frame.pixels(extent);
        assert_eq!((edge.offset.x, edge.offset.y), (0, 0));
        assert_eq!((edge.extent.width, edge.extent.height), (100, 60));
        let corner = TileRect {
            x: 12,
            y: 6,
            width: 1,
            height: 2,
        };
        let corner = corner.pixels(extent);
        assert_eq!((corner.offset.x, corner.offset.y), (96, 48));
        assert_eq!((corner.extent.width, corner.extent.height), (4, 12));
    }
}
