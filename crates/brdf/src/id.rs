use std::fmt;
use std::str::FromStr;

/// A shading model. The numeric value ([`BrdfId::index`]) is what the G-buffer stores and what the
/// GLSL `BRDF_*` constants (generated from [`BrdfId::ALL`] and the engine's [`BrdfSet`](crate::BrdfSet)
/// by the shader build) switch on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum BrdfId {
    /// `rho / pi`: the diffuse default.
    Lambert,
    /// The normalized Blinn-Phong lobe `(n + 8) / (8 pi) * max(N.H, 0)^n`.
    BlinnPhong,
    /// Oren-Nayar 1994 with the inter-reflection term.
    OrenNayarFull,
    /// Oren-Nayar's qualitative model.
    OrenNayarQualitative,
    /// Cook-Torrance with GGX D, Smith height-correlated visibility and Schlick Fresnel.
    Ggx,
    /// Kajiya-Kay fibres.
    KajiyaKay,
    /// Penner's pre-integrated skin.
    PennerSkin,
    /// glTF 2.0's metallic-roughness BRDF (the specification's Appendix B): Lambert diffuse
    /// and GGX specular by Fresnel for the dielectric part, base-tinted GGX for the metal part.
    GltfMetalRough,
    /// A BRDF of an engine's own, a GLSL function declared in its [`BrdfSet`](crate::BrdfSet):
    /// id [`ENGINE_FIRST`] + its position among the set's engine BRDFs.
    Engine(EngineBrdf),
}

/// The first id of an engine's BRDFs: the built-ins keep theirs (0 to 7), so a G-buffer written
/// for histencil's BRDFs means the same under any set.
pub const ENGINE_FIRST: u32 = 8;

/// The most engine BRDFs a set holds: the tiled classification maps each model id to a slot in
/// its push constants (`TILED_MODELS` = 24 ids, 116 of the 128 bytes every device has).
pub const MAX_ENGINE_BRDFS: usize = 16;

/// An engine BRDF's identity: its position among its set's engine BRDFs and its name. Two sets
/// that give the same position different names are different BRDFs, so a scene made for one set
/// cannot be lit by another's function in silence.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct EngineBrdf {
    position: u8,
    name: &'static str,
}

impl EngineBrdf {
    /// The `position`-th engine BRDF of a set, named `name` (interned: a process keeps each
    /// distinct name once, however many sets name it).
    pub fn new(position: u8, name: &str) -> Self {
        Self {
            position,
            name: intern(name),
        }
    }

    /// Its position among its set's engine BRDFs.
    pub const fn position(self) -> u8 {
        self.position
    }

    /// Its name, as the manifest gives it.
    pub const fn name(self) -> &'static str {
        self.name
    }
}

/// `name` as a `&'static str`, leaked once per distinct name: engine BRDF names are few and live
/// as long as the sets that name them, which an engine keeps for its lifetime.
fn intern(name: &str) -> &'static str {
    use std::collections::HashSet;
    use std::sync::{Mutex, OnceLock};
    static NAMES: OnceLock<Mutex<HashSet<&'static str>>> = OnceLock::new();
    let mut names = NAMES
        .get_or_init(Default::default)
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    if let Some(known) = names.get(name) {
        return known;
    }
    let leaked: &'static str = Box::leak(name.to_owned().into_boxed_str());
    names.insert(leaked);
    leaked
}

impl BrdfId {
    /// Every BRDF, in index order.
    pub const ALL: [BrdfId; 8] = [
        BrdfId::Lambert,
        BrdfId::BlinnPhong,
        BrdfId::OrenNayarFull,
        BrdfId::OrenNayarQualitative,
        BrdfId::Ggx,
        BrdfId::KajiyaKay,
        BrdfId::PennerSkin,
        BrdfId::GltfMetalRough,
    ];

    /// The stable numeric id used by the G-buffer and the shaders.
    pub const fn index(self) -> u32 {
        match self {
            BrdfId::Lambert => 0,
            BrdfId::BlinnPhong => 1,
            BrdfId::OrenNayarFull => 2,
            BrdfId::OrenNayarQualitative => 3,
            BrdfId::Ggx => 4,
            BrdfId::KajiyaKay => 5,
            BrdfId::PennerSkin => 6,
            BrdfId::GltfMetalRough => 7,
            BrdfId::Engine(e) => ENGINE_FIRST + e.position as u32,
        }
    }

    /// Whether this is one of histencil's own BRDFs, with an f64 reference.
    pub const fn is_builtin(self) -> bool {
        !matches!(self, BrdfId::Engine(_))
    }

    /// The built-in BRDF with numeric id `index`, if any (an engine's ids mean something only
    /// with its set: [`BrdfSet::by_index`](crate::BrdfSet::by_index)).
    pub fn from_index(index: u32) -> Option<BrdfId> {
        BrdfId::ALL.into_iter().find(|b| b.index() == index)
    }

    /// The snake_case name used on the command line, in glTF extras and in CSV files.
    pub const fn name(self) -> &'static str {
        match self {
            BrdfId::Lambert => "lambert",
            BrdfId::BlinnPhong => "blinn_phong",
            BrdfId::OrenNayarFull => "oren_nayar_full",
            BrdfId::OrenNayarQualitative => "oren_nayar_qualitative",
            BrdfId::Ggx => "ggx",
            BrdfId::KajiyaKay => "kajiya_kay",
            BrdfId::PennerSkin => "penner_skin",
            BrdfId::GltfMetalRough => "gltf_metal_rough",
            BrdfId::Engine(e) => e.name,
        }
    }

    /// The name of the GLSL constant holding [`BrdfId::index`]: `BRDF_` and the name in capitals
    /// (an engine BRDF's is `BRDF_ENGINE_` and its name, so it cannot clash with a built-in's).
    pub fn glsl_constant(self) -> String {
        match self {
            BrdfId::Engine(e) => format!("BRDF_ENGINE_{}", e.name.to_uppercase()),
            _ => format!("BRDF_{}", self.name().to_uppercase()),
        }
    }
}

impl fmt::Display for BrdfId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A BRDF name that histencil does not know.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown BRDF `{0}` (known: {names})", names = crate::MODEL_NAMES.join(", "))]
pub struct UnknownBrdf(pub String);

impl FromStr for BrdfId {
    type Err = UnknownBrdf;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        BrdfId::ALL
            .into_iter()
            .find(|b| b.name() == s)
            .ok_or_else(|| UnknownBrdf(s.to_owned()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_indices_are_dense() {
        for (i, b) in BrdfId::ALL.into_iter().enumerate() {
            assert_eq!(b.index() as usize, i);
            assert_eq!(b.name().parse::<BrdfId>().unwrap(), b);
        }
        assert_eq!(BrdfId::BlinnPhong.glsl_constant(), "BRDF_BLINN_PHONG");
        assert!("phong".parse::<BrdfId>().is_err());
        let toon = BrdfId::Engine(EngineBrdf::new(2, "toon"));
        assert_eq!(toon.index(), ENGINE_FIRST + 2);
        assert_eq!(toon.name(), "toon");
        assert_eq!(toon.glsl_constant(), "BRDF_ENGINE_TOON");
        assert!(!toon.is_builtin() && BrdfId::Ggx.is_builtin());
        assert_eq!(BrdfId::from_index(toon.index()), None);
        // Interned: the same name is the same pointer, however often it is made.
        let again = EngineBrdf::new(0, &String::from("toon"));
        assert!(std::ptr::eq(again.name(), toon.name()));
    }
}
