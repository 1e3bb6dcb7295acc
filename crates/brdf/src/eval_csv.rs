//! The `brdf-eval` case file: BRDF evaluations as CSV rows, parsed, evaluated with the f64
//! reference and written back. The GPU half (the GLSL spelling in a compute shader) is the
//! command line's; this half needs no device, so it is fuzzed and tested here.
//!
//! Input columns (by header name; extra columns ignored): `id`, `brdf`, `params` (a JSON
//! object), `N`, `T`, `V`, `L` (vectors as `x;y;z`). A vector the model does not use may be
//! empty. Output: `id,value`, the value `r;g;b` for skin. A bad row is reported with its row
//! number and id, and does not stop the others.

use crate::{Brdf, V3};
use std::io::{Read, Write};

/// Why a case file could not be read at all (a bad row is a [`RowError`] instead).
#[derive(Debug, thiserror::Error)]
pub enum CaseFileError {
    /// The header line could not be read (not CSV, or not UTF-8).
    #[error("reading the CSV header: {0}")]
    Header(csv::Error),
    /// A required column is absent; the message lists the columns the file must have.
    #[error("the CSV has no `{0}` column (columns: id,brdf,params,N,T,V,L)")]
    MissingColumn(&'static str),
    /// The results could not be written.
    #[error("writing the results: {0}")]
    Write(#[from] csv::Error),
}

/// One parsed row: its id, BRDF and directions `[N, T, V, L]`.
#[derive(Debug)]
pub struct Row {
    /// The row's `id` column, echoed in the output so results can be joined to the cases.
    pub id: String,
    /// The model and its parameters from `brdf` and `params`.
    pub brdf: Brdf,
    /// `[N, T, V, L]`; a vector the model does not read and the row left empty is zero.
    pub dirs: [V3<f64>; 4],
}

/// A row that could not be parsed; `row` counts data rows from 1.
#[derive(Debug)]
pub struct RowError {
    /// The data row's number, from 1 (the header not counted).
    pub row: usize,
    /// The row's `id`, empty when the record itself could not be read.
    pub id: String,
    /// What was wrong, in the terms of the file (column and value).
    pub message: String,
}

impl std::fmt::Display for RowError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "row {} (id `{}`): {}", self.row, self.id, self.message)
    }
}

const VECTOR_COLUMNS: [&str; 4] = ["N", "T", "V", "L"];

/// Which of N, T, V, L a model reads.
fn used_vectors(brdf: &Brdf) -> [bool; 4] {
    match brdf {
        Brdf::Lambert { .. } | Brdf::PennerSkin { .. } => [true, false, false, true],
        Brdf::KajiyaKay { .. } => [false, true, true, true],
        _ => [true, false, true, true],
    }
}

fn parse_vector(text: &str) -> std::result::Result<V3<f64>, String> {
    let parts: Vec<&str> = text.split(';').map(str::trim).collect();
    let [x, y, z] = parts[..] else {
        return Err(format!("`{text}` is not a vector `x;y;z`"));
    };
    let mut v = [0.0; 3];
    for (slot, part) in v.iter_mut().zip([x, y, z]) {
        *slot = part
            .parse::<f64>()
            .ok()
            .filter(|c| c.is_finite())
            .ok_or_else(|| format!("`{part}` in `{text}` is not a finite number"))?;
    }
    Ok(v)
}

fn parse_row(
    get: impl Fn(&str) -> Option<String>,
) -> std::result::Result<(Brdf, [V3<f64>; 4]), String> {
    let name = get("brdf").unwrap_or_default();
    let params_text = get("params").unwrap_or_default();
    let params_text = if params_text.trim().is_empty() {
        "{}".to_owned()
    } else {
        params_text
    };
    let params: serde_json::Value = serde_json::from_str(&params_text)
        .map_err(|e| format!("params `{params_text}` is not JSON: {e}"))?;
    let Some(params) = params.as_object() else {
        return Err(format!("params `{params_text}` is not a JSON object"));
    };
    let brdf = Brdf::parse(name.trim(), params).map_err(|e| e.to_string())?;
    let mut dirs = [[0.0; 3]; 4];
    for ((column, used), dir) in VECTOR_COLUMNS
        .iter()
        .zip(used_vectors(&brdf))
        .zip(&mut dirs)
    {
        let text = get(column).unwrap_or_default();
        if text.trim().is_empty() {
            if used {
                return Err(format!("{} needs vector {column}", brdf.name()));
            }
            continue;
        }
        *dir = parse_vector(&text).map_err(|e| format!("{column}: {e}"))?;
        if used && dir.iter().all(|c| *c == 0.0) {
            return Err(format!("{column} is a zero vector"));
        }
    }
    Ok((brdf, dirs))
}

/// Parses every row; a malformed file (no header, missing columns) is an error, a malformed row
/// is reported and skipped.
pub fn parse_cases(input: impl Read) -> Result<(Vec<Row>, Vec<RowError>), CaseFileError> {
    let mut reader = csv::ReaderBuilder::new().flexible(true).from_reader(input);
    let headers = reader.headers().map_err(CaseFileError::Header)?.clone();
    let column = |name: &str| headers.iter().position(|h| h.trim() == name);
    for required in ["id", "brdf", "L"] {
        if column(required).is_none() {
            return Err(CaseFileError::MissingColumn(required));
        }
    }
    let (mut rows, mut errors) = (Vec::new(), Vec::new());
    for (index, record) in reader.records().enumerate() {
        let row = index + 1;
        let record = match record {
            Ok(r) => r,
            Err(e) => {
                errors.push(RowError {
                    row,
                    id: String::new(),
                    message: e.to_string(),
                });
                continue;
            }
        };
        let get = |name: &str| column(name).and_then(|i| record.get(i)).map(str::to_owned);
        let id = get("id").unwrap_or_default();
        match parse_row(get) {
            Ok((brdf, dirs)) => rows.push(Row { id, brdf, dirs }),
            Err(message) => errors.push(RowError { row, id, message }),
        }
    }
    Ok((rows, errors))
}

fn format_value(brdf: &Brdf, value: [f64; 3], as_f32: bool) -> String {
    let one = |x: f64| {
        if as_f32 {
            format!("{}", x as f32)
        } else {
            format!("{x}")
        }
    };
    if brdf.is_rgb() {
        value.map(one).join(";")
    } else {
        one(value[0])
    }
}

/// Writes `id,value` rows.
pub fn write_results(
    out: impl Write,
    rows: &[Row],
    values: &[[f64; 3]],
    as_f32: bool,
) -> Result<(), CaseFileError> {
    let mut writer = csv::Writer::from_writer(out);
    writer.write_record(["id", "value"])?;
    for (row, value) in rows.iter().zip(values) {
        writer.write_record([row.id.as_str(), &format_value(&row.brdf, *value, as_f32)])?;
    }
    writer.flush().map_err(csv::Error::from)?;
    Ok(())
}

/// The f64 reference of every row.
pub fn evaluate_cpu(rows: &[Row]) -> Vec<[f64; 3]> {
    rows.iter().map(|r| r.brdf.reference(r.dirs)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_parse_and_bad_rows_name_themselves() {
        let csv = "id,brdf,params,N,T,V,L,comment\n\
                   a,lambert,\"{\"\"rho\"\": 1}\",0;0;1,,,0;0;1,ignored\n\
                   b,ggx,\"{\"\"alpha\"\": 0.2}\",0;0;1,,0;0;1,0;0.1;1,\n\
                   c,phong,{},0;0;1,,0;0;1,0;0;1,\n\
                   d,lambert,\"{\"\"rho\"\": 1}\",0;0;0,,,0;0;1,\n\
                   e,kajiya_kay,\"{\"\"kd\"\":1,\"\"ks\"\":1,\"\"p\"\":2}\",,1;0;0,0;0;1,0;x;1,\n\
                   f,lambert,\"{\"\"rho\"\": 1}\",0;0;1,,,,\n";
        let (rows, errors) = parse_cases(csv.as_bytes()).unwrap();
        assert_eq!(
            rows.iter().map(|r| r.id.as_str()).collect::<Vec<_>>(),
            ["a", "b"]
        );
        let messages: Vec<String> = errors.iter().map(ToString::to_string).collect();
        assert!(
            messages[0].starts_with("row 3 (id `c`): unknown BRDF `phong`"),
            "{messages:?}"
        );
        assert!(messages[1].contains("N is a zero vector"), "{messages:?}");
        assert!(messages[2].contains("`x` in `0;x;1`"), "{messages:?}");
        assert!(messages[3].contains("needs vector L"), "{messages:?}");
        let values = evaluate_cpu(&rows);
        assert!((values[0][0] - std::f64::consts::FRAC_1_PI).abs() < 1e-15);
        let mut out = Vec::new();
        write_results(&mut out, &rows, &values, false).unwrap();
        assert!(String::from_utf8(out)
            .unwrap()
            .starts_with("id,value\na,0.3183098861837907\n"));
    }

    #[test]
    fn a_file_without_the_columns_is_an_error() {
        let err = parse_cases("x,y\n1,2\n".as_bytes()).unwrap_err();
        assert!(err.to_string().contains("no `id` column"));
    }
}
