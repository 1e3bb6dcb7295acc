//! How far a rendered frame is from its reference: 8-bit max and mean, and FLIP.

use image::RgbaImage;

/// Error of an 8-bit frame against a reference frame of the same size.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ImageError {
    /// Largest per-channel difference, 8-bit steps.
    pub max: f64,
    /// Mean per-channel (RGB) difference, 8-bit steps.
    pub mean: f64,
    /// Mean FLIP error (NVIDIA's perceptual difference, 0 to 1) at 67 pixels per degree.
    pub flip: f64,
}

impl ImageError {
    /// The larger of the two errors, measure by measure.
    pub fn worst(self, other: ImageError) -> ImageError {
        ImageError {
            max: self.max.max(other.max),
            mean: self.mean.max(other.mean),
            flip: self.flip.max(other.flip),
        }
    }
}

/// `actual` against `reference` (the same size; alpha is ignored).
pub fn image_error(actual: &RgbaImage, reference: &RgbaImage) -> ImageError {
    assert_eq!(
        actual.dimensions(),
        reference.dimensions(),
        "same-size frames"
    );
    let rgb = |image: &RgbaImage| -> Vec<u8> {
        image
            .pixels()
            .flat_map(|p| [p.0[0], p.0[1], p.0[2]])
            .collect()
    };
    let (a, r) = (rgb(actual), rgb(reference));
    let diffs = a.iter().zip(&r).map(|(x, y)| x.abs_diff(*y));
    let (max, sum) = diffs.fold((0u8, 0u64), |(m, s), d| (m.max(d), s + u64::from(d)));
    let (w, h) = actual.dimensions();
    let flip = if a == r {
        0.0
    } else {
        let map = nv_flip::flip(
            nv_flip::FlipImageRgb8::with_data(w, h, &r),
            nv_flip::FlipImageRgb8::with_data(w, h, &a),
            nv_flip::DEFAULT_PIXELS_PER_DEGREE,
        );
        f64::from(nv_flip::FlipPool::from_image(&map).mean())
    };
    ImageError {
        max: f64::from(max),
        mean: sum as f64 / a.len().max(1) as f64,
        flip,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identical_frames_have_no_error_and_a_changed_one_has_some() {
        let a = RgbaImage::from_fn(32, 32, |x, y| {
            image::Rgba([x as u8 * 8, y as u8 * 8, 40, 255])
        });
        assert_eq!(image_error(&a, &a), ImageError::default());
        let mut b = a.clone();
        b.put_pixel(3, 4, image::Rgba([255, 0, 0, 255]));
        let e = image_error(&b, &a);
        assert_eq!(e.max, 255.0 - 24.0);
        assert!(e.mean > 0.0 && e.flip > 0.0 && e.flip <= 1.0, "{e:?}");
    }
}
