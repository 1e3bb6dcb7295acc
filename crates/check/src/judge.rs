//! Judging one frame, on plain images (no device): its 8-bit error against the forward
//! reference within the case's stated tolerance, and its stencil after lighting against what the
//! backend promises.

use crate::matrix::{Expect, Platform};
use histencil_model::StencilLayout;
use image::RgbaImage;

pub use crate::bound::Tolerance;

/// The LUT technique at its default resolution (32): the bound `tests/tests/techniques.rs`
/// holds it to and the README documents (23/255 at most where Blinn-Phong 256 highlights fall
/// between grid points; mean 0.02/255).
pub const LUT: Tolerance = Tolerance {
    max: 32,
    mean: 0.05,
};

/// Lightmapped alpha entities over the pixels they cover: the README's figures at the default
/// (coverage-chosen) lightmap sides, 13/255 mean on `alpha-many` at 1280x720, with margin for tiny
/// frames where a region is 8 texels for a whole entity.
pub const ALPHA_LIGHTMAP: Tolerance = Tolerance {
    max: 255,
    mean: 24.0,
};

/// The single light probe per entity over the pixels it covers: the README's 92/255 mean on
/// `volume`. Only a gross failure (a black or white entity) exceeds it; what the case holds
/// exactly is the rest of the frame, and its validation.
pub const ALPHA_PROBE: Tolerance = Tolerance {
    max: 255,
    mean: 128.0,
};

/// The error of one image against another, over some of their pixels.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ImageError {
    pub max: u8,
    /// Mean absolute difference per channel, in 8-bit steps.
    pub mean: f64,
    /// Pixels judged.
    pub pixels: usize,
    /// Pixels with any channel beyond the tolerance's max.
    pub over: usize,
}

impl ImageError {
    /// Within the max, and within the mean with one 8-bit step of slack: a mean bound speaks of
    /// many pixels, and over a frame of a few pixels a single step on one channel is more than
    /// it (a 1x1 LUT frame on an NVIDIA H100, 1/255 off forward in one channel, has mean 0.25
    /// against LUT's 0.05). The step's share vanishes at real sizes (1e-7 at 1280x720).
    pub fn within(&self, tolerance: Tolerance) -> bool {
        let one_step = 1.0 / (4 * self.pixels.max(1)) as f64;
        self.max <= tolerance.max && self.mean <= tolerance.mean + one_step
    }
}

/// The error of `actual` against `expected` over the pixels `judged` accepts (by index).
///
/// # Panics
/// If the sizes differ: both come from one renderer.
pub fn image_error(
    actual: &RgbaImage,
    expected: &RgbaImage,
    tolerance: u8,
    judged: impl Fn(usize) -> bool,
) -> ImageError {
    assert_eq!(actual.dimensions(), expected.dimensions());
    let (mut max, mut sum, mut pixels, mut over) = (0u8, 0u64, 0usize, 0usize);
    for (i, (a, e)) in actual.pixels().zip(expected.pixels()).enumerate() {
        if !judged(i) {
            continue;
        }
        let d = a.0.iter().zip(e.0).map(|(x, y)| x.abs_diff(y));
        let worst = d.clone().max().unwrap_or(0);
        max = max.max(worst);
        sum += d.map(u64::from).sum::<u64>();
        pixels += 1;
        over += usize::from(worst > tolerance);
    }
    ImageError {
        max,
        mean: if pixels == 0 {
            0.0
        } else {
            sum as f64 / (4 * pixels) as f64
        },
        pixels,
        over,
    }
}

/// The image verdict of a case: its error over the pixels judged, and the bound.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageVerdict {
    /// Over the whole frame, or with alpha cases over the pixels alpha entities cover.
    pub error: ImageError,
    pub tolerance: Tolerance,
    /// Whether `error` covers only the alpha entities' pixels.
    pub alpha_covered: bool,
}

impl ImageVerdict {
    pub fn passed(&self) -> bool {
        self.error.within(self.tolerance)
    }

    /// `max 12/255 (bound 2), mean 0.310/255 (bound 1) over 33153 pixels, 210 beyond the max`;
    /// a mean bound that is not whole is given to three decimals (`bound 1.873`).
    pub fn describe(&self) -> String {
        let (e, t) = (&self.error, &self.tolerance);
        format!(
            "{}max {}/255 (bound {}), mean {:.3}/255 (bound {}) over {} pixels, {} beyond the max",
            if self.alpha_covered {
                "alpha-covered pixels: "
            } else {
                ""
            },
            e.max,
            t.max,
            e.mean,
            (t.mean * 1000.0).round() / 1000.0,
            e.pixels,
            e.over
        )
    }
}

/// Judges `actual` against the forward reference `expected`: the LUT technique ([`Expect::Lut`])
/// within [`LUT`], every other case within `exact`, the bound derived for its scene and
/// technique ([`crate::matrix::SceneNeeds::exact_tolerance`]).
///
/// An approximate alpha mode ([`Expect::Alpha`], with `alpha`: the forward frame without alpha
/// entities and the mode's bound) is judged over the pixels alpha entities cover: where the
/// reference differs from that background, or the case differs from it by more than `exact`
/// allows. (Where neither does, the case is within `exact` of the reference by construction;
/// the opaque frame under alpha entities is held exactly by the cases that light them forward.)
/// Coverage cannot be read from the reference alone: an entity whose forward-lit colour equals
/// the background there would be missed.
pub fn judge_image(
    expect: Expect,
    actual: &RgbaImage,
    expected: &RgbaImage,
    exact: Tolerance,
    alpha: Option<(&RgbaImage, Tolerance)>,
) -> ImageVerdict {
    match alpha {
        None => {
            let tolerance = if expect == Expect::Lut { LUT } else { exact };
            ImageVerdict {
                error: image_error(actual, expected, tolerance.max, |_| true),
                tolerance,
                alpha_covered: false,
            }
        }
        Some((background, tolerance)) => {
            let differs = |a: &image::Rgba<u8>, b: &image::Rgba<u8>| {
                a.0.iter().zip(b.0).any(|(x, y)| x.abs_diff(y) > exact.max)
            };
            let covered: Vec<bool> = (expected.pixels().zip(actual.pixels()))
                .zip(background.pixels())
                .map(|((e, a), b)| e != b || differs(a, b))
                .collect();
            ImageVerdict {
                error: image_error(actual, expected, tolerance.max, |i| covered[i]),
                tolerance,
                alpha_covered: true,
            }
        }
    }
}

/// What the frame's G-buffer pass wrote, per pixel: the BRDF slot of the surface there (`None`
/// where no surface is).
pub struct StencilInputs<'a> {
    pub layout: StencilLayout,
    pub slots: &'a [Option<u32>],
    pub pattern: u8,
    pub platform: Platform,
    pub width: u32,
}

/// Checks the stencil after lighting: the culling bit clear everywhere, the BRDF bits as the
/// G-buffer pass wrote them, and the preserved bits as the backend promises: intact on PS3-like,
/// native and 360-like with save / restore; intact or zeroed (never anything else) on 360-like
/// with zeroing. With `predicted` (the CPU simulator's stencil from the GPU's own inputs), the
/// whole stencil must equal it, which pins down where 360-like zeroing happened.
///
/// Returns every problem found, each with its pixel count and first pixel.
pub fn judge_stencil(
    stencil: &[u8],
    inputs: &StencilInputs<'_>,
    predicted: Option<&[u8]>,
) -> Vec<String> {
    let layout = inputs.layout;
    let preserved = layout.preserved_mask();
    let zeroes = inputs.platform == Platform::X360;
    let mut problems: Vec<(&str, usize, usize)> = Vec::new();
    let mut note = |what: &'static str, i: usize| match problems.iter_mut().find(|p| p.0 == what) {
        Some(p) => p.1 += 1,
        None => problems.push((what, 1, i)),
    };
    for (i, (&value, slot)) in stencil.iter().zip(inputs.slots).enumerate() {
        if value & layout.culling_mask() != 0 {
            note("culling bit left set", i);
        }
        let (brdf, pattern) = match slot {
            Some(slot) => (layout.brdf_reference(*slot), inputs.pattern & preserved),
            None => (0, 0),
        };
        if value & layout.brdf_mask() != brdf {
            note("BRDF bits differ from the G-buffer's", i);
        }
        let kept = value & preserved;
        if kept != pattern && !(zeroes && kept == 0) {
            note(
                if zeroes {
                    "preserved bits neither intact nor zeroed"
                } else {
                    "preserved bits not intact"
                },
                i,
            );
        }
        if predicted.is_some_and(|p| p.get(i) != Some(&value)) {
            note("stencil differs from the simulator's prediction", i);
        }
    }
    problems
        .into_iter()
        .map(|(what, count, first)| {
            let (x, y) = (first as u32 % inputs.width, first as u32 / inputs.width);
            format!(
                "{what} at {count} pixel(s), first ({x}, {y}): {:#04x}",
                stencil[first]
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bound::exact_bound;

    fn image(pixels: &[[u8; 4]], width: u32) -> RgbaImage {
        RgbaImage::from_raw(width, pixels.len() as u32 / width, pixels.concat()).unwrap()
    }

    /// One step in one channel of a one-pixel frame passes a mean bound below it; two steps do
    /// not, and neither does the same step spread over a large frame above the bound.
    #[test]
    fn a_mean_bound_allows_one_step_on_tiny_frames() {
        let a = image(&[[10, 10, 10, 255]], 1);
        let one = image_error(&a, &image(&[[11, 10, 10, 255]], 1), 32, |_| true);
        let two = image_error(&a, &image(&[[12, 10, 10, 255]], 1), 32, |_| true);
        assert!((one.mean - 0.25).abs() < 1e-12);
        assert!(one.within(LUT));
        assert!(!two.within(LUT));
        let big = ImageError {
            max: 1,
            mean: 0.06,
            pixels: 1280 * 720,
            over: 0,
        };
        assert!(!big.within(LUT));
    }

    #[test]
    fn image_error_counts_only_judged_pixels() {
        let a = image(&[[10, 10, 10, 255], [0, 0, 0, 255]], 2);
        let b = image(&[[11, 10, 10, 255], [40, 0, 0, 255]], 2);
        let all = image_error(&a, &b, 1, |_| true);
        assert_eq!((all.max, all.pixels, all.over), (40, 2, 1));
        assert!((all.mean - 41.0 / 8.0).abs() < 1e-12);
        let first = image_error(&a, &b, 1, |i| i == 0);
        assert_eq!((first.max, first.over), (1, 0));
        assert!(first.within(exact_bound(1)));
        assert!(!all.within(exact_bound(1)));
    }

    /// Exact cases are held to the bound they are given, and say which.
    #[test]
    fn exact_cases_are_judged_by_their_derived_bound() {
        let expected = image(&[[10, 10, 10, 255], [200, 100, 0, 255]], 2);
        let actual = image(&[[12, 10, 10, 255], [201, 100, 0, 255]], 2);
        let one = Tolerance { max: 1, mean: 1.0 };
        let v = judge_image(Expect::Exact, &actual, &expected, one, None);
        assert!(!v.passed(), "{}", v.describe());
        let derived = exact_bound(1);
        assert_eq!(derived.max, 2);
        let v = judge_image(Expect::Exact, &actual, &expected, derived, None);
        assert!(v.passed(), "{}", v.describe());
        assert!(v
            .describe()
            .starts_with("max 2/255 (bound 2), mean 0.375/255 (bound 1) "));
        // Many roundings: a larger bound, its mean given to three decimals.
        let many = exact_bound(64);
        let v = judge_image(Expect::Exact, &actual, &expected, many, None);
        let text = v.describe();
        assert!(text.contains(&format!("(bound {})", many.max)), "{text}");
        assert!(
            text.contains(&format!("(bound {:.3})", many.mean)),
            "{text}"
        );
        // The LUT technique keeps its own bound whatever it is given.
        let v = judge_image(Expect::Lut, &actual, &expected, one, None);
        assert_eq!(v.tolerance, LUT);
    }

    #[test]
    fn alpha_cases_are_judged_where_either_frame_shows_an_entity() {
        let background = image(&[[0, 0, 0, 255], [5, 5, 5, 255], [9, 9, 9, 255]], 3);
        // Pixel 1: the reference shows an entity. Pixel 2: only the case does (an entity whose
        // forward-lit colour equals the background). Pixel 0: neither.
        let expected = image(&[[0, 0, 0, 255], [50, 50, 50, 255], [9, 9, 9, 255]], 3);
        let actual = image(&[[1, 0, 0, 255], [60, 50, 50, 255], [9, 9, 99, 255]], 3);
        let v = judge_image(
            Expect::Alpha,
            &actual,
            &expected,
            exact_bound(1),
            Some((&background, ALPHA_LIGHTMAP)),
        );
        assert_eq!((v.error.pixels, v.error.max), (2, 90));
        assert!((v.error.mean - 100.0 / 8.0).abs() < 1e-12);
        assert!(v.passed(), "{}", v.describe());
        let tight = Tolerance {
            max: 255,
            mean: 12.0,
        };
        let v = judge_image(
            Expect::Alpha,
            &actual,
            &expected,
            exact_bound(1),
            Some((&background, tight)),
        );
        assert!(!v.passed(), "{}", v.describe());
    }

    #[test]
    fn stencil_promises_per_backend() {
        let layout = StencilLayout::new(2, 0).unwrap(); // culling 0x01, BRDF 0x02
        let slots = [Some(0), Some(1), None];
        let inputs = |platform| StencilInputs {
            layout,
            slots: &slots,
            pattern: 0xA0,
            platform,
            width: 3,
        };
        let intact = [0xA0, 0xA2, 0x00];
        let zeroed = [0x00, 0xA2, 0x00];
        for platform in [Platform::Ps3, Platform::Native, Platform::X360SaveRestore] {
            assert!(judge_stencil(&intact, &inputs(platform), None).is_empty());
            let problems = judge_stencil(&zeroed, &inputs(platform), None);
            assert_eq!(problems.len(), 1, "{problems:?}");
            assert!(
                problems[0].starts_with("preserved bits not intact at 1 pixel(s), first (0, 0)")
            );
        }
        let x360 = inputs(Platform::X360);
        assert!(judge_stencil(&zeroed, &x360, None).is_empty());
        assert!(judge_stencil(&intact, &x360, None).is_empty());
        // Zeroing must happen where the simulator says, not just anywhere.
        let problems = judge_stencil(&zeroed, &x360, Some(&intact));
        assert_eq!(problems.len(), 1, "{problems:?}");
        // Half-zeroed bits, a stray culling bit, BRDF bits of the wrong slot.
        let bad = [0x80, 0xA1, 0x02];
        let problems = judge_stencil(&bad, &x360, None);
        assert_eq!(problems.len(), 3, "{problems:?}");
    }
}
