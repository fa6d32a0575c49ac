//! CSV files of direction pairs: columns `wi_x,wi_y,wi_z,wo_x,wo_y,wo_z` (any
//! order, other columns ignored, `#` lines are comments; read with the `csv`
//! crate, see [`crate::text::csv_records`]), in the local frame of docs/design.md
//! section 2. Each direction must be finite and of unit length
//! (to 1e-4); an error names the file, line and field.

use crate::DataError;
use paperbsdf_core::DVec3;

/// One row of a direction file.
#[derive(Debug, Clone)]
pub struct DirRow {
    /// 1-based line in the file.
    pub line: usize,
    /// The row's fields as written, trimmed and unquoted (echo them with [`csv_line`]).
    pub fields: Vec<String>,
    /// Direction toward the light (normalised).
    pub wi: DVec3,
    /// Direction toward the viewer (normalised).
    pub wo: DVec3,
}

/// A parsed direction file.
#[derive(Debug, Clone)]
pub struct DirFile {
    /// The header's column names.
    pub header: Vec<String>,
    /// The data rows.
    pub rows: Vec<DirRow>,
}

/// Allowed deviation of a direction's length from 1.
pub const UNIT_TOLERANCE: f64 = 1e-4;

const COLS: [&str; 6] = ["wi_x", "wi_y", "wi_z", "wo_x", "wo_y", "wo_z"];

/// Reads a direction file from `path`.
pub fn read_dirs(path: &str) -> Result<DirFile, DataError> {
    let text = crate::text::read_text(path)?;
    parse_dirs(&text, path)
}

/// Parses the text of a direction file; `origin` names it in errors.
pub fn parse_dirs(text: &str, origin: &str) -> Result<DirFile, DataError> {
    let err = |line: usize, field: &str, message: String| DataError::Field {
        file: origin.to_string(),
        line,
        field: field.to_string(),
        message,
    };
    let mut records = crate::text::csv_records(crate::text::strip_bom(text), origin);
    let header: Vec<String> = match records.next().transpose()? {
        Some(r) => r.fields.iter().map(str::to_string).collect(),
        None => {
            return Err(DataError::Other {
                file: origin.to_string(),
                message: "empty file: expected a header with wi_x,wi_y,wi_z,wo_x,wo_y,wo_z".into(),
            })
        }
    };
    let mut idx = [0usize; 6];
    for (k, c) in COLS.iter().enumerate() {
        idx[k] = header.iter().position(|h| h == c).ok_or_else(|| DataError::Other {
            file: origin.to_string(),
            message: format!("missing column `{c}` (header: {})", header.join(",")),
        })?;
    }
    let mut rows = Vec::new();
    for r in records {
        let r = r?;
        let line = r.line;
        if r.fields.len() != header.len() {
            return Err(DataError::Syntax {
                file: origin.to_string(),
                line,
                column: 0,
                message: format!("{} fields, but the header has {}", r.fields.len(), header.len()),
            });
        }
        let mut v = [0.0f64; 6];
        for k in 0..6 {
            let s = &r.fields[idx[k]];
            v[k] = s
                .parse::<f64>()
                .map_err(|_| err(line, COLS[k], format!("`{s}` is not a number")))?;
            if !v[k].is_finite() {
                return Err(err(line, COLS[k], format!("`{s}` is not a finite number")));
            }
        }
        let wi = DVec3::new(v[0], v[1], v[2]);
        let wo = DVec3::new(v[3], v[4], v[5]);
        for (name, w) in [("wi", wi), ("wo", wo)] {
            let l = w.length();
            if (l - 1.0).abs() > UNIT_TOLERANCE {
                return Err(err(
                    line,
                    &format!("{name}_x,{name}_y,{name}_z"),
                    format!("direction has length {l}, expected a unit vector (tolerance {UNIT_TOLERANCE})"),
                ));
            }
        }
        rows.push(DirRow {
            line,
            fields: r.fields.iter().map(str::to_string).collect(),
            wi: wi.normalize(),
            wo: wo.normalize(),
        });
    }
    Ok(DirFile { header, rows })
}

/// `fields` as one CSV line: a field holding a comma, a quote or a line break
/// is quoted (`"` doubled), so a row read with quoted fields is echoed intact.
pub fn csv_line(fields: &[String]) -> String {
    let quoted = fields.iter().map(|f| {
        if f.contains([',', '"', '\n', '\r']) {
            format!("\"{}\"", f.replace('"', "\"\""))
        } else {
            f.clone()
        }
    });
    quoted.collect::<Vec<_>>().join(",")
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn parses_with_comments_and_extra_columns() {
        let t = "# comment\nid,wi_x,wi_y,wi_z,wo_x,wo_y,wo_z\n7,0,0,1,1,0,0\n# more\n8,0,1,0,0,0,-1\n";
        let f = parse_dirs(t, "x.csv").unwrap();
        assert_eq!(f.rows.len(), 2);
        assert_eq!(f.rows[1].line, 5);
        assert_eq!(f.rows[1].wo, DVec3::new(0.0, 0.0, -1.0));
    }
    #[test]
    fn errors_name_line_and_field() {
        let t = "wi_x,wi_y,wi_z,wo_x,wo_y,wo_z\n0,0,1,1,0,0\n0,0,1,abc,0,0\n";
        let e = parse_dirs(t, "x.csv").unwrap_err().to_string();
        assert!(e.contains("x.csv:3") && e.contains("wo_x") && e.contains("abc"), "{e}");
        let t = "wi_x,wi_y,wi_z,wo_x,wo_y,wo_z\n0,0,2,1,0,0\n";
        let e = parse_dirs(t, "x.csv").unwrap_err().to_string();
        assert!(
            e.contains("x.csv:2") && e.contains("wi_x,wi_y,wi_z") && e.contains("length 2"),
            "{e}"
        );
        let t = "wi_x,wi_y,wi_z,wo_x,wo_y,wo_z\n0,0,NaN,1,0,0\n";
        let e = parse_dirs(t, "x.csv").unwrap_err().to_string();
        assert!(e.contains("wi_z") && e.contains("finite"), "{e}");
        let e = parse_dirs("a,b\n1,2\n", "y.csv").unwrap_err().to_string();
        assert!(e.contains("missing column `wi_x`"), "{e}");
        assert!(parse_dirs("", "z.csv").is_err());
        let e = parse_dirs("wi_x,wi_y,wi_z,wo_x,wo_y,wo_z\n\n0,0,1,1,0\n", "x.csv")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("x.csv:3:0: 5 fields"), "{e}");
    }
    #[test]
    fn quoted_fields_are_read_and_echoed() {
        let t = "label,wi_x,wi_y,wi_z,wo_x,wo_y,wo_z\n\"a, \"\"b\"\"\",0,0,1,1,0,0\n";
        let f = parse_dirs(t, "q.csv").unwrap();
        assert_eq!(f.rows[0].fields[0], "a, \"b\"");
        assert_eq!(csv_line(&f.rows[0].fields), "\"a, \"\"b\"\"\",0,0,1,1,0,0");
    }
    #[test]
    fn byte_order_mark_is_ignored() {
        // Issue 16: a UTF-8 BOM before the header gave `missing column wi_x`.
        let t = "\u{feff}wi_x,wi_y,wi_z,wo_x,wo_y,wo_z\n0,0,1,1,0,0\n";
        let f = parse_dirs(t, "bom.csv").unwrap();
        assert_eq!(f.header[0], "wi_x");
        assert_eq!(f.rows.len(), 1);
        let t = "\u{feff}# comment first\nwi_x,wi_y,wi_z,wo_x,wo_y,wo_z\n0,0,1,1,0,0\n";
        assert_eq!(parse_dirs(t, "bom.csv").unwrap().rows[0].line, 3);
        // Only one mark is a byte-order mark (the csv reader must not drop a second).
        assert!(parse_dirs("\u{feff}\u{feff}wi_x,wi_y,wi_z,wo_x,wo_y,wo_z\n", "bom.csv").is_err());
    }
}
