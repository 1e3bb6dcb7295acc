//! Writing images to files, with errors that name the path.

use crate::error::{Error, Result};
use std::path::Path;

fn output_error(path: &Path, e: impl std::fmt::Display) -> Error {
    Error::Output {
        path: path.display().to_string(),
        message: e.to_string(),
    }
}

/// Writes an 8-bit PNG (RGBA or grey).
pub fn save_png<P, C>(image: &image::ImageBuffer<P, C>, path: &Path) -> Result<()>
where
    P: image::Pixel + image::PixelWithColorType,
    [P::Subpixel]: image::EncodableLayout,
    C: std::ops::Deref<Target = [P::Subpixel]>,
{
    image
        .save_with_format(path, image::ImageFormat::Png)
        .map_err(|e| output_error(path, e))
}

/// Writes a linear HDR image as OpenEXR (RGBA, 32-bit float).
pub fn save_exr(image: &image::Rgba32FImage, path: &Path) -> Result<()> {
    image
        .save_with_format(path, image::ImageFormat::OpenExr)
        .map_err(|e| output_error(path, e))
}
