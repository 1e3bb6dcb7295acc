use std::fmt;
use std::str::FromStr;

/// A shading model. The numeric value ([`BrdfId::index`]) is what the G-buffer stores and what the
/// GLSL `BRDF_*` constants (generated from [`BrdfId::ALL`] by the shader build) switch on.
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
        self as u32
    }

    /// The BRDF with numeric id `index`, if any.
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
        }
    }

    /// The name of the GLSL constant holding [`BrdfId::index`].
    pub fn glsl_constant(self) -> String {
        format!("BRDF_{}", self.name().to_uppercase())
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
    }
}
