//! The costs file a calibration writes and the adaptive technique reads: a JSON object whose top
//! level holds the four costs by name, with an optional `intervals` object of `[lo, hi]` pairs,
//! and optionally the tiled technique's costs as `tiled` (the same shape: `classify_ms`,
//! `shade_ms` and optional `intervals`), which may hold the depth-id technique's as `depth_id`
//! (`per_brdf_ms`, `shade_ms`, optional `intervals`).
//! Each BRDF's relative shading cost may come as `brdf_weights` (`{"<name>": weight}`, read by
//! [`brdf_weights_from_json`]: names are the lighting's to resolve). Other keys (the device, the
//! settings, the measurements) are the writer's and are ignored.
//! Reading needs no device, so it is fuzzed and tested here.

use crate::{CostModel, DepthIdCosts, TiledCosts};
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
        let (v, interval) = costs_and_intervals(&value, COST_FIELDS, "")?;
        let tiled = match value.get("tiled") {
            None | Some(Value::Null) => None,
            Some(t) => {
                let (v, interval) = costs_and_intervals(t, TILED_FIELDS, "tiled.")?;
                let depth_id = match t.get("depth_id") {
                    None | Some(Value::Null) => None,
                    Some(d) => {
                        let path = "tiled.depth_id.";
                        let (v, interval) = costs_and_intervals(d, DEPTH_ID_FIELDS, path)?;
                        Some(DepthIdCosts {
                            per_brdf_ms: v[0],
                            shade_ms: v[1],
                            interval,
                        })
                    }
                };
                Some(TiledCosts {
                    classify_ms: v[0],
                    shade_ms: v[1],
                    interval,
                    depth_id,
                })
            }
        };
        Ok(CostModel {
            pass_overhead_ms: v[0],
            stencil_per_brdf_ms: v[1],
            branch_tax_per_brdf_ms: v[2],
            shade_ms: v[3],
            interval,
            tiled,
            slot_weights: None,
        })
    }
}

/// The costs file's `brdf_weights` (a BRDF's name, its shading cost relative to the others), in
/// the file's order; empty when it has none. Each weight finite and above 0.
pub fn brdf_weights_from_json(text: &str) -> Result<Vec<(String, f64)>, CostsError> {
    let value: Value =
        serde_json::from_str(text).map_err(|e| CostsError(format!("not JSON: {e}")))?;
    let Some(weights) = value.get("brdf_weights").filter(|v| !v.is_null()) else {
        return Ok(Vec::new());
    };
    let weights = weights
        .as_object()
        .ok_or_else(|| CostsError("`brdf_weights` must be an object of BRDF names".into()))?;
    weights
        .iter()
        .map(|(name, w)| {
            w.as_f64()
                .filter(|w| w.is_finite() && *w > 0.0)
                .map(|w| (name.clone(), w))
                .ok_or_else(|| {
                    CostsError(format!(
                        "`brdf_weights.{name}` must be a finite number above 0"
                    ))
                })
        })
        .collect()
}

/// The tiled costs' names in the file's `tiled` object.
pub const TILED_FIELDS: [&str; 2] = ["classify_ms", "shade_ms"];

/// The depth-id costs' names in the `tiled` object's `depth_id` object.
pub const DEPTH_ID_FIELDS: [&str; 2] = ["per_brdf_ms", "shade_ms"];

impl DepthIdCosts {
    /// The two costs in [`DEPTH_ID_FIELDS`] order.
    pub fn fields(&self) -> [f64; 2] {
        [self.per_brdf_ms, self.shade_ms]
    }
}

impl TiledCosts {
    /// The two costs in [`TILED_FIELDS`] order.
    pub fn fields(&self) -> [f64; 2] {
        [self.classify_ms, self.shade_ms]
    }
}

/// The costs `names` of `value`, each finite and non-negative, and their `intervals` when
/// present; `path` prefixes the names in messages.
#[allow(clippy::type_complexity)]
fn costs_and_intervals<const N: usize>(
    value: &Value,
    names: [&str; N],
    path: &str,
) -> Result<([f64; N], Option<[(f64, f64); N]>), CostsError> {
    let mut v = [0.0; N];
    for (out, name) in v.iter_mut().zip(names) {
        *out = value
            .get(name)
            .and_then(Value::as_f64)
            .filter(|x| x.is_finite() && *x >= 0.0)
            .ok_or_else(|| {
                CostsError(format!(
                    "`{path}{name}` must be a finite, non-negative number"
                ))
            })?;
    }
    let interval = match value.get("intervals") {
        None | Some(Value::Null) => None,
        Some(iv) => {
            let mut out = [(0.0, 0.0); N];
            for ((slot, name), cost) in out.iter_mut().zip(names).zip(v) {
                *slot = iv
                    .get(name)
                    .and_then(Value::as_array)
                    .filter(|p| p.len() == 2)
                    .and_then(|p| Some((p[0].as_f64()?, p[1].as_f64()?)))
                    .filter(|(lo, hi)| {
                        lo.is_finite() && hi.is_finite() && 0.0 <= *lo && *lo <= cost && cost <= *hi
                    })
                    .ok_or_else(|| {
                        CostsError(format!(
                            "`{path}intervals.{name}` must be [lo, hi], finite, with \
                             0 <= lo <= {name} <= hi"
                        ))
                    })?;
            }
            Some(out)
        }
    };
    Ok((v, interval))
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

    #[test]
    fn tiled_costs_are_optional_and_checked_like_the_others() {
        let base = r#""pass_overhead_ms": 0, "stencil_per_brdf_ms": 1, "branch_tax_per_brdf_ms": 2, "shade_ms": 3"#;
        let read = |tiled: &str| CostModel::from_json(&format!("{{{base}, \"tiled\": {tiled}}}"));
        let costs = read(r#"{"classify_ms": 0.5, "shade_ms": 4, "intervals": {"classify_ms": [0.4, 0.6], "shade_ms": [3, 5]}}"#).unwrap();
        let tiled = costs.tiled.unwrap();
        assert_eq!(tiled.fields(), [0.5, 4.0]);
        assert_eq!(tiled.interval, Some([(0.4, 0.6), (3.0, 5.0)]));
        assert_eq!(read("null").unwrap().tiled, None);
        assert_eq!(tiled.depth_id, None);
        let with_ids = read(
            r#"{"classify_ms": 0.5, "shade_ms": 4, "depth_id": {"per_brdf_ms": 0.2, "shade_ms": 3}}"#,
        );
        let ids = with_ids.unwrap().tiled.unwrap().depth_id.unwrap();
        assert_eq!((ids.fields(), ids.interval), ([0.2, 3.0], None));
        for (tiled, needle) in [
            ("{}", "`tiled.classify_ms`"),
            (r#"{"classify_ms": 1, "shade_ms": -2}"#, "`tiled.shade_ms`"),
            (
                r#"{"classify_ms": 1, "shade_ms": 2, "intervals": {"classify_ms": [2, 3]}}"#,
                "`tiled.intervals.classify_ms`",
            ),
            (
                r#"{"classify_ms": 1, "shade_ms": 2, "depth_id": {"per_brdf_ms": "x"}}"#,
                "`tiled.depth_id.per_brdf_ms`",
            ),
        ] {
            let err = read(tiled).unwrap_err().to_string();
            assert!(err.contains(needle), "{tiled}: {err}");
        }
    }
}
