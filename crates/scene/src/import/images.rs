//! A glTF's images and textures: each image decoded once, on first use by a material, under the
//! same rules as buffers (a `data:` URI, a buffer view, or a regular file inside the glTF's
//! folder, bounded before it is read), and each texture reference as a [`TextureRef`].

use super::buffers::{read_uri, ReadLimit};
use super::ImportError;
use crate::{
    uv_transform, Filter, Sampler, TextureImage, TextureRef, UvTransform, Wrap, MAX_TEXTURE_SIDE,
};
use gltf::texture::{MagFilter, MinFilter, WrappingMode};
use std::collections::HashMap;
use std::io::Cursor;
use std::path::Path;

/// The most bytes one encoded image file may have.
pub const MAX_IMAGE_FILE_BYTES: u64 = 512 << 20;

/// The most bytes the decoded images of one import may take together (RGBA8).
pub const MAX_DECODED_IMAGE_BYTES: u64 = 4 << 30;

/// Decodes a glTF's images as materials ask for them, each once.
pub(super) struct Images<'a> {
    document: &'a gltf::Document,
    buffers: &'a [Vec<u8>],
    base_dir: Option<&'a Path>,
    /// glTF image index to its index in the scene's images.
    decoded: HashMap<usize, u32>,
    budget: u64,
}

impl<'a> Images<'a> {
    pub(super) fn new(
        document: &'a gltf::Document,
        buffers: &'a [Vec<u8>],
        base_dir: Option<&'a Path>,
    ) -> Self {
        Self {
            document,
            buffers,
            base_dir,
            decoded: HashMap::new(),
            budget: MAX_DECODED_IMAGE_BYTES,
        }
    }

    /// The reference a material's texture info makes: its image decoded into `images` (once),
    /// its sampler, and `placement`, its uv transform and texture coordinate set (or why the
    /// texture's `KHR_texture_transform` was refused).
    pub(super) fn texture_ref(
        &mut self,
        images: &mut Vec<TextureImage>,
        texture: &gltf::Texture,
        placement: Result<(UvTransform, u32), String>,
    ) -> Result<TextureRef, ImportError> {
        let image = self.image(images, &texture.source())?;
        let (transform, texcoord) = placement.map_err(|problem| {
            ImportError::Structure(format!(
                "texture {}: KHR_texture_transform {problem}",
                texture.index()
            ))
        })?;
        Ok(TextureRef {
            image,
            sampler: sampler(&texture.sampler()),
            texcoord,
            transform,
        })
    }

    fn image(
        &mut self,
        images: &mut Vec<TextureImage>,
        image: &gltf::Image,
    ) -> Result<u32, ImportError> {
        if let Some(&slot) = self.decoded.get(&image.index()) {
            return Ok(slot);
        }
        let json = &self.document.as_json().images[image.index()];
        let name = image
            .name()
            .map(str::to_owned)
            .or_else(|| json.uri.clone().filter(|u| !u.starts_with("data:")))
            .unwrap_or_else(|| format!("image{}", image.index()));
        let bad = |problem: String| ImportError::Image {
            index: image.index(),
            name: name.clone(),
            problem,
        };
        let declared = json.mime_type.as_ref().map(|m| m.0.as_str());
        let bytes = match (&json.buffer_view, &json.uri) {
            (Some(view), _) => self.view_bytes(view.value()).map_err(bad)?,
            (None, Some(uri)) => {
                read_uri(uri, self.base_dir, ReadLimit::AtMost(MAX_IMAGE_FILE_BYTES))
                    .map_err(bad)?
            }
            (None, None) => return Err(bad("has neither a uri nor a bufferView".into())),
        };
        let decoded = decode(&bytes, declared, self.budget).map_err(bad)?;
        let (width, height) = decoded.dimensions();
        self.budget -= u64::from(width) * u64::from(height) * 4;
        let slot = images.len() as u32;
        images.push(TextureImage {
            name,
            width,
            height,
            rgba8: decoded.into_raw(),
        });
        self.decoded.insert(image.index(), slot);
        Ok(slot)
    }

    fn view_bytes(&self, view: usize) -> Result<Vec<u8>, String> {
        let view = self
            .document
            .views()
            .nth(view)
            .ok_or_else(|| format!("buffer view {view} does not exist"))?;
        let data = self.buffers.get(view.buffer().index());
        let range = view.offset()..view.offset().saturating_add(view.length());
        data.and_then(|d| d.get(range))
            .map(<[u8]>::to_vec)
            .ok_or_else(|| {
                format!(
                    "buffer view {} runs past the end of buffer {}",
                    view.index(),
                    view.buffer().index()
                )
            })
    }
}

/// The image in `bytes` as RGBA8: a PNG or a JPEG (what glTF 2.0 allows), as its header says
/// (a `mimeType` that disagrees is refused: the file is not what it claims), at most
/// [`MAX_TEXTURE_SIDE`] on a side and `budget` bytes decoded. Decoding is bounded before it
/// allocates, so a header claiming 100000 x 100000 texels is refused, not attempted.
pub(super) fn decode(
    bytes: &[u8],
    declared: Option<&str>,
    budget: u64,
) -> Result<image::RgbaImage, String> {
    let reader = image::ImageReader::new(Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| format!("cannot be read: {e}"))?;
    let format = match reader.format() {
        Some(image::ImageFormat::Png) => "image/png",
        Some(image::ImageFormat::Jpeg) => "image/jpeg",
        Some(other) => return Err(format!("is {other:?}; glTF images are PNG or JPEG")),
        None => return Err("is neither a PNG nor a JPEG (unknown header)".into()),
    };
    if let Some(declared) = declared.filter(|d| *d != format) {
        return Err(format!("declares mimeType {declared} but holds {format}"));
    }
    let (width, height) = reader
        .into_dimensions()
        .map_err(|e| format!("has a corrupt header: {e}"))?;
    if let Some(problem) = crate::texture::side_problem(width, height) {
        return Err(problem);
    }
    let rgba_bytes = u64::from(width) * u64::from(height) * 4;
    if rgba_bytes > budget {
        return Err(format!(
            "decodes to {rgba_bytes} bytes, past the {MAX_DECODED_IMAGE_BYTES} bytes of images \
             an import may hold"
        ));
    }
    let mut reader = image::ImageReader::new(Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| format!("cannot be read: {e}"))?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_TEXTURE_SIDE);
    limits.max_image_height = Some(MAX_TEXTURE_SIDE);
    // The RGBA8 result and the decoder's own buffer (16-bit channels at most).
    limits.max_alloc = Some(rgba_bytes * 2 + (1 << 20));
    reader.limits(limits);
    let image = reader.decode().map_err(|e| format!("is corrupt: {e}"))?;
    Ok(image.into_rgba8())
}

fn sampler(s: &gltf::texture::Sampler) -> Sampler {
    let wrap = |w: WrappingMode| match w {
        WrappingMode::Repeat => Wrap::Repeat,
        WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
        WrappingMode::ClampToEdge => Wrap::ClampToEdge,
    };
    let mag = match s.mag_filter() {
        Some(MagFilter::Nearest) => Filter::Nearest,
        Some(MagFilter::Linear) | None => Filter::Linear,
    };
    let (min, mip) = match s.min_filter() {
        Some(MinFilter::Nearest) => (Filter::Nearest, None),
        Some(MinFilter::Linear) => (Filter::Linear, None),
        Some(MinFilter::NearestMipmapNearest) => (Filter::Nearest, Some(Filter::Nearest)),
        Some(MinFilter::LinearMipmapNearest) => (Filter::Linear, Some(Filter::Nearest)),
        Some(MinFilter::NearestMipmapLinear) => (Filter::Nearest, Some(Filter::Linear)),
        Some(MinFilter::LinearMipmapLinear) | None => (Filter::Linear, Some(Filter::Linear)),
    };
    Sampler {
        wrap_u: wrap(s.wrap_s()),
        wrap_v: wrap(s.wrap_t()),
        mag,
        min,
        mip,
    }
}

/// `KHR_texture_transform`'s JSON object as a matrix, and the texture coordinate set (its
/// `texCoord` when present, else `tex_coord`): for the normal texture, whose extension the
/// `gltf` crate leaves as raw JSON.
pub(super) fn parse_transform(
    value: &serde_json::Value,
    tex_coord: u32,
) -> Result<(UvTransform, u32), String> {
    let object = value.as_object().ok_or("is not a JSON object")?;
    let number = |key: &str, default: f32| -> Result<f32, String> {
        match object.get(key) {
            None => Ok(default),
            Some(v) => v
                .as_f64()
                .map(|x| x as f32)
                .filter(|x| x.is_finite())
                .ok_or_else(|| format!("`{key}` must be a finite number")),
        }
    };
    let pair = |key: &str, default: f32| -> Result<[f32; 2], String> {
        match object.get(key) {
            None => Ok([default; 2]),
            Some(v) => {
                let items = v
                    .as_array()
                    .filter(|a| a.len() == 2)
                    .ok_or_else(|| format!("`{key}` must be an array of 2 numbers"))?;
                let mut out = [0.0f32; 2];
                for (o, item) in out.iter_mut().zip(items) {
                    *o = item
                        .as_f64()
                        .map(|x| x as f32)
                        .filter(|x| x.is_finite())
                        .ok_or_else(|| format!("`{key}` must hold finite numbers"))?;
                }
                Ok(out)
            }
        }
    };
    let tex_coord = match object.get("texCoord") {
        None => tex_coord,
        Some(v) => v
            .as_u64()
            .and_then(|t| u32::try_from(t).ok())
            .ok_or("`texCoord` must be a non-negative integer")?,
    };
    Ok((
        uv_transform(
            pair("offset", 0.0)?,
            number("rotation", 0.0)?,
            pair("scale", 1.0)?,
        ),
        tex_coord,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn png(width: u32, height: u32) -> Vec<u8> {
        let image = image::RgbaImage::from_pixel(width, height, image::Rgba([10, 20, 30, 255]));
        let mut out = Cursor::new(Vec::new());
        image.write_to(&mut out, image::ImageFormat::Png).unwrap();
        out.into_inner()
    }

    /// PNG's chunk checksum (CRC-32, polynomial 0xEDB88320).
    fn crc32(bytes: &[u8]) -> u32 {
        let mut crc = !0u32;
        for &b in bytes {
            crc ^= u32::from(b);
            for _ in 0..8 {
                crc = if crc & 1 == 1 {
                    (crc >> 1) ^ 0xEDB8_8320
                } else {
                    crc >> 1
                };
            }
        }
        !crc
    }

    #[test]
    fn images_decode_to_rgba8() {
        let image = decode(&png(3, 2), Some("image/png"), u64::MAX).unwrap();
        assert_eq!(image.dimensions(), (3, 2));
        assert_eq!(image.get_pixel(2, 1).0, [10, 20, 30, 255]);
    }

    /// Every class of bad image bytes is a clear error, before a large allocation.
    #[test]
    fn bad_images_are_refused_with_their_reason() {
        let good = png(4, 4);
        let mut truncated = good.clone();
        truncated.truncate(good.len() / 2);
        let mut huge = good.clone();
        // The IHDR width (bytes 16..20) set to 100000: the header claims 100000 x 4.
        huge[16..20].copy_from_slice(&100_000u32.to_be_bytes());
        let crc = crc32(&huge[12..29]);
        huge[29..33].copy_from_slice(&crc.to_be_bytes());
        let gif = b"GIF89a\x01\x00\x01\x00\x00\x00\x00;".to_vec();
        let cases: [(&[u8], Option<&str>, u64, &str); 7] = [
            (b"", None, u64::MAX, "neither a PNG nor a JPEG"),
            (
                b"hello, not an image",
                None,
                u64::MAX,
                "neither a PNG nor a JPEG",
            ),
            (&truncated, None, u64::MAX, "corrupt"),
            (&huge, None, u64::MAX, "sides must be"),
            (&gif, None, u64::MAX, "glTF images are PNG or JPEG"),
            (
                &good,
                Some("image/jpeg"),
                u64::MAX,
                "declares mimeType image/jpeg",
            ),
            (&good, None, 63, "past the"),
        ];
        for (bytes, declared, budget, why) in cases {
            let err = decode(bytes, declared, budget).unwrap_err();
            assert!(err.contains(why), "{why}: {err}");
        }
    }

    #[test]
    fn transforms_parse_and_refuse() {
        let (m, set) = parse_transform(
            &serde_json::json!({"offset": [0.5, 0], "scale": [2, 2], "texCoord": 1}),
            0,
        )
        .unwrap();
        assert_eq!(set, 1);
        assert_eq!(m, [[2.0, 0.0, 0.5], [0.0, 2.0, 0.0]]);
        for bad in [
            serde_json::json!([1, 2]),
            serde_json::json!({"offset": [1]}),
            serde_json::json!({"rotation": "x"}),
            serde_json::json!({"scale": [1e39, 1]}),
            serde_json::json!({"texCoord": -1}),
        ] {
            assert!(parse_transform(&bad, 0).is_err(), "{bad}");
        }
    }
}
