//! The costs file a calibration writes and the adaptive technique reads: a JSON object whose top
//! level holds the four costs by name, with an optional `intervals` object of `[lo, hi]` pairs.
//! Other keys (the device, the settings, the measurements) are the writer's and are ignored.
//! Reading needs no device, so it is fuzzed and tested here.

use crate::CostModel;
use serde_json::Value;

/// The costs' names in the file, in [`CostModel::fields`] order.
pub const COST_FIELDS: [&str; 4] = [
    "pass_overhead_ms",
    "stencil_per_brdf_ms",
    "branch_tax_per_brdf_ms",
    "shade_ms",
];

/// Why a costs file was refused; the message names the field.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct CostsError(String);

impl CostModel {
    /// The four costs in [`COST_FIELDS`] order.
    pub fn fields(&self) -> [f64; 4] {
        [
            self.pass_overhead_ms,
            self.stencil_per_brdf_ms,
            self.branch_tax_per_brdf_ms,
            self.shade_ms,
        ]
    }

    /// Reads a costs file's text: each cost finite and non-negative; each interval, when
    /// `intervals` is present, a finite `[lo, hi]` with `0 <= lo <= cost <= hi`. Costs written
    /// by hand may leave the intervals out.
    pub fn from_json(text: &str) -> Result<CostModel, CostsError> {
        let value: Value =
            serde_json::from_str(text).map_err(|e| CostsError(format!("not JSON: {e}")))?;
        let mut v = [0.0; 4];
        for (out, name) in v.iter_mut().zip(COST_FIELDS) {
            *out = value
                .get(name)
                .and_then(Value::as_f64)
                .filter(|x| x.is_finite() && *x >= 0.0)
                .ok_or_else(|| {
                    CostsError(format!("`{name}` must be a finite, non-negative number"))
                })?;
        }
        let interval = match value.get("intervals") {
            None | Some(Value::Null) => None,
            Some(iv) => {
                let mut out = [(0.0, 0.0); 4];
                for ((slot, name), cost) in out.iter_mut().zip(COST_FIELDS).zip(v) {
                    *slot = iv
                        .get(name)
                        .and_then(Value::as_array)
                        .filter(|p| p.len() == 2)
                        .and_then(|p| Some((p[0].as_f64()?, p[1].as_f64()?)))
                        .filter(|(lo, hi)| {
                            lo.is_finite()
                                && hi.is_finite()
                                && 0.0 <= *lo
                                && *lo <= cost
                                && cost <= *hi
                        })
                        .ok_or_else(|| {
                            CostsError(format!(
                                "`intervals.{name}` must be [lo, hi], finite, with \
                                 0 <= lo <= {name} <= hi"
                            ))
                        })?;
                }
                Some(out)
            }
        };
        Ok(CostModel {
            pass_overhead_ms: v[0],
            stencil_per_brdf_ms: v[1],
            branch_tax_per_brdf_ms: v[2],
            shade_ms: v[3],
            interval,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hand_written_costs_read_and_bad_ones_name_their_field() {
        let costs = CostModel::from_json(
            r#"{"pass_overhead_ms": 0, "stencil_per_brdf_ms": 1, "branch_tax_per_brdf_ms": 2,
                "shade_ms": 3, "device": "ignored"}"#,
        )
        .unwrap();
        assert_eq!(costs.fields(), [0.0, 1.0, 2.0, 3.0]);
        assert_eq!(costs.interval, None);
        for (text, needle) in [
            ("{", "not JSON"),
            ("[]", "`pass_overhead_ms`"),
            (r#"{"pass_overhead_ms": -1}"#, "`pass_overhead_ms`"),
            (r#"{"pass_overhead_ms": 1e999}"#, "not JSON"),
            (
                r#"{"pass_overhead_ms": 0, "stencil_per_brdf_ms": 1, "branch_tax_per_brdf_ms": 2,
                    "shade_ms": 3, "intervals": {"pass_overhead_ms": [0, 1]}}"#,
                "intervals.stencil_per_brdf_ms",
            ),
        ] {
            let err = CostModel::from_json(text).unwrap_err().to_string();
            assert!(err.contains(needle), "{text}: {err}");
        }
    }
}
