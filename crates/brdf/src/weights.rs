//! Each BRDF's measured shading cost, relative to the others: what `histencil calibrate`
//! measures per BRDF of a set (`brdf_weights` in its costs file) and the adaptive technique
//! weights branching's tax by (`histencil_model::SlotWeights`, once a renderer has put its BRDFs
//! in stencil slots).

use crate::{BrdfId, BrdfSet, MODEL_IDS};

/// Per BRDF id ([`BrdfId::index`]), its full-screen shading time over the mean of the BRDFs
/// measured with it: 1.0 for a BRDF as costly as their mean, and for every BRDF not measured.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BrdfWeights([f32; MODEL_IDS as usize]);

/// Why a costs file's `brdf_weights` were refused: the message names the BRDF.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum WeightsError {
    /// A name the set being lit does not hold: costs measured on another set of BRDFs.
    #[error(
        "`brdf_weights` names `{0}`, which the BRDFs being lit do not have: these costs were \
         calibrated with another set (calibrate again with the same --brdfs)"
    )]
    Unknown(String),
    /// Not a finite, positive number.
    #[error("`brdf_weights.{0}` must be a finite number above 0")]
    Value(String),
}

impl BrdfWeights {
    /// Every BRDF at 1.0.
    pub const UNIFORM: Self = Self([1.0; MODEL_IDS as usize]);

    /// The weights `named` (a BRDF's name, its weight) of `set`'s BRDFs; the others keep 1.0.
    ///
    /// # Errors
    /// [`WeightsError`]: a name `set` does not hold, a weight that is not finite and positive.
    pub fn by_name(set: &BrdfSet, named: &[(String, f64)]) -> Result<Self, WeightsError> {
        let mut out = Self::UNIFORM;
        for (name, weight) in named {
            let id = set
                .by_name(name)
                .ok_or_else(|| WeightsError::Unknown(name.clone()))?;
            if !(weight.is_finite() && *weight > 0.0) {
                return Err(WeightsError::Value(name.clone()));
            }
            out.0[id.index() as usize] = *weight as f32;
        }
        Ok(out)
    }

    /// The weight of `id`.
    pub fn get(&self, id: BrdfId) -> f32 {
        self.0.get(id.index() as usize).copied().unwrap_or(1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_are_read_by_name_and_refused_with_the_name() {
        let set = BrdfSet::new(&[BrdfId::Lambert, BrdfId::Ggx], Vec::new()).unwrap();
        let w =
            BrdfWeights::by_name(&set, &[("ggx".into(), 1.5), ("lambert".into(), 0.5)]).unwrap();
        assert_eq!((w.get(BrdfId::Ggx), w.get(BrdfId::Lambert)), (1.5, 0.5));
        assert_eq!(w.get(BrdfId::KajiyaKay), 1.0);
        let unknown = BrdfWeights::by_name(&set, &[("kajiya_kay".into(), 1.0)]).unwrap_err();
        assert!(unknown.to_string().contains("`kajiya_kay`"), "{unknown}");
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let err = BrdfWeights::by_name(&set, &[("ggx".into(), bad)]).unwrap_err();
            assert_eq!(err, WeightsError::Value("ggx".into()));
        }
    }
}
