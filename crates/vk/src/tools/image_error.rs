//! Error of one 8-bit frame against another, over the pixels some layer changed: how the alpha
//! techniques are compared with the forward reference without the (identical) rest of the frame
//! diluting the figure.

use image::RgbaImage;

/// `|actual - expected|` per colour channel times `scale` (saturating, so one 8-bit step shows
/// at 16 or 32), opaque: the difference image of a failed comparison or a contact sheet.
///
/// # Panics
/// If the sizes differ: both frames come from one renderer.
pub fn difference_image(actual: &RgbaImage, expected: &RgbaImage, scale: u8) -> RgbaImage {
    assert_eq!(actual.dimensions(), expected.dimensions());
    RgbaImage::from_fn(actual.width(), actual.height(), |x, y| {
        let (a, e) = (actual.get_pixel(x, y), expected.get_pixel(x, y));
        let c = |i: usize| a.0[i].abs_diff(e.0[i]).saturating_mul(scale);
        image::Rgba([c(0), c(1), c(2), 255])
    })
}

/// Absolute 8-bit colour error over a mask.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaskedError {
    /// Mean over the masked pixels' RGB channels, in 8-bit steps.
    pub mean: f64,
    /// Largest channel difference, in 8-bit steps.
    pub max: u8,
    /// Pixels in the mask.
    pub pixels: usize,
}

/// The RGB error of `actual` against `expected` over the pixels where `expected` differs from
/// `background` (the frame without the layer under test). `None` when the images' sizes differ.
pub fn masked_error(
    actual: &RgbaImage,
    expected: &RgbaImage,
    background: &RgbaImage,
) -> Option<MaskedError> {
    if actual.dimensions() != expected.dimensions()
        || expected.dimensions() != background.dimensions()
    {
        return None;
    }
    let (mut sum, mut max, mut pixels) = (0u64, 0u8, 0usize);
    for ((a, e), b) in actual
        .pixels()
        .zip(expected.pixels())
        .zip(background.pixels())
    {
        if e.0[..3] == b.0[..3] {
            continue;
        }
        pixels += 1;
        for c in 0..3 {
            let d = a.0[c].abs_diff(e.0[c]);
            sum += u64::from(d);
            max = max.max(d);
        }
    }
    let mean = if pixels == 0 {
        0.0
    } else {
        sum as f64 / (3 * pixels) as f64
    };
    Some(MaskedError { mean, max, pixels })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_the_changed_pixels_count() {
        let background = RgbaImage::from_pixel(4, 1, image::Rgba([10, 10, 10, 255]));
        let mut expected = background.clone();
        expected.put_pixel(1, 0, image::Rgba([40, 40, 40, 255]));
        let mut actual = expected.clone();
        actual.put_pixel(1, 0, image::Rgba([43, 40, 40, 255]));
        actual.put_pixel(3, 0, image::Rgba([99, 99, 99, 255])); // outside the mask
        let e = masked_error(&actual, &expected, &background).unwrap();
        assert_eq!((e.pixels, e.max), (1, 3));
        assert!((e.mean - 1.0).abs() < 1e-12);
        assert!(masked_error(&actual, &RgbaImage::new(1, 1), &background).is_none());
    }

    #[test]
    fn differences_are_scaled_saturated_and_opaque() {
        let a = RgbaImage::from_pixel(1, 1, image::Rgba([10, 200, 7, 0]));
        let b = RgbaImage::from_pixel(1, 1, image::Rgba([11, 0, 7, 9]));
        assert_eq!(
            difference_image(&a, &b, 32).get_pixel(0, 0).0,
            [32, 255, 0, 255]
        );
    }
}
