//! Parameter files: a path to a JSON or TOML file, or inline JSON (a string
//! starting with `{`). Keys are exactly the parameter names of DESIGN.md
//! section 3 (unknown keys are errors, which catches typos); values outside
//! their ranges are errors naming the file, line, parameter, value and range.

use crate::DataError;
use paperbsdf_core::ParamError;
use serde::de::DeserializeOwned;

/// A parsed parameter file with where it came from (for later error messages).
#[derive(Debug, Clone)]
pub struct Loaded<T> {
    /// The parsed value.
    pub value: T,
    /// File name, or `<inline>`.
    pub origin: String,
    /// The text it was parsed from.
    pub text: String,
    /// Whether the text was TOML (else JSON).
    pub is_toml: bool,
}

impl<T> Loaded<T> {
    /// Turns a parameter error into a [`DataError`] that names this file and the
    /// line where the parameter is written.
    pub fn param_error(&self, e: ParamError) -> DataError {
        let key = e.name().split('[').next().unwrap_or("").to_string();
        DataError::Param {
            file: self.origin.clone(),
            line: locate_key(&self.text, &key, self.is_toml),
            source: e,
        }
    }
}

/// 1-based line of the first occurrence of `key` as a key (`"key":` in JSON,
/// `key =` in TOML); 0 when not found.
pub fn locate_key(text: &str, key: &str, is_toml: bool) -> usize {
    for (i, line) in text.lines().enumerate() {
        let t = line.trim_start();
        let hit = if is_toml {
            t.strip_prefix(key)
                .map(|r| r.trim_start().starts_with('='))
                .unwrap_or(false)
        } else {
            line.contains(&format!("\"{key}\""))
        };
        if hit {
            return i + 1;
        }
    }
    0
}

/// Reads `source` (a path, or inline JSON starting with `{`) as the text of a parameter set.
pub fn read_source(source: &str) -> Result<(String, String, bool), DataError> {
    let s = source.trim_start();
    if s.starts_with('{') {
        return Ok((source.to_string(), "<inline>".to_string(), false));
    }
    let text = std::fs::read_to_string(source).map_err(|e| DataError::Io {
        file: source.to_string(),
        source: e,
    })?;
    let is_toml = source.to_ascii_lowercase().ends_with(".toml");
    Ok((text, source.to_string(), is_toml))
}

/// Parses `text` (JSON or TOML) into `T`; errors name `origin` with line and column.
pub fn parse_text<T: DeserializeOwned>(text: &str, origin: &str, is_toml: bool) -> Result<T, DataError> {
    if is_toml {
        toml::from_str::<T>(text).map_err(|e| {
            let (line, column) = e
                .span()
                .map(|sp| {
                    let before = &text[..sp.start.min(text.len())];
                    let line = before.matches('\n').count() + 1;
                    let col = sp.start - before.rfind('\n').map(|p| p + 1).unwrap_or(0) + 1;
                    (line, col)
                })
                .unwrap_or((0, 0));
            DataError::Syntax {
                file: origin.to_string(),
                line,
                column,
                message: e.message().to_string(),
            }
        })
    } else {
        serde_json::from_str::<T>(text).map_err(|e| DataError::Syntax {
            file: origin.to_string(),
            line: e.line(),
            column: e.column(),
            message: e.to_string().split(" at line ").next().unwrap_or("").to_string(),
        })
    }
}

/// Loads a parameter set of type `T` from `source` (see the module doc).
pub fn load_params<T: DeserializeOwned>(source: &str) -> Result<Loaded<T>, DataError> {
    let (text, origin, is_toml) = read_source(source)?;
    let value = parse_text(&text, &origin, is_toml)?;
    Ok(Loaded {
        value,
        origin,
        text,
        is_toml,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use paperbsdf_core::PaperParams;

    const GOOD: &str = r#"{"d":0.1,"sigma_a":0.6,"sigma_s":[120,110,100],"g_f":0.85,"g_b":-0.4,"w_b":0.15,
"eta_f":1.45,"eta_b":1.45,"m_f":0.35,"m_b":0.35,"dist_f":"ggx","dist_b":"ggx"}"#;

    #[test]
    fn inline_json() {
        let p = load_params::<PaperParams>(GOOD).unwrap();
        assert!(p.value.is_rgb());
        p.value.validate().unwrap();
    }

    #[test]
    fn unknown_key_names_line() {
        let bad = GOOD.replace("\"w_b\"", "\"wb\"");
        let e = load_params::<PaperParams>(&bad).unwrap_err().to_string();
        assert!(e.contains("<inline>:1:") && e.contains("wb"), "{e}");
    }

    #[test]
    fn toml_range_error_names_line() {
        let text = "d = 0.1\nsigma_a = 0.6\nsigma_s = 100\ng_f = 0.8\ng_b = -0.3\nw_b = 1.5\neta_f = 1.5\neta_b = 1.5\nm_f = 0.3\nm_b = 0.3\ndist_f = \"ggx\"\ndist_b = \"beckmann\"\n";
        let dir = std::env::temp_dir().join(format!("pb_io_test_{}.toml", std::process::id()));
        std::fs::write(&dir, text).unwrap();
        let l = load_params::<PaperParams>(dir.to_str().unwrap()).unwrap();
        let e = l.param_error(l.value.validate().unwrap_err()).to_string();
        std::fs::remove_file(&dir).unwrap();
        assert!(
            e.contains(":6:") && e.contains("w_b") && e.contains("1.5") && e.contains("[0, 1]"),
            "{e}"
        );
    }

    #[test]
    fn bad_distribution_and_missing_field() {
        let e = load_params::<PaperParams>(&GOOD.replace("\"ggx\",\"dist_b\"", "\"gxx\",\"dist_b\""))
            .unwrap_err()
            .to_string();
        assert!(e.contains("gxx"), "{e}");
        let e = load_params::<PaperParams>(&GOOD.replace("\"d\":0.1,", ""))
            .unwrap_err()
            .to_string();
        assert!(e.contains("missing field `d`"), "{e}");
        let e = load_params::<PaperParams>("/nonexistent/p.json")
            .unwrap_err()
            .to_string();
        assert!(e.contains("/nonexistent/p.json"), "{e}");
    }
}
