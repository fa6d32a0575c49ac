//! Readers for BSDF measurement files.
//!
//! Two CSV layouts, in the conventions of DESIGN.md section 2 (`f` without the
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
//! `(f + e) / sqrt(weight)` that has that weight in the objective (see
//! [`crate::objective::weight`]; weights above `1 / SIGMA_FLOOR^2` = 1e6 count
//! as 1e6), so weight 0 leaves a point out and weight 4 counts it four times.
//! Other columns (e.g. `samples`) are ignored. Lines starting with `#` are
//! comments; two header comments are understood: `# params: {JSON}` (the
//! parameters the data were made with; its `d` is the thickness) and
//! `# thickness: D` (mm). Every error names the file, the line and the column.

use paperbsdf_core::geometry::in_plane_directions;
use paperbsdf_core::{DVec3, Rgb};

/// An error reading a measurement file.
#[derive(Debug, thiserror::Error)]
pub enum MeasurementError {
    /// The file could not be read.
    #[error("{file}: {source}")]
    Io {
        /// The file.
        file: String,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// A problem at a line and column (1-based; column is the field number).
    #[error("{file}:{line}:{column}: {message}")]
    At {
        /// The file.
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column (field number in the row; 0 for the whole line).
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// A problem with the file as a whole (empty, no header, mixed channels).
    #[error("{file}: {message}")]
    File {
        /// The file.
        file: String,
        /// What is wrong.
        message: String,
    },
}

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
pub fn read_measurement(path: &str) -> Result<Measurement, MeasurementError> {
    let text = std::fs::read_to_string(path).map_err(|source| MeasurementError::Io {
        file: path.to_string(),
        source,
    })?;
    parse_measurement(&text, path)
}

fn col_index(header: &[String], name: &str) -> Option<usize> {
    header.iter().position(|h| h == name)
}

/// Parses the text of a measurement file; `origin` names it in errors.
pub fn parse_measurement(text: &str, origin: &str) -> Result<Measurement, MeasurementError> {
    let file = origin.to_string();
    let at = |line: usize, column: usize, message: String| MeasurementError::At {
        file: file.clone(),
        line,
        column,
        message,
    };
    let mut params_header = None;
    let mut thickness = None;
    let mut header: Option<Vec<String>> = None;
    let mut points = Vec::new();
    // Column layout, decided from the header.
    struct Layout {
        in_plane: bool,
        idx: Vec<usize>,
        value: Vec<usize>,
        stderr: Vec<usize>,
        weight: Option<usize>,
        width: usize,
    }
    let mut layout: Option<Layout> = None;
    // A UTF-8 byte-order mark is not content (issue 16: it made the first comment line the header).
    let text = paperbsdf_io::text::strip_bom(text);
    for (ln0, raw) in text.lines().enumerate() {
        let ln = ln0 + 1;
        let line = raw.trim();
        if line.is_empty() {
            continue;
        }
        if let Some(c) = line.strip_prefix('#') {
            let c = c.trim();
            if let Some(j) = c.strip_prefix("params:") {
                let v: serde_json::Value = serde_json::from_str(j.trim())
                    .map_err(|e| at(ln, e.column() + 1, format!("`# params:` header is not valid JSON: {e}")))?;
                if let Some(d) = v.get("d").and_then(|d| d.as_f64()) {
                    if thickness.is_none() {
                        thickness = Some(d);
                    }
                }
                params_header = Some(v);
            } else if let Some(t) = c.strip_prefix("thickness") {
                let t = t.trim_start_matches([':', '=', ' ']).trim();
                let t = t.trim_end_matches("mm").trim();
                let d: f64 = t
                    .parse()
                    .map_err(|_| at(ln, 0, format!("`# thickness` header: `{t}` is not a number")))?;
                if !(d > 0.0 && d.is_finite()) {
                    return Err(at(
                        ln,
                        0,
                        format!("`# thickness` header: {d} is not a positive thickness in mm"),
                    ));
                }
                thickness = Some(d);
            }
            continue;
        }
        let fields: Vec<&str> = line.split(',').map(|s| s.trim()).collect();
        if header.is_none() {
            let h: Vec<String> = fields.iter().map(|s| s.to_ascii_lowercase()).collect();
            let find = |n: &str| col_index(&h, n);
            let in_plane_cols = ["kind", "theta_i_deg", "theta_o_deg"];
            let dir_cols = ["wi_x", "wi_y", "wi_z", "wo_x", "wo_y", "wo_z"];
            let (in_plane, idx) = if in_plane_cols.iter().all(|c| find(c).is_some()) {
                (true, in_plane_cols.iter().map(|c| find(c).unwrap()).collect())
            } else if dir_cols.iter().all(|c| find(c).is_some()) {
                (false, dir_cols.iter().map(|c| find(c).unwrap()).collect())
            } else {
                return Err(at(
                    ln,
                    0,
                    format!(
                        "header `{line}` has neither the in-plane columns kind,theta_i_deg,theta_o_deg nor the direction columns wi_x,wi_y,wi_z,wo_x,wo_y,wo_z"
                    ),
                ));
            };
            let value: Vec<usize> = if let Some(f) = find("f") {
                vec![f]
            } else if let (Some(r), Some(g), Some(b)) = (find("r"), find("g"), find("b")) {
                vec![r, g, b]
            } else {
                return Err(at(ln, 0, "header has no value column: expected `f` or `r,g,b`".into()));
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
                    ln,
                    wcol + 1,
                    "header has both `weight` and `stderr` columns: give one of them".into(),
                ));
            }
            layout = Some(Layout {
                in_plane,
                idx,
                value,
                stderr,
                weight,
                width: h.len(),
            });
            header = Some(h);
            continue;
        }
        let lay = layout.as_ref().unwrap();
        let hdr = header.as_ref().unwrap();
        if fields.len() < lay.width {
            return Err(at(
                ln,
                fields.len() + 1,
                format!("row has {} fields, the header has {}", fields.len(), lay.width),
            ));
        }
        let num = |i: usize| -> Result<f64, MeasurementError> {
            let s = fields[i];
            match s.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err(at(
                    ln,
                    i + 1,
                    format!("field `{}`: `{s}` is not a finite number", hdr[i]),
                )),
            }
        };
        let (kind, theta_i, theta_o, wi, wo) = if lay.in_plane {
            let ks = fields[lay.idx[0]];
            let kind = match ks {
                "R" | "r" => Kind::R,
                "T" | "t" => Kind::T,
                _ => {
                    return Err(at(
                        ln,
                        lay.idx[0] + 1,
                        format!("field `kind`: unknown kind `{ks}` (expected R or T)"),
                    ))
                }
            };
            let ti = num(lay.idx[1])?;
            let to = num(lay.idx[2])?;
            for (v, i) in [(ti, lay.idx[1]), (to, lay.idx[2])] {
                if !(-90.0..=90.0).contains(&v) {
                    return Err(at(
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
            for (k, &i) in lay.idx.iter().enumerate() {
                v[k] = num(i)?;
            }
            let mut dirs = [DVec3::ZERO; 2];
            for (k, name) in ["wi", "wo"].iter().enumerate() {
                let d = DVec3::new(v[3 * k], v[3 * k + 1], v[3 * k + 2]);
                let len = d.length();
                if (len - 1.0).abs() > 1e-3 {
                    return Err(at(
                        ln,
                        lay.idx[3 * k] + 1,
                        format!("direction `{name}` has length {len}; expected a unit vector"),
                    ));
                }
                if d.z == 0.0 {
                    return Err(at(
                        ln,
                        lay.idx[3 * k + 2] + 1,
                        format!("direction `{name}` lies in the surface (z = 0)"),
                    ));
                }
                dirs[k] = d / len;
            }
            let (wi, wo) = (dirs[0], dirs[1]);
            let kind = if wi.z * wo.z > 0.0 { Kind::R } else { Kind::T };
            (kind, wi.z.abs().min(1.0).acos().to_degrees(), None, wi, wo)
        };
        let mut f = [0.0; 3];
        for (k, &i) in lay.value.iter().enumerate() {
            let v = num(i)?;
            if v < 0.0 {
                return Err(at(ln, i + 1, format!("field `{}`: negative BSDF value {v}", hdr[i])));
            }
            f[k] = v;
        }
        if lay.value.len() == 1 {
            f = [f[0]; 3];
        }
        let stderr = if let Some(i) = lay.weight {
            let w = num(i)?;
            if w < 0.0 {
                return Err(at(ln, i + 1, format!("field `weight`: negative weight {w}")));
            }
            let e = crate::objective::LOG_OFFSET;
            Some(Rgb(f.map(|v| if w > 0.0 { (v + e) / w.sqrt() } else { f64::INFINITY })))
        } else if lay.stderr.is_empty() {
            None
        } else {
            let mut s = [0.0; 3];
            for (k, &i) in lay.stderr.iter().enumerate() {
                let v = num(i)?;
                if v < 0.0 {
                    return Err(at(
                        ln,
                        i + 1,
                        format!("field `{}`: negative standard error {v}", hdr[i]),
                    ));
                }
                s[k] = v;
            }
            if lay.stderr.len() == 1 {
                s = [s[0]; 3];
            }
            Some(Rgb(s))
        };
        points.push(Point {
            kind,
            theta_i,
            theta_o,
            wi,
            wo,
            f: Rgb(f),
            stderr,
            line: ln,
        });
    }
    let Some(lay) = layout else {
        return Err(MeasurementError::File {
            file,
            message: "empty file: no header and no measurements".into(),
        });
    };
    if points.is_empty() {
        return Err(MeasurementError::File {
            file,
            message: "empty file: a header but no measurements".into(),
        });
    }
    Ok(Measurement {
        origin: origin.to_string(),
        points,
        is_rgb: lay.value.len() == 3,
        params_header,
        thickness,
        in_plane: lay.in_plane,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `weight` column reproduces the weight in the objective: weight 4 counts a
    /// point four times, weight 0 not at all (against the definition in `objective`).
    #[test]
    fn weight_column_is_the_objective_weight() {
        let m = parse_measurement(
            "kind,theta_i_deg,theta_o_deg,f,weight\nR,30,-30,1,4\nR,30,0,2,0\nR,30,10,0.5,1\n",
            "w.csv",
        )
        .unwrap();
        let w: Vec<f64> = m.points.iter().map(|p| crate::objective::weight(p, 0)).collect();
        assert!(
            (w[0] - 4.0).abs() < 1e-9 && w[1] == 0.0 && (w[2] - 1.0).abs() < 1e-9,
            "{w:?}"
        );
        let e = parse_measurement("kind,theta_i_deg,theta_o_deg,f,weight\nR,30,-30,1,-1\n", "w.csv").unwrap_err();
        assert!(
            e.to_string().contains("w.csv:2:5") && e.to_string().contains("negative weight"),
            "{e}"
        );
        let e = parse_measurement(
            "kind,theta_i_deg,theta_o_deg,f,weight,stderr\nR,30,-30,1,1,1\n",
            "w.csv",
        )
        .unwrap_err();
        assert!(e.to_string().contains("both"), "{e}");
    }

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
}
