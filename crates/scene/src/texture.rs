//! Textures as plain data: decoded images, how a material reads them (texture coordinate set,
//! `KHR_texture_transform`, sampler), and how a metallic-roughness texel modulates each BRDF.
//!
//! The renderer's G-buffer pass and its forward reference read a material's maps through one
//! GLSL function (`crates/vk/shaders/include/material.glsl`), so the surface every technique lights is the
//! surface forward lights: textures change what is shaded, never the exactness of a technique.

use histencil_brdf::Brdf;

/// An image as decoded: straight (not premultiplied) 8-bit RGBA, rows top to bottom. Whether
/// its values are sRGB or linear is decided by the map that reads it ([`MaterialMaps`]).
#[derive(Clone, Debug, PartialEq)]
pub struct TextureImage {
    /// Where it came from (the glTF image's name or URI), for error messages and object names.
    pub name: String,
    /// Width in texels, 1 to [`MAX_TEXTURE_SIDE`].
    pub width: u32,
    /// Height in texels, 1 to [`MAX_TEXTURE_SIDE`].
    pub height: u32,
    /// `width * height * 4` bytes.
    pub rgba8: Vec<u8>,
}

/// The largest image side accepted: Vulkan guarantees 4096 (`maxImageDimension2D`); 16384 is
/// what desktop GPUs and lavapipe give, and the renderer checks the device's own limit.
pub const MAX_TEXTURE_SIDE: u32 = 16384;

impl TextureImage {
    /// What is wrong with the image, if anything: a zero or oversized side, or a pixel buffer
    /// of the wrong length.
    pub fn problem(&self) -> Option<String> {
        let (w, h) = (self.width, self.height);
        if let Some(problem) = side_problem(w, h) {
            return Some(problem);
        }
        let expected = u64::from(w) * u64::from(h) * 4;
        (self.rgba8.len() as u64 != expected).then(|| {
            format!(
                "holds {} bytes, {w}x{h} RGBA8 needs {expected}",
                self.rgba8.len()
            )
        })
    }
}

/// What is wrong with an image of `width` x `height` texels, if anything: a zero side or one
/// over [`MAX_TEXTURE_SIDE`]. The importer asks before it decodes, the scene after.
pub(crate) fn side_problem(width: u32, height: u32) -> Option<String> {
    let ok = |s: u32| (1..=MAX_TEXTURE_SIDE).contains(&s);
    (!ok(width) || !ok(height))
        .then(|| format!("is {width}x{height}; sides must be 1 to {MAX_TEXTURE_SIDE} texels"))
}

/// How texture coordinates outside `[0, 1]` wrap (glTF's `wrapS` / `wrapT`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Wrap {
    /// Tiles the image (glTF's default).
    #[default]
    Repeat,
    /// Tiles the image, mirrored every other tile.
    MirroredRepeat,
    /// Repeats the edge texels.
    ClampToEdge,
}

/// Texel filtering (glTF's `magFilter` / `minFilter`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Filter {
    /// The nearest texel.
    Nearest,
    /// Bilinear between the four nearest texels (the default).
    #[default]
    Linear,
}

/// A sampler as glTF describes it. The default (what glTF leaves to the renderer when the
/// sampler or a filter is absent) is repeat and trilinear.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Sampler {
    /// Wrapping along u.
    pub wrap_u: Wrap,
    /// Wrapping along v.
    pub wrap_v: Wrap,
    /// Filtering when the image is magnified.
    pub mag: Filter,
    /// Filtering within a mip level when it is minified.
    pub min: Filter,
    /// Between mip levels; `None` reads only the full-resolution level (glTF's `NEAREST` and
    /// `LINEAR` minification filters).
    pub mip: Option<Filter>,
}

impl Default for Sampler {
    fn default() -> Self {
        Self {
            wrap_u: Wrap::Repeat,
            wrap_v: Wrap::Repeat,
            mag: Filter::Linear,
            min: Filter::Linear,
            mip: Some(Filter::Linear),
        }
    }
}

/// A 2x3 affine map of texture coordinates, rows `(a, b, c)`: `u' = a u + b v + c`.
pub type UvTransform = [[f32; 3]; 2];

/// The identity [`UvTransform`].
pub const UV_IDENTITY: UvTransform = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

/// `KHR_texture_transform`'s `offset`, `rotation` (radians, counter-clockwise in uv) and
/// `scale` as the matrix the extension defines, `T * R * S`.
pub fn uv_transform(offset: [f32; 2], rotation: f32, scale: [f32; 2]) -> UvTransform {
    let (s, c) = rotation.sin_cos();
    [
        [c * scale[0], s * scale[1], offset[0]],
        [-s * scale[0], c * scale[1], offset[1]],
    ]
}

/// One map of a material: which image, read through which sampler, at which texture
/// coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureRef {
    /// Index into [`crate::Scene::images`].
    pub image: u32,
    /// How the texels are wrapped and filtered.
    pub sampler: Sampler,
    /// 0 reads [`crate::Vertex::uv`] (`TEXCOORD_0`), 1 [`crate::Vertex::uv1`].
    pub texcoord: u32,
    /// Applied to the texture coordinates before sampling (`KHR_texture_transform`).
    pub transform: UvTransform,
}

impl TextureRef {
    /// `image` read at `TEXCOORD_0`, untransformed, with the default sampler.
    pub fn new(image: u32) -> Self {
        Self {
            image,
            sampler: Sampler::default(),
            texcoord: 0,
            transform: UV_IDENTITY,
        }
    }
}

/// A material's texture maps, glTF's metallic-roughness set. Each is optional; absent, it
/// changes nothing.
///
/// - `base_color` (sRGB): its RGB multiplies the material's tint, as does the vertex colour.
///   Its alpha is not read by opaque surfaces.
/// - `normal` (linear, tangent space, glTF's convention: +Y along +v): bends the shading normal,
///   `normalize((2 t - 1) * (scale, scale, 1))` in the frame of the vertex tangent, bitangent
///   `cross(N, T) * w` and normal. Needs tangents, which the importer reads or generates.
/// - `metallic_roughness` (linear): green is roughness, blue metalness, each a factor in
///   `[0, 1]` on the BRDF's parameters as [`textured_brdf`] says.
/// - `emissive` (sRGB): its RGB multiplies the material's emitted radiance
///   ([`crate::Material::emissive`]), which is added once per pixel, not per light.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct MaterialMaps {
    /// sRGB; multiplies the tint.
    pub base_color: Option<TextureRef>,
    /// Linear, tangent space; bends the shading normal.
    pub normal: Option<TextureRef>,
    /// glTF's `normalTexture.scale`.
    pub normal_scale: f32,
    /// Linear; green scales roughness, blue the metal share ([`textured_brdf`]).
    pub metallic_roughness: Option<TextureRef>,
    /// sRGB; multiplies the emitted radiance.
    pub emissive: Option<TextureRef>,
    /// glTF's `alphaMode: MASK`: a fragment whose base-colour texel alpha times `COLOR_0`'s
    /// alpha is below this is discarded (in the G-buffer, forward and emissive passes alike).
    /// It is `alphaCutoff / baseColorFactor.a`, so the factor is applied without storing it;
    /// `None` for opaque surfaces.
    pub alpha_cutoff: Option<f32>,
}

/// How many maps a material has ([`MaterialMaps::refs`]).
pub const MAP_COUNT: usize = 4;

impl MaterialMaps {
    /// The maps, in the order the GPU binds them (base colour, normal, metallic-roughness,
    /// emissive).
    pub fn refs(&self) -> [Option<TextureRef>; MAP_COUNT] {
        [
            self.base_color,
            self.normal,
            self.metallic_roughness,
            self.emissive,
        ]
    }

    /// Whether map `i` of [`MaterialMaps::refs`] holds colour, stored as sRGB.
    pub fn is_srgb(i: usize) -> bool {
        i == 0 || i == 3
    }

    /// Whether the material has no maps at all.
    pub fn is_empty(&self) -> bool {
        self.refs().iter().all(Option::is_none)
    }
}

/// Blinn-Phong's exponent is held below this when a roughness texel sharpens it (the top of
/// its parameter range).
const MAX_TEXTURED_EXPONENT: f64 = 1e4;

/// The BRDF a metallic-roughness texel makes of `brdf`: `roughness` is the texel's green, a
/// factor on the model's roughness, `metallic` its blue, a factor on the model's metal share.
/// The BRDF model never changes (it is the stencil's BRDF id), only its parameters:
///
/// - GGX: `alpha * roughness^2` (alpha is perceptual roughness squared), and
///   `f0 = 0.04 + (f0 - 0.04) * metallic` where `f0` exceeds a dielectric's 0.04 (the metal
///   share of `0.04 + 0.96 * metallic`, the PBR fallback's reflectance).
/// - Blinn-Phong: the exponent of the Beckmann-equivalent roughness scaled the same way,
///   `(n + 2) / roughness^4 - 2` (from `n = 2 / alpha^2 - 2`), at most 1e4.
/// - Oren-Nayar (both forms): `sigma * roughness`.
/// - glTF's metallic-roughness: as glTF defines it, `alpha * roughness^2` and
///   `metallic * metallic texel`.
/// - Lambert, Kajiya-Kay, Penner skin: unchanged (no roughness; fibre and skin parameters are
///   not what the texture describes).
///
/// The GLSL spelling is `material_textured_params` in `crates/vk/shaders/include/material.glsl`.
pub fn textured_brdf(brdf: Brdf, roughness: f32, metallic: f32) -> Brdf {
    let r = f64::from(roughness).clamp(0.0, 1.0);
    let m = f64::from(metallic).clamp(0.0, 1.0);
    match brdf {
        Brdf::Ggx { alpha, f0, f90 } => Brdf::Ggx {
            alpha: alpha * r * r,
            f0: f0 - (f0 - 0.04).max(0.0) * (1.0 - m),
            f90,
        },
        // A white texel (the common case) leaves the exponent bit for bit; the sum below would
        // round it.
        Brdf::BlinnPhong { exponent } if r < 1.0 => {
            let r4 = (r * r) * (r * r);
            let sharpened = if r4 > 0.0 {
                (exponent + 2.0) / r4 - 2.0
            } else {
                MAX_TEXTURED_EXPONENT
            };
            Brdf::BlinnPhong {
                exponent: sharpened.max(exponent).min(MAX_TEXTURED_EXPONENT),
            }
        }
        Brdf::OrenNayarFull { rho, sigma } => Brdf::OrenNayarFull {
            rho,
            sigma: sigma * r,
        },
        Brdf::OrenNayarQualitative { rho, sigma } => Brdf::OrenNayarQualitative {
            rho,
            sigma: sigma * r,
        },
        // glTF's own rule: the texel's green times roughnessFactor (alpha is its square), its
        // blue times metallicFactor.
        Brdf::GltfMetalRough { alpha, metallic } => Brdf::GltfMetalRough {
            alpha: alpha * r * r,
            metallic: metallic * m,
        },
        other => other,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_white_texel_changes_nothing() {
        let models = [
            Brdf::Ggx {
                alpha: 0.3,
                f0: 0.5,
                f90: 1.0,
            },
            Brdf::BlinnPhong { exponent: 40.0 },
            Brdf::OrenNayarFull {
                rho: 0.8,
                sigma: 0.4,
            },
            Brdf::Lambert { rho: 1.0 },
        ];
        for brdf in models {
            assert_eq!(textured_brdf(brdf, 1.0, 1.0), brdf);
        }
    }

    #[test]
    fn the_texel_scales_roughness_and_metal_share() {
        let ggx = Brdf::Ggx {
            alpha: 0.64,
            f0: 1.0,
            f90: 1.0,
        };
        let Brdf::Ggx { alpha, f0, .. } = textured_brdf(ggx, 0.5, 0.0) else {
            unreachable!()
        };
        assert!((alpha - 0.16).abs() < 1e-12 && (f0 - 0.04).abs() < 1e-12);
        // Below a dielectric's 0.04 there is no metal share to take away.
        let dull = Brdf::Ggx {
            alpha: 0.5,
            f0: 0.02,
            f90: 1.0,
        };
        assert!(matches!(textured_brdf(dull, 1.0, 0.0), Brdf::Ggx { f0, .. } if f0 == 0.02));
        let Brdf::BlinnPhong { exponent } =
            textured_brdf(Brdf::BlinnPhong { exponent: 30.0 }, 0.5, 1.0)
        else {
            unreachable!()
        };
        assert_eq!(exponent, 32.0 * 16.0 - 2.0);
        let Brdf::BlinnPhong { exponent } =
            textured_brdf(Brdf::BlinnPhong { exponent: 30.0 }, 0.0, 1.0)
        else {
            unreachable!()
        };
        assert_eq!(exponent, 1e4);
    }

    #[test]
    fn textured_parameters_stay_in_their_ranges() {
        let models = [
            Brdf::Ggx {
                alpha: 1.0,
                f0: 1.0,
                f90: 1.0,
            },
            Brdf::BlinnPhong { exponent: 1e4 },
            Brdf::BlinnPhong { exponent: 0.0 },
            Brdf::OrenNayarQualitative {
                rho: 1.0,
                sigma: std::f64::consts::FRAC_PI_2,
            },
        ];
        for brdf in models {
            for r in [0.0, 1e-3, 0.3, 1.0, 2.0, -1.0] {
                for m in [0.0, 0.5, 1.0] {
                    let t = textured_brdf(brdf, r, m);
                    assert!(t.check().is_ok(), "{brdf:?} at {r}, {m}: {t:?}");
                }
            }
        }
    }

    #[test]
    fn the_transform_is_translation_rotation_scale() {
        let m = uv_transform([0.5, 0.25], std::f32::consts::FRAC_PI_2, [2.0, 3.0]);
        let apply = |u: f32, v: f32| {
            [
                m[0][0] * u + m[0][1] * v + m[0][2],
                m[1][0] * u + m[1][1] * v + m[1][2],
            ]
        };
        // Scale (1, 0) to (2, 0), rotate by the extension's matrix to (0, -2), translate.
        let [u, v] = apply(1.0, 0.0);
        assert!(
            (u - 0.5).abs() < 1e-6 && (v - -1.75).abs() < 1e-6,
            "{u} {v}"
        );
        assert_eq!(uv_transform([0.0; 2], 0.0, [1.0; 2]), UV_IDENTITY);
    }

    #[test]
    fn bad_images_are_named() {
        let image = |width, height, len| TextureImage {
            name: "x".into(),
            width,
            height,
            rgba8: vec![0; len],
        };
        assert!(image(2, 2, 16).problem().is_none());
        assert!(image(0, 2, 0).problem().unwrap().contains("0x2"));
        assert!(image(2, 2, 15).problem().unwrap().contains("needs 16"));
        assert!(image(MAX_TEXTURE_SIDE + 1, 1, 0).problem().is_some());
    }
}
