//! Readers for BSDF measurement files.
//!
//! Two CSV layouts, in the conventions of docs/design.md section 2 (`f` without the
//! cosine factor, `wi` toward the light, `wo` toward the viewer):
//!
//! * **in-plane**: columns `kind,theta_i_deg,theta_o_deg` (the layout of
//!   `reference/devA.csv`): `kind` is `R` (viewer above the sheet) or `T`
//!   (viewer below, `theta_o` measured from `-z`); `theta_o` is signed, positive
//!   on the light's side. Directions come from
//!   [`paperbsdf_core::geometry::in_plane_directions`].
//! * **general**: columns `wi_x,wi_y,wi_z,wo_x,wo_y,wo_z` (unit vectors in the
//!   local frame); the kind is `R` when both directions are on the same side.
//!
//! The value is one column `f` or three columns `r,g,b`; an optional standard
//! error is one column `stderr` (all channels) or `stderr_r,stderr_g,stderr_b`;
//! instead of it, a column `weight` (>= 0, all channels) gives each point its
//! weight in the fit directly: it is stored as the standard error
//! `(f + e) / sqrt(weight)` (`e` = [`LOG_OFFSET`]) that has that weight in the
//! objective of `paperbsdf_fit::objective::weight` (weights above
//! `1 / SIGMA_FLOOR^2` = 1e6 count as 1e6), so weight 0 leaves a point out and
//! weight 4 counts it four times. Other columns (e.g. `samples`) are ignored.
//! Lines starting with `#` are comments; two header comments are understood:
//! `# params: {JSON}` (the parameters the data were made with; its `d` is the
//! thickness) and `# thickness: D` (mm). The rows are read with the `csv`
//! crate (fields trimmed, quoted fields allowed). Every error names the file,
//! the line and the column.

use crate::text::{csv_records, CsvRecord};
use crate::DataError;
use paperbsdf_core::geometry::in_plane_directions;
use paperbsdf_core::{DVec3, Rgb};

/// The offset `e` (1/sr) of the log-space error `ln((model + e) / (meas + e))`
/// of the fit, used here to turn a `weight` column into a standard error; the
/// fitter's `paperbsdf_fit::objective::LOG_OFFSET` is the same constant.
pub const LOG_OFFSET: f64 = 1e-3;

/// Reflection or transmission.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize)]
pub enum Kind {
    /// The viewer is on the light's side of the sheet (`kind = R`).
    R,
    /// The viewer is on the other side (`kind = T`).
    T,
}

impl Kind {
    /// `"R"` or `"T"`.
    pub fn name(self) -> &'static str {
        match self {
            Kind::R => "R",
            Kind::T => "T",
        }
    }
}

/// One measured BSDF value.
#[derive(Clone, Debug, PartialEq)]
pub struct Point {
    /// Reflection or transmission.
    pub kind: Kind,
    /// Polar angle of the light, degrees (in-plane files: as written; general
    /// files: the angle of `wi` from the normal of the face it is above).
    pub theta_i: f64,
    /// Signed viewing angle, degrees (in-plane files only).
    pub theta_o: Option<f64>,
    /// Direction toward the light (unit, local frame).
    pub wi: DVec3,
    /// Direction toward the viewer (unit, local frame).
    pub wo: DVec3,
    /// The measured `f` (three equal channels for a one-channel file).
    pub f: Rgb,
    /// Standard error of `f`, when given.
    pub stderr: Option<Rgb>,
    /// 1-based line in the file.
    pub line: usize,
}

/// The contents of one measurement file.
#[derive(Clone, Debug)]
pub struct Measurement {
    /// The file it was read from.
    pub origin: String,
    /// The values, in file order.
    pub points: Vec<Point>,
    /// Whether the file has `r,g,b` columns (else one `f` column).
    pub is_rgb: bool,
    /// The `# params: {...}` header, when present.
    pub params_header: Option<serde_json::Value>,
    /// Thickness in mm from the `# thickness:` header or the `d` of `# params:`.
    pub thickness: Option<f64>,
    /// Whether the file is in the in-plane layout (else general directions).
    pub in_plane: bool,
}

impl Measurement {
    /// The distinct incident angles (degrees), sorted.
    pub fn theta_i_values(&self) -> Vec<f64> {
        let mut v: Vec<f64> = self.points.iter().map(|p| p.theta_i).collect();
        v.sort_by(|a, b| a.partial_cmp(b).unwrap());
        v.dedup_by(|a, b| (*a - *b).abs() < 1e-6);
        v
    }
}

/// Reads a measurement file (see the module doc).
pub fn read_measurement(path: &str) -> Result<Measurement, DataError> {
    let text = crate::text::read_text(path)?;
    parse_measurement(&text, path)
}

/// An error at `line`, `column` of `file`.
fn at(file: &str, line: usize, column: usize, message: String) -> DataError {
    DataError::Syntax {
        file: file.to_string(),
        line,
        column,
        message,
    }
}

/// What the header comments (`# params:`, `# thickness`) of a file say.
#[derive(Default)]
struct Headers {
    params: Option<serde_json::Value>,
    thickness: Option<f64>,
}

impl Headers {
    /// Reads the header comments of `text` in file order (a later `# params:`
    /// replaces an earlier one; `# thickness` wins over the `d` of `# params:`).
    /// The first bad header comment is returned with its line, not at once: the
    /// rows above it may hold an earlier error.
    fn read(text: &str, file: &str) -> (Headers, Option<(usize, DataError)>) {
        let mut h = Headers::default();
        for (i, raw) in text.lines().enumerate() {
            if let Some(c) = raw.trim().strip_prefix('#') {
                if let Err(e) = h.comment(c.trim(), i + 1, file) {
                    return (h, Some((i + 1, e)));
                }
            }
        }
        (h, None)
    }

    /// Takes in one comment `c` (without its `#`) of line `ln`.
    fn comment(&mut self, c: &str, ln: usize, file: &str) -> Result<(), DataError> {
        if let Some(j) = c.strip_prefix("params:") {
            let v: serde_json::Value = serde_json::from_str(j.trim()).map_err(|e| {
                at(
                    file,
                    ln,
                    e.column() + 1,
                    format!("`# params:` header is not valid JSON: {e}"),
                )
            })?;
            if let Some(d) = v.get("d").and_then(|d| d.as_f64()) {
                if self.thickness.is_none() {
                    self.thickness = Some(d);
                }
            }
            self.params = Some(v);
        } else if let Some(t) = c.strip_prefix("thickness") {
            let t = t.trim_start_matches([':', '=', ' ']).trim();
            let t = t.trim_end_matches("mm").trim();
            let d: f64 = t
                .parse()
                .map_err(|_| at(file, ln, 0, format!("`# thickness` header: `{t}` is not a number")))?;
            if !(d > 0.0 && d.is_finite()) {
                return Err(at(
                    file,
                    ln,
                    0,
                    format!("`# thickness` header: {d} is not a positive thickness in mm"),
                ));
            }
            self.thickness = Some(d);
        }
        Ok(())
    }
}

/// The column layout of a file, decided from its header.
struct Layout {
    /// The header's column names, lower case.
    names: Vec<String>,
    in_plane: bool,
    /// The columns `kind,theta_i_deg,theta_o_deg` or `wi_x,...,wo_z`.
    idx: Vec<usize>,
    value: Vec<usize>,
    stderr: Vec<usize>,
    weight: Option<usize>,
}

impl Layout {
    /// The layout of header `rec` at line `ln`; `raw` is the line as written.
    fn from_header(rec: &CsvRecord, raw: &str, file: &str) -> Result<Layout, DataError> {
        let ln = rec.line;
        let names: Vec<String> = rec.fields.iter().map(|s| s.to_ascii_lowercase()).collect();
        let find = |n: &str| names.iter().position(|h| h == n);
        let in_plane_cols = ["kind", "theta_i_deg", "theta_o_deg"];
        let dir_cols = ["wi_x", "wi_y", "wi_z", "wo_x", "wo_y", "wo_z"];
        let (in_plane, idx) = if in_plane_cols.iter().all(|c| find(c).is_some()) {
            (true, in_plane_cols.iter().map(|c| find(c).unwrap()).collect())
        } else if dir_cols.iter().all(|c| find(c).is_some()) {
            (false, dir_cols.iter().map(|c| find(c).unwrap()).collect())
        } else {
            return Err(at(
                file,
                ln,
                0,
                format!(
                    "header `{raw}` has neither the in-plane columns kind,theta_i_deg,theta_o_deg nor the direction columns wi_x,wi_y,wi_z,wo_x,wo_y,wo_z"
                ),
            ));
        };
        let value: Vec<usize> = if let Some(f) = find("f") {
            vec![f]
        } else if let (Some(r), Some(g), Some(b)) = (find("r"), find("g"), find("b")) {
            vec![r, g, b]
        } else {
            return Err(at(
                file,
                ln,
                0,
                "header has no value column: expected `f` or `r,g,b`".into(),
            ));
        };
        let stderr: Vec<usize> = if let Some(s) = find("stderr") {
            vec![s]
        } else if let (Some(r), Some(g), Some(b)) = (find("stderr_r"), find("stderr_g"), find("stderr_b")) {
            vec![r, g, b]
        } else {
            vec![]
        };
        let weight = find("weight");
        if let (Some(wcol), false) = (weight, stderr.is_empty()) {
            return Err(at(
                file,
                ln,
                wcol + 1,
                "header has both `weight` and `stderr` columns: give one of them".into(),
            ));
        }
        Ok(Layout {
            names,
            in_plane,
            idx,
            value,
            stderr,
            weight,
        })
    }

    /// The point of data row `rec`.
    fn point(&self, rec: &CsvRecord, file: &str) -> Result<Point, DataError> {
        let ln = rec.line;
        let fields = &rec.fields;
        let hdr = &self.names;
        let width = hdr.len();
        if fields.len() < width {
            return Err(at(
                file,
                ln,
                fields.len() + 1,
                format!("row has {} fields, the header has {width}", fields.len()),
            ));
        }
        let num = |i: usize| -> Result<f64, DataError> {
            let s = &fields[i];
            match s.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err(at(
                    file,
                    ln,
                    i + 1,
                    format!("field `{}`: `{s}` is not a finite number", hdr[i]),
                )),
            }
        };
        let (kind, theta_i, theta_o, wi, wo) = if self.in_plane {
            let ks = &fields[self.idx[0]];
            let kind = match ks {
                "R" | "r" => Kind::R,
                "T" | "t" => Kind::T,
                _ => {
                    return Err(at(
                        file,
                        ln,
                        self.idx[0] + 1,
                        format!("field `kind`: unknown kind `{ks}` (expected R or T)"),
                    ))
                }
            };
            let ti = num(self.idx[1])?;
            let to = num(self.idx[2])?;
            for (v, i) in [(ti, self.idx[1]), (to, self.idx[2])] {
                if !(-90.0..=90.0).contains(&v) {
                    return Err(at(
                        file,
                        ln,
                        i + 1,
                        format!("field `{}`: angle {v} is outside [-90, 90] degrees", hdr[i]),
                    ));
                }
            }
            let (wi, wo) = in_plane_directions(ti, to, kind == Kind::T);
            (kind, ti, Some(to), wi, wo)
        } else {
            let mut v = [0.0; 6];
            for (k, &i) in self.idx.iter().enumerate() {
                v[k] = num(i)?;
            }
            let mut dirs = [DVec3::ZERO; 2];
            for (k, name) in ["wi", "wo"].iter().enumerate() {
                let d = DVec3::new(v[3 * k], v[3 * k + 1], v[3 * k + 2]);
                let len = d.length();
                if (len - 1.0).abs() > 1e-3 {
                    return Err(at(
                        file,
                        ln,
                        self.idx[3 * k] + 1,
                        format!("direction `{name}` has length {len}; expected a unit vector"),
                    ));
                }
                if d.z == 0.0 {
                    return Err(at(
                        file,
                        ln,
                        self.idx[3 * k + 2] + 1,
                        format!("direction `{name}` lies in the surface (z = 0)"),
                    ));
                }
                dirs[k] = d / len;
            }
            let (wi, wo) = (dirs[0], dirs[1]);
            let kind = if wi.z * wo.z > 0.0 { Kind::R } else { Kind::T };
            (kind, wi.z.abs().min(1.0).acos().to_degrees(), None, wi, wo)
        };
        // The channels of columns `cols` (one column: three equal channels),
        // each a finite number >= 0; `what` names a negative value.
        let channels = |cols: &[usize], what: &str| -> Result<Rgb, DataError> {
            let mut c = [0.0; 3];
            for (k, &i) in cols.iter().enumerate() {
                let v = num(i)?;
                if v < 0.0 {
                    return Err(at(file, ln, i + 1, format!("field `{}`: negative {what} {v}", hdr[i])));
                }
                c[k] = v;
            }
            Ok(Rgb(if cols.len() == 1 { [c[0]; 3] } else { c }))
        };
        let f = channels(&self.value, "BSDF value")?;
        let stderr = if let Some(i) = self.weight {
            let w = num(i)?;
            if w < 0.0 {
                return Err(at(file, ln, i + 1, format!("field `weight`: negative weight {w}")));
            }
            Some(Rgb(f.0.map(|v| {
                if w > 0.0 {
                    (v + LOG_OFFSET) / w.sqrt()
                } else {
                    f64::INFINITY
                }
            })))
        } else if self.stderr.is_empty() {
            None
        } else {
            Some(channels(&self.stderr, "standard error")?)
        };
        Ok(Point {
            kind,
            theta_i,
            theta_o,
            wi,
            wo,
            f,
            stderr,
            line: ln,
        })
    }
}

/// Parses the text of a measurement file; `origin` names it in errors.
pub fn parse_measurement(text: &str, origin: &str) -> Result<Measurement, DataError> {
    // A UTF-8 byte-order mark is not content (issue 16: it made the first comment line the header).
    let text = crate::text::strip_bom(text);
    let (headers, mut header_error) = Headers::read(text, origin);
    let mut layout: Option<Layout> = None;
    let mut points = Vec::new();
    for rec in csv_records(text, origin) {
        let rec = rec?;
        // Errors in file order: a bad header comment above this row comes first.
        if let Some((_, e)) = header_error.take_if(|(line, _)| *line < rec.line) {
            return Err(e);
        }
        match &layout {
            None => {
                let raw = text[rec.byte..].lines().next().unwrap_or_default().trim();
                layout = Some(Layout::from_header(&rec, raw, origin)?);
            }
            Some(lay) => points.push(lay.point(&rec, origin)?),
        }
    }
    if let Some((_, e)) = header_error {
        return Err(e);
    }
    let other = |message: &str| DataError::Other {
        file: origin.to_string(),
        message: message.into(),
    };
    let Some(lay) = layout else {
        return Err(other("empty file: no header and no measurements"));
    };
    if points.is_empty() {
        return Err(other("empty file: a header but no measurements"));
    }
    Ok(Measurement {
        origin: origin.to_string(),
        points,
        is_rgb: lay.value.len() == 3,
        params_header: headers.params,
        thickness: headers.thickness,
        in_plane: lay.in_plane,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn in_plane_directions_follow_design_convention() {
        let m = parse_measurement("kind,theta_i_deg,theta_o_deg,f\nR,30,-30,1\nT,30,-30,2\n", "x.csv").unwrap();
        let r = &m.points[0];
        // Mirror direction of the light at +30 deg is theta_o = -30 in R.
        assert!((r.wo.x + r.wi.x).abs() < 1e-12 && (r.wo.z - r.wi.z).abs() < 1e-12);
        let t = &m.points[1];
        // Straight-through direction: wo = -wi.
        assert!((t.wo + t.wi).length() < 1e-12);
    }

    /// Comments (also indented ones), blank lines and header comments anywhere
    /// keep the line numbers of the file; a bad header comment is reported in
    /// file order with the rows' errors.
    #[test]
    fn comments_and_line_numbers() {
        let text = "# a\n\n  # indented, with \"quote\n   \nkind,theta_i_deg,theta_o_deg,f\n# thickness: 0.2 mm\nR,0,0,1\n\r\nT,0,0,2\r\n# params: {\"d\": 0.1}\n";
        let m = parse_measurement(text, "c.csv").unwrap();
        assert_eq!(m.points.iter().map(|p| p.line).collect::<Vec<_>>(), [7, 9]);
        assert_eq!(m.thickness, Some(0.2));
        assert_eq!(m.params_header.unwrap()["d"], 0.1);
        let e = parse_measurement("kind,theta_i_deg,theta_o_deg,f\nR,0,x,1\n# thickness: x\n", "c.csv")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("c.csv:2:3:"), "{e}");
        let e = parse_measurement("kind,theta_i_deg,theta_o_deg,f\n# thickness: -1\nR,0,x,1\n", "c.csv")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("c.csv:2:0:") && e.contains("positive thickness"), "{e}");
        let e = parse_measurement("kind,theta_i_deg,theta_o_deg,f\nR,0,0,1\n# params: {x\n", "c.csv")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("c.csv:3:") && e.contains("not valid JSON"), "{e}");
        // The header is quoted as written.
        let e = parse_measurement("# c\n kind , theta_i ,f\n", "c.csv")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("c.csv:2:0: header `kind , theta_i ,f`"), "{e}");
    }
}
