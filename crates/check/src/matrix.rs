//! The matrix: which configurations a scene needs, as plain data (no device). A case is one
//! configuration of the lighting (technique, platform backend, flush policy), the engine's
//! preserved stencil pattern, the alpha lighting mode, the depth-stencil format and the
//! resolution, with what it is expected to do.
//!
//! "Model only what a scene needs": the native backend has no hi-stencil, so flush policies are
//! not varied on it; `deferred` is branching on the native backend, so branching is not run
//! there twice; the preserved pattern is only run where the scene's stencil layout leaves its
//! bits free; alpha modes only vary on scenes with alpha entities (elsewhere they draw nothing);
//! the known-wrong configurations run on the one depth format whose depths the CPU simulator
//! reads (it decides whether their failure must show).

use crate::bound::{
    alpha_layers, exact_bound, lights_at_a_point, Accumulation, PixelPath, Tolerance,
};
use histencil_model::FlushPolicy;
use histencil_vk::{AlphaMode, DepthStencilFormat, MixedTiles, Technique, TileSide};
use std::fmt;

/// The engine bits the G-buffer pass writes into the preserved stencil bits: the talk's example
/// of "garbage" a 360-like hi-stencil reads because it has no read mask.
pub const PRESERVED_PATTERN: u8 = 0xA0;

/// Resolutions of every run: a single pixel, an odd size smaller than a hi-stencil tile, and an
/// odd size that leaves partial tiles on both edges.
pub const QUICK_RESOLUTIONS: [(u32, u32); 3] = [(1, 1), (7, 5), (257, 129)];
/// Added by the full run.
pub const FULL_RESOLUTION: (u32, u32) = (1280, 720);
/// Known-wrong cases run only on frames at least this wide and high: in a frame of a few pixels
/// the lost light can lie in a light's faint tail or under a translucent entity, so that the
/// wrong frame is right to the 8-bit step and the case could not tell a blind check from a
/// lucky one.
pub const KNOWN_WRONG_MIN_SIDE: u32 = 64;

/// How the lights are applied.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Lighting {
    Stencil,
    Branching,
    Deferred,
    Adaptive,
    Lut,
    /// Tile classification and one dispatch per BRDF (16x16 tiles, mixed tiles per BRDF); no
    /// stencil, so one configuration, like deferred.
    Tiled,
    /// Bevy's depth ids: one full-screen pass per BRDF selected by depth compare EQUAL, lights
    /// from 16x16 tiles' lists; one configuration, like tiled.
    DepthId,
}

impl Lighting {
    pub const ALL: [Lighting; 7] = [
        Lighting::Stencil,
        Lighting::Branching,
        Lighting::Deferred,
        Lighting::Adaptive,
        Lighting::Lut,
        Lighting::Tiled,
        Lighting::DepthId,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Lighting::Stencil => "stencil",
            Lighting::Branching => "branching",
            Lighting::Deferred => "deferred",
            Lighting::Adaptive => "adaptive",
            Lighting::Lut => "lut",
            Lighting::Tiled => "tiled",
            Lighting::DepthId => "depth-id",
        }
    }
}

/// The platforms, named as `histencil render --backend` names them (one vocabulary, in the
/// renderer's crate).
pub use histencil_vk::Platform;

/// The platforms the matrix runs (the no-zeroing one only as a known-wrong case).
pub const CHECKED: [Platform; 4] = [
    Platform::X360,
    Platform::X360SaveRestore,
    Platform::Ps3,
    Platform::Native,
];

pub fn flush_name(flush: FlushPolicy) -> &'static str {
    match flush {
        FlushPolicy::Auto => "auto",
        FlushPolicy::Always => "always",
        FlushPolicy::Never => "never",
    }
}

pub fn alpha_name(mode: AlphaMode) -> &'static str {
    match mode {
        AlphaMode::Lightmap => "lightmap",
        AlphaMode::Forward => "forward",
        AlphaMode::Probe => "probe",
        AlphaMode::Directional => "directional",
    }
}

/// A configuration the talk documents as wrong: the check must see it fail.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum KnownWrong {
    /// 360-like hi-stencil without a read mask, preserved bits not zeroed: tiles whose pixels
    /// carry engine bits fail the BRDF test and their light is lost.
    PreservedBitsNotZeroed,
    /// No hi-stencil flushes: shade passes read another pass's stale tile state.
    StaleHiStencil,
    /// GFX12's AND/OR tiles compared without the tests' read mask: the engine's preserved bits
    /// contradict the BRDF tests' references and whole tiles of light are rejected.
    AndOrReadMaskIgnored,
}

impl KnownWrong {
    pub fn describe(self) -> &'static str {
        match self {
            KnownWrong::PreservedBitsNotZeroed => {
                "360-like hi-stencil reads the preserved bits it does not zero"
            }
            KnownWrong::StaleHiStencil => "shade passes read stale hi-stencil without flushes",
            KnownWrong::AndOrReadMaskIgnored => {
                "AMD GFX12 AND/OR tiles compared without the read mask reject tiles for the engine bits"
            }
        }
    }
}

/// What a case is held to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Expect {
    /// The forward reference itself: it must render cleanly under validation (and light the
    /// frame somewhere, unless the scene has no lights).
    Reference,
    /// Within the bound derived for its scene and technique ([`SceneNeeds::exact_tolerance`]) of
    /// forward, stencil as the backend promises.
    Exact,
    /// The LUT technique's documented bound against forward.
    Lut,
    /// An approximate alpha mode: exact where no alpha entity covers the frame, its mode's
    /// documented bound over the pixels they cover.
    Alpha,
    /// Must fail the image or stencil judgement, where the simulator says the failure can show.
    Wrong(KnownWrong),
}

/// One configuration of a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Config {
    pub lighting: Lighting,
    pub platform: Platform,
    pub flush: FlushPolicy,
    /// The preserved stencil pattern; 0 for none.
    pub pattern: u8,
    pub alpha: AlphaMode,
}

impl Config {
    /// The renderer's technique for the configuration.
    pub fn technique(&self) -> Technique {
        let (backend, flush) = (self.platform.backend(), self.flush);
        match self.lighting {
            Lighting::Stencil => Technique::Stencil { backend, flush },
            Lighting::Branching => Technique::Branching { backend, flush },
            Lighting::Deferred => Technique::DEFERRED,
            Lighting::Adaptive => Technique::Adaptive { backend, flush },
            Lighting::Lut => Technique::Lut { backend, flush },
            Lighting::Tiled => Technique::Tiled {
                mixed: MixedTiles::PerBrdf,
                side: TileSide::Sixteen,
            },
            Lighting::DepthId => Technique::DepthId {
                side: TileSide::Sixteen,
            },
        }
    }
}

/// One case: a configuration on a depth format at a resolution.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Case {
    /// `None` for the forward reference.
    pub config: Option<Config>,
    pub format: DepthStencilFormat,
    pub width: u32,
    pub height: u32,
    pub expect: Expect,
}

impl Case {
    /// A stable name, unique within a scene, usable as a file name:
    /// `stencil-x360-auto-pA0-forward-d32s8-257x129`, `forward-reference-d32s8-7x5`.
    pub fn name(&self) -> String {
        let format = match self.format {
            DepthStencilFormat::D32S8 => "d32s8",
            DepthStencilFormat::D24S8 => "d24s8",
        };
        let size = format!("{}x{}", self.width, self.height);
        match self.config {
            None => format!("forward-reference-{format}-{size}"),
            Some(c) => {
                let lighting = match c.lighting {
                    Lighting::Deferred => "deferred".to_owned(),
                    Lighting::Tiled | Lighting::DepthId => c.lighting.name().to_owned(),
                    l => format!("{}-{}-{}", l.name(), c.platform.name(), flush_name(c.flush)),
                };
                let pattern = if c.pattern == 0 {
                    "p00".to_owned()
                } else {
                    format!("p{:02X}", c.pattern)
                };
                format!(
                    "{lighting}-{pattern}-{}-{format}-{size}",
                    alpha_name(c.alpha)
                )
            }
        }
    }
}

impl fmt::Display for Case {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.name())
    }
}

/// What the matrix needs to know of a scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SceneNeeds {
    /// The preserved stencil bits its layout leaves (`StencilLayout::preserved_mask`).
    pub preserved_mask: u8,
    pub has_alpha: bool,
    /// The LUT technique can be held to the check's LUT bound on it: no material's parameters
    /// vary per texel (`Material::parameters_vary`), which a table per material cannot follow,
    /// no BRDF is an engine's (its table's error is its function's, which no bound here knows),
    /// and no BRDF has a white part. Tables hold glTF's metallic-roughness (two factors per
    /// entry), but the bound ([`crate::judge::LUT`]) is the talk's models' interpolation error
    /// at the default resolution, and a white specular's error grows as its roughness falls: it
    /// is held to its tables' own predicted error instead (`tests/tests/lut.rs`).
    pub lut: bool,
    /// The most lights whose range can hold one point ([`lights_at_a_point`]): the f16 blends
    /// a light-volume technique can make at one pixel.
    pub lights_at_a_point: u32,
    /// Some opaque surface emits: its pixels' emission is stored before the lights add on.
    pub emissive: bool,
    /// The most alpha-entity layers that can be blended over one pixel ([`alpha_layers`]).
    pub alpha_layers: u32,
}

impl SceneNeeds {
    /// # Errors
    /// When the scene's BRDFs do not fit the stencil (its layout cannot be built).
    pub fn of(scene: &histencil_scene::Scene) -> Result<Self, histencil_model::LayoutError> {
        let brdfs = scene.brdfs_in_use().len().max(1) as u32;
        let layout = histencil_model::StencilLayout::new(brdfs, 0)?;
        Ok(Self {
            preserved_mask: layout.preserved_mask(),
            has_alpha: scene.alpha_entity_count() > 0,
            lut: !scene.objects.iter().any(|o| {
                let brdf = &o.material.brdf;
                o.material.parameters_vary() || brdf.has_white_part() || !brdf.is_tabulable()
            }),
            lights_at_a_point: lights_at_a_point(&scene.lights),
            emissive: scene.objects.iter().any(|o| o.material.emits()),
            alpha_layers: alpha_layers(scene),
        })
    }

    /// The image bound of an exact case of `lighting` on the scene, derived from the f16
    /// roundings its pixels can go through ([`crate::bound`]). Adaptive may light a frame
    /// tiled, which rounds less than its light volumes do.
    pub fn exact_tolerance(&self, lighting: Lighting) -> Tolerance {
        let accumulation = match lighting {
            Lighting::Tiled | Lighting::DepthId => Accumulation::Summed,
            _ => Accumulation::Blended,
        };
        let path = PixelPath {
            lights: self.lights_at_a_point,
            emissive: self.emissive,
            alpha_layers: self.alpha_layers,
            accumulation,
        };
        exact_bound(path.roundings())
    }
}

/// The resolutions of a run.
pub fn resolutions(quick: bool) -> Vec<(u32, u32)> {
    let mut sizes = QUICK_RESOLUTIONS.to_vec();
    if !quick {
        sizes.push(FULL_RESOLUTION);
    }
    sizes
}

/// The lighting configurations every scene needs, with `pattern` and the alpha mode `alpha`.
fn lighting_configs(pattern: u8, alpha: AlphaMode) -> Vec<Config> {
    let mut configs = Vec::new();
    for lighting in Lighting::ALL {
        // None uses stencil or hi-stencil: one configuration on the native backend.
        if matches!(
            lighting,
            Lighting::Deferred | Lighting::Tiled | Lighting::DepthId
        ) {
            configs.push(Config {
                lighting,
                platform: Platform::Native,
                flush: FlushPolicy::Auto,
                pattern,
                alpha,
            });
            continue;
        }
        for platform in CHECKED {
            // Deferred is branching on the native backend.
            if lighting == Lighting::Branching && platform == Platform::Native {
                continue;
            }
            let flushes: &[FlushPolicy] = if platform.has_hi_stencil() {
                &[FlushPolicy::Auto, FlushPolicy::Always]
            } else {
                &[FlushPolicy::Auto]
            };
            for &flush in flushes {
                configs.push(Config {
                    lighting,
                    platform,
                    flush,
                    pattern,
                    alpha,
                });
            }
        }
        // AMD's own hierarchies (modelled), on the talk's technique they cull for.
        if lighting == Lighting::Stencil {
            for platform in [Platform::AmdPretest, Platform::AmdAndOr] {
                configs.push(Config {
                    lighting,
                    platform,
                    flush: FlushPolicy::Auto,
                    pattern,
                    alpha,
                });
            }
        }
    }
    configs
}

/// Every case of one scene on one depth format at one resolution, the forward reference first.
pub fn cases(
    needs: SceneNeeds,
    format: DepthStencilFormat,
    (width, height): (u32, u32),
) -> Vec<Case> {
    let case = |config: Option<Config>, expect| Case {
        config,
        format,
        width,
        height,
        expect,
    };
    let pattern_fits = PRESERVED_PATTERN & !needs.preserved_mask == 0;
    let patterns: &[u8] = if pattern_fits {
        &[0, PRESERVED_PATTERN]
    } else {
        &[0]
    };
    // On scenes with alpha entities the lighting matrix draws them forward-lit, so the whole
    // frame is held exactly; the approximate modes get cases of their own.
    let exact_alpha = if needs.has_alpha {
        AlphaMode::Forward
    } else {
        AlphaMode::Lightmap
    };
    let mut out = vec![case(None, Expect::Reference)];
    for &pattern in patterns {
        for config in lighting_configs(pattern, exact_alpha) {
            if config.lighting == Lighting::Lut && !needs.lut {
                continue;
            }
            let expect = if config.lighting == Lighting::Lut {
                Expect::Lut
            } else {
                Expect::Exact
            };
            out.push(case(Some(config), expect));
        }
    }
    let talk = |platform, flush, pattern, alpha| Config {
        lighting: Lighting::Stencil,
        platform,
        flush,
        pattern,
        alpha,
    };
    if needs.has_alpha {
        for alpha in [
            AlphaMode::Lightmap,
            AlphaMode::Directional,
            AlphaMode::Probe,
        ] {
            let config = talk(Platform::X360, FlushPolicy::Auto, 0, alpha);
            out.push(case(Some(config), Expect::Alpha));
        }
    }
    if format == DepthStencilFormat::D32S8 && width.min(height) >= KNOWN_WRONG_MIN_SIDE {
        let pattern = if pattern_fits { PRESERVED_PATTERN } else { 0 };
        if pattern != 0 {
            let config = talk(
                Platform::X360NoZeroing,
                FlushPolicy::Auto,
                pattern,
                exact_alpha,
            );
            out.push(case(
                Some(config),
                Expect::Wrong(KnownWrong::PreservedBitsNotZeroed),
            ));
            let config = talk(
                Platform::AmdAndOrUnmasked,
                FlushPolicy::Auto,
                pattern,
                exact_alpha,
            );
            out.push(case(
                Some(config),
                Expect::Wrong(KnownWrong::AndOrReadMaskIgnored),
            ));
        }
        for platform in [Platform::Ps3, Platform::X360] {
            let config = talk(platform, FlushPolicy::Never, pattern, exact_alpha);
            out.push(case(
                Some(config),
                Expect::Wrong(KnownWrong::StaleHiStencil),
            ));
        }
    }
    out
}

/// The configuration a known-wrong case breaks: the same frame as the talk says to draw it.
pub fn corrected(config: Config) -> Config {
    Config {
        platform: match config.platform {
            Platform::X360NoZeroing => Platform::X360,
            Platform::AmdAndOrUnmasked => Platform::AmdAndOr,
            p => p,
        },
        flush: FlushPolicy::Auto,
        ..config
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashSet;

    const ROOM: SceneNeeds = SceneNeeds {
        preserved_mask: 0xFC,
        has_alpha: false,
        lut: true,
        lights_at_a_point: 8,
        emissive: false,
        alpha_layers: 0,
    };

    #[test]
    fn names_are_unique_and_file_safe() {
        for needs in [
            ROOM,
            SceneNeeds {
                preserved_mask: 0xF0,
                has_alpha: true,
                alpha_layers: 2,
                ..ROOM
            },
        ] {
            let mut seen = HashSet::new();
            for format in DepthStencilFormat::ALL {
                for size in resolutions(false) {
                    for case in cases(needs, format, size) {
                        let name = case.name();
                        assert!(
                            name.chars().all(|c| c.is_ascii_alphanumeric() || c == '-'),
                            "{name}"
                        );
                        assert!(seen.insert(name.clone()), "{name} twice");
                    }
                }
            }
        }
    }

    #[test]
    fn the_matrix_holds_what_a_scene_needs_and_nothing_else() {
        let room = cases(ROOM, DepthStencilFormat::D32S8, (257, 129));
        // Per pattern: stencil, adaptive, lut 7 each (x360, save-restore, ps3 with two flushes,
        // native with one), branching 6 (not on native), deferred 1, tiled 1, depth-id 1, and
        // stencil on the two AMD platforms.
        let lighting = 3 * 7 + 6 + 1 + 1 + 1 + 2;
        let known_wrong = 4;
        assert_eq!(room.len(), 1 + 2 * lighting + known_wrong);
        assert!(room
            .iter()
            .filter_map(|c| c.config)
            .all(|c| c.alpha == AlphaMode::Lightmap));
        assert!(room
            .iter()
            .filter_map(|c| c.config)
            .all(|c| { c.platform.has_hi_stencil() || c.flush == FlushPolicy::Auto }));
        // No known-wrong cases on D24S8 (the simulator that decides them reads f32 depth), nor
        // at a few pixels.
        let d24 = cases(ROOM, DepthStencilFormat::D24S8, (257, 129));
        assert_eq!(d24.len(), 1 + 2 * lighting);
        let tiny = cases(ROOM, DepthStencilFormat::D32S8, (7, 5));
        assert_eq!(tiny.len(), 1 + 2 * lighting);
        // A layout whose BRDF bits reach bit 5 leaves no room for 0xA0.
        let crowded = SceneNeeds {
            preserved_mask: 0xC0,
            ..ROOM
        };
        let crowded = cases(crowded, DepthStencilFormat::D32S8, (257, 129));
        assert!(crowded
            .iter()
            .filter_map(|c| c.config)
            .all(|c| c.pattern == 0));
        assert_eq!(crowded.len(), 1 + lighting + 2);
        // Alpha scenes: the lighting matrix lit forward (exact), plus lightmap, directional and
        // probe.
        let alpha = SceneNeeds {
            has_alpha: true,
            ..ROOM
        };
        let alpha = cases(alpha, DepthStencilFormat::D32S8, (257, 129));
        assert_eq!(alpha.len(), room.len() + 3);
        // Per-texel BRDF parameters: no LUT cases (7 per pattern), everything else kept.
        let textured = SceneNeeds { lut: false, ..ROOM };
        let textured = cases(textured, DepthStencilFormat::D32S8, (257, 129));
        assert_eq!(textured.len(), room.len() - 2 * 7);
        assert!(textured
            .iter()
            .filter_map(|c| c.config)
            .all(|c| c.lighting != Lighting::Lut));
        let modes: HashSet<_> = alpha
            .iter()
            .filter(|c| c.expect == Expect::Alpha)
            .map(|c| c.config.unwrap().alpha)
            .collect();
        assert_eq!(
            modes,
            HashSet::from([
                AlphaMode::Lightmap,
                AlphaMode::Directional,
                AlphaMode::Probe
            ])
        );
    }

    #[test]
    fn known_wrong_cases_break_one_thing_of_a_correct_case() {
        for case in cases(ROOM, DepthStencilFormat::D32S8, (257, 129)) {
            if let Expect::Wrong(_) = case.expect {
                let config = case.config.unwrap();
                let fixed = corrected(config);
                assert_ne!(fixed, config);
                assert!(
                    cases(ROOM, DepthStencilFormat::D32S8, (257, 129))
                        .iter()
                        .any(|c| c.config == Some(fixed) && c.expect == Expect::Exact),
                    "{case}: its correction is not a case"
                );
            }
        }
    }

    #[test]
    fn every_embedded_scene_has_an_exact_bound_from_its_content() {
        for name in histencil_scene::embedded_names() {
            let scene = histencil_scene::embedded(name).unwrap();
            let needs = SceneNeeds::of(&scene).unwrap();
            assert!(
                needs.lights_at_a_point as usize <= scene.lights.len(),
                "{name}"
            );
            assert!(needs.lights_at_a_point >= 1, "{name}");
            assert_eq!(needs.alpha_layers > 0, needs.has_alpha, "{name}");
            for lighting in Lighting::ALL {
                let t = needs.exact_tolerance(lighting);
                assert!(t.max >= 2 && t.mean >= 1.0, "{name} {lighting:?}");
            }
            // Summing in one kernel rounds less than blending each light.
            let (tiled, stencil) = (
                needs.exact_tolerance(Lighting::Tiled),
                needs.exact_tolerance(Lighting::Stencil),
            );
            assert!(
                tiled.max <= stencil.max && tiled.mean <= stencil.mean,
                "{name}"
            );
        }
    }
}
