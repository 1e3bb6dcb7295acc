//! Writing output files, with errors that name the path, and never half-written: every file is
//! written to a temporary file in its own folder and renamed over the final name once complete,
//! so a failed or interrupted run leaves no empty or truncated output behind. The checks run
//! before long work create nothing, so a failed run leaves no empty folders either.

use crate::gpu::device::error::{Error, Result};
use std::io::Write as _;
use std::path::{Path, PathBuf};

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
    save_image(image, path, image::ImageFormat::Png)
}

/// What an image file holds, which decides the formats it may be written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageKind {
    /// A tonemapped 8-bit colour frame: PNG, or JPEG (lossy, without alpha).
    Colour,
    /// Linear HDR radiance: OpenEXR (32-bit float).
    Hdr,
    /// Exact 8-bit values, such as a stencil byte: PNG only, since JPEG would change them.
    Exact,
}

impl ImageKind {
    fn formats(self) -> &'static [(&'static str, image::ImageFormat)] {
        use image::ImageFormat::{Jpeg, OpenExr, Png};
        match self {
            ImageKind::Colour => &[("png", Png), ("jpg", Jpeg), ("jpeg", Jpeg)],
            ImageKind::Hdr => &[("exr", OpenExr)],
            ImageKind::Exact => &[("png", Png)],
        }
    }

    fn describe(self) -> &'static str {
        match self {
            ImageKind::Colour => "an 8-bit colour image",
            ImageKind::Hdr => "a linear HDR image",
            ImageKind::Exact => "exact 8-bit values (JPEG would change them)",
        }
    }
}

/// The format `path`'s extension names (case ignored) for an image of `kind`, or an error
/// naming the path and the extensions that `kind` may be written as. A file is never written in
/// a format other than the one its name says.
pub fn image_format(path: &Path, kind: ImageKind) -> Result<image::ImageFormat> {
    let formats = kind.formats();
    let names: Vec<String> = formats.iter().map(|(e, _)| format!(".{e}")).collect();
    let names = names.join(", ");
    let extension = path.extension().map(|e| e.to_string_lossy().to_lowercase());
    let Some(extension) = extension else {
        return Err(output_error(
            path,
            format!(
                "has no extension to say its format: {} is written as {names}",
                kind.describe()
            ),
        ));
    };
    formats
        .iter()
        .find(|(e, _)| *e == extension)
        .map(|(_, format)| *format)
        .ok_or_else(|| {
            output_error(
                path,
                format!(
                    "`.{extension}` is not a format histencil writes {} in: name it {names}",
                    kind.describe()
                ),
            )
        })
}

/// [`check_output_file`] and [`image_format`]: fails before any long work when `path` could not
/// be written later or its extension names no format for `kind`; creates nothing.
pub fn check_image_output(path: &Path, kind: ImageKind) -> Result<()> {
    check_output_file(path)?;
    image_format(path, kind).map(|_| ())
}

/// Writes `image` in the format `path`'s extension names for `kind` ([`image_format`]), whole or
/// not at all. JPEG drops the alpha channel, which it cannot hold.
pub fn save_image_as(image: &image::DynamicImage, path: &Path, kind: ImageKind) -> Result<()> {
    let format = image_format(path, kind)?;
    let mut bytes = Vec::new();
    let mut cursor = std::io::Cursor::new(&mut bytes);
    let written = match format {
        image::ImageFormat::Jpeg => image.to_rgb8().write_to(&mut cursor, format),
        image::ImageFormat::OpenExr => image.to_rgba32f().write_to(&mut cursor, format),
        _ => image.write_to(&mut cursor, format),
    };
    written.map_err(|e| output_error(path, e))?;
    write_atomically(path, &bytes)
}

fn save_image<P, C>(
    image: &image::ImageBuffer<P, C>,
    path: &Path,
    format: image::ImageFormat,
) -> Result<()>
where
    P: image::Pixel + image::PixelWithColorType,
    [P::Subpixel]: image::EncodableLayout,
    C: std::ops::Deref<Target = [P::Subpixel]>,
{
    let mut bytes = Vec::new();
    image
        .write_to(&mut std::io::Cursor::new(&mut bytes), format)
        .map_err(|e| output_error(path, e))?;
    write_atomically(path, &bytes)
}

/// Writes `bytes` to `path` whole or not at all: into a temporary file beside it, flushed, then
/// renamed over `path`. Creates the parent folders.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    let dir = parent_of(path);
    std::fs::create_dir_all(dir).map_err(|e| output_error(dir, e))?;
    let temp = temp_name(path);
    let written = std::fs::File::create(&temp)
        .and_then(|mut f| f.write_all(bytes).and_then(|()| f.sync_all()))
        .and_then(|()| std::fs::rename(&temp, path));
    written.map_err(|e| {
        let _ = std::fs::remove_file(&temp);
        output_error(path, e)
    })
}

/// Fails early, naming the path, when `path` could not be written later; creates nothing. The
/// nearest existing folder on its way must be writable (checked by creating and removing a
/// probe file there), and `path` must not be a folder.
pub fn check_output_file(path: &Path) -> Result<()> {
    if path.as_os_str().is_empty() || path.file_name().is_none() {
        return Err(output_error(path, "not a file name"));
    }
    if path.is_dir() {
        return Err(output_error(path, "is a directory"));
    }
    check_writable_dir(parent_of(path)).map_err(|e| output_error(path, e))
}

/// Fails early when files could not be written into the folder `dir` later; creates nothing.
pub fn check_output_dir(dir: &Path) -> Result<()> {
    if dir.exists() && !dir.is_dir() {
        return Err(output_error(dir, "exists and is not a directory"));
    }
    check_writable_dir(dir).map_err(|e| output_error(dir, e))
}

/// `dir` or its nearest existing ancestor is a folder a file can be created in.
fn check_writable_dir(dir: &Path) -> std::result::Result<(), String> {
    let mut existing = dir;
    while !existing.exists() {
        existing = match existing.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
    }
    if !existing.is_dir() {
        return Err(format!("{} is not a directory", existing.display()));
    }
    let probe = existing.join(format!(".histencil-probe-{}", std::process::id()));
    std::fs::File::create(&probe)
        .map_err(|e| format!("cannot write in {}: {e}", existing.display()))?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

fn parent_of(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// A hidden name beside `path`, unique to this process and call.
fn temp_name(path: &Path) -> PathBuf {
    use std::sync::atomic::{AtomicU64, Ordering};
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    parent_of(path).join(format!(
        ".{name}.{}-{}.tmp",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(tag: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("histencil-output-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    #[test]
    fn checks_create_nothing_and_writes_leave_only_the_file() {
        let dir = scratch("atomic");
        let file = dir.join("a/b/out.png");
        check_output_file(&file).unwrap();
        check_output_dir(&dir.join("report")).unwrap();
        assert!(!dir.exists(), "a check created {}", dir.display());
        write_atomically(&file, b"abc").unwrap();
        write_atomically(&file, b"de").unwrap();
        assert_eq!(std::fs::read(&file).unwrap(), b"de");
        let names: Vec<_> = std::fs::read_dir(file.parent().unwrap())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, ["out.png"]);
        assert!(check_output_file(&dir.join("a"))
            .unwrap_err()
            .to_string()
            .contains("directory"));
        assert!(check_output_dir(&file)
            .unwrap_err()
            .to_string()
            .contains("not a directory"));
        assert!(check_output_file(&file.join("x")).is_err());
        // A write that cannot finish (its folder is a file) leaves nothing behind.
        assert!(write_atomically(&file.join("x"), b"abc").is_err());
        assert_eq!(std::fs::read(&file).unwrap(), b"de");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Every file is written in the format its extension names, or refused before anything is
    /// written: the bytes are checked, not only the name.
    #[test]
    fn images_are_written_in_the_format_their_extension_names() {
        let dir = scratch("formats");
        let colour = image::DynamicImage::ImageRgba8(image::RgbaImage::from_pixel(
            5,
            3,
            image::Rgba([200, 100, 50, 255]),
        ));
        let hdr = image::DynamicImage::ImageRgba32F(image::Rgba32FImage::from_pixel(
            5,
            3,
            image::Rgba([4.5, 0.25, 0.0, 1.0]),
        ));
        let exact = image::DynamicImage::ImageLuma8(image::GrayImage::from_pixel(
            5,
            3,
            image::Luma([0xA3]),
        ));
        let written = [
            (&colour, "a.png", ImageKind::Colour, image::ImageFormat::Png),
            (
                &colour,
                "b.JPG",
                ImageKind::Colour,
                image::ImageFormat::Jpeg,
            ),
            (
                &colour,
                "c.jpeg",
                ImageKind::Colour,
                image::ImageFormat::Jpeg,
            ),
            (&hdr, "d.exr", ImageKind::Hdr, image::ImageFormat::OpenExr),
            (&exact, "e.png", ImageKind::Exact, image::ImageFormat::Png),
        ];
        for (image, name, kind, format) in written {
            let path = dir.join(name);
            check_image_output(&path, kind).unwrap();
            save_image_as(image, &path, kind).unwrap();
            let bytes = std::fs::read(&path).unwrap();
            assert_eq!(image::guess_format(&bytes).unwrap(), format, "{name}");
            let back = image::load_from_memory(&bytes).unwrap();
            assert_eq!((back.width(), back.height()), (5, 3), "{name}");
        }
        let back = image::open(dir.join("d.exr")).unwrap().to_rgba32f();
        assert_eq!(back.get_pixel(4, 2).0, [4.5, 0.25, 0.0, 1.0]);
        let back = image::open(dir.join("e.png")).unwrap().to_luma8();
        assert_eq!(back.get_pixel(4, 2).0, [0xA3]);
        let refused = [
            (
                &colour,
                "f.exr",
                ImageKind::Colour,
                "name it .png, .jpg, .jpeg",
            ),
            (&colour, "g.bmp", ImageKind::Colour, "`.bmp`"),
            (&colour, "noext", ImageKind::Colour, "has no extension"),
            (&hdr, "h.png", ImageKind::Hdr, "name it .exr"),
            (&exact, "i.jpg", ImageKind::Exact, "JPEG would change them"),
        ];
        for (image, name, kind, needle) in refused {
            let path = dir.join(name);
            let early = check_image_output(&path, kind).unwrap_err().to_string();
            assert!(early.contains(needle) && early.contains(name), "{early}");
            let late = save_image_as(image, &path, kind).unwrap_err().to_string();
            assert_eq!(early, late);
            assert!(!path.exists(), "{name} was written");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
