//! Parameter files: a path to a JSON or TOML file, inline JSON (a string
//! starting with `{`), the name of a paper preset (`matte`, `luster`, `glossy`,
//! see [`paperbsdf_core::presets`]) when no file of that name exists, or a
//! FIT.json written by `paperbsdf fit` (its `params` object is used, and error
//! lines still point into the fit file). Keys are exactly the parameter names
//! of docs/design.md section 3 (unknown keys are errors, which catches typos);
//! values outside their ranges are errors naming the file, line, parameter,
//! value and range.

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

/// A parameter source read into text: what [`read_source_full`] returns.
#[derive(Debug, Clone)]
pub struct Source {
    /// The text of the parameter set (for a FIT.json: the file with everything
    /// but its `params` object blanked, so line numbers stay those of the file).
    pub text: String,
    /// File name, `<inline>`, or `preset `NAME``.
    pub origin: String,
    /// Whether the text is TOML (else JSON).
    pub is_toml: bool,
    /// The model of a FIT.json (`paper`, `lambert-glass`, ...), if the source is one.
    pub fit_model: Option<String>,
    /// The value of a FIT.json's `slab_nodes` (the discretisation a `slab`
    /// fit was solved with, `paperbsdf fit --refine slab`), unchecked: see
    /// [`crate::models::SlabSettings::recorded`].
    pub fit_slab_nodes: Option<serde_json::Value>,
    /// The preset name, if the source is one.
    pub preset: Option<String>,
}

/// The top-level keys of a FIT.json that identify it (see `paperbsdf fit --out`).
#[derive(serde::Deserialize)]
struct FitFile<'a> {
    model: String,
    #[serde(borrow)]
    params: &'a serde_json::value::RawValue,
    /// Kept as any JSON value so that a bad one is reported as such, not
    /// taken for "not a FIT.json".
    #[serde(default)]
    slab_nodes: Option<serde_json::Value>,
}

/// If `text` is a FIT.json, its model, `text` with everything outside the
/// `params` object replaced by spaces (newlines kept: still valid JSON, the
/// parameters, with line and column numbers those of the fit file) and its
/// `slab_nodes` value, if any.
fn fit_params(text: &str) -> Option<(String, String, Option<serde_json::Value>)> {
    let fit: FitFile = serde_json::from_str(text).ok()?;
    let raw = fit.params.get();
    let start = (raw.as_ptr() as usize).checked_sub(text.as_ptr() as usize)?;
    let end = start + raw.len();
    if end > text.len() {
        return None;
    }
    let blank = |s: &str| -> String { s.chars().map(|c| if c == '\n' { '\n' } else { ' ' }).collect() };
    Some((
        fit.model,
        blank(&text[..start]) + raw + &blank(&text[end..]),
        fit.slab_nodes,
    ))
}

/// Reads `source` (a path, inline JSON starting with `{`, a preset name or a
/// FIT.json; see the module doc) as the text of a parameter set.
pub fn read_source_full(source: &str) -> Result<Source, DataError> {
    let s = source.trim_start();
    if s.starts_with('{') {
        return Ok(Source {
            text: source.to_string(),
            origin: "<inline>".to_string(),
            is_toml: false,
            fit_model: None,
            fit_slab_nodes: None,
            preset: None,
        });
    }
    if !std::path::Path::new(source).exists() {
        if let Some(p) = paperbsdf_core::presets::preset(source) {
            let text = serde_json::to_string_pretty(&p).expect("presets serialise") + "\n";
            return Ok(Source {
                text,
                origin: format!("preset `{source}`"),
                is_toml: false,
                fit_model: None,
                fit_slab_nodes: None,
                preset: Some(source.to_string()),
            });
        }
    }
    let text = crate::text::read_text(source).map_err(|e| match e {
        DataError::Io { source: io, .. } if !source.contains(['/', '\\', '.']) => DataError::Io {
            file: format!(
                "{source} (neither a file nor a preset; presets: {})",
                paperbsdf_core::presets::PRESET_NAMES.join(", ")
            ),
            source: io,
        },
        other => other,
    })?;
    let is_toml = source.to_ascii_lowercase().ends_with(".toml");
    if !is_toml {
        if let Some((model, params, slab_nodes)) = fit_params(&text) {
            return Ok(Source {
                text: params,
                origin: source.to_string(),
                is_toml,
                fit_model: Some(model),
                fit_slab_nodes: slab_nodes,
                preset: None,
            });
        }
    }
    Ok(Source {
        text,
        origin: source.to_string(),
        is_toml,
        fit_model: None,
        fit_slab_nodes: None,
        preset: None,
    })
}

/// Reads `source` as the text of a parameter set: `(text, origin, is_toml)` of [`read_source_full`].
pub fn read_source(source: &str) -> Result<(String, String, bool), DataError> {
    let s = read_source_full(source)?;
    Ok((s.text, s.origin, s.is_toml))
}

/// The key whose value is being read at byte `offset` of `text`: the last
/// `"key":` (JSON) or `key =` (TOML) before it. Parameter files are flat, so
/// this names the parameter a value error is about.
fn key_before(text: &str, offset: usize, is_toml: bool) -> Option<String> {
    let mut end = offset.min(text.len());
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    let prefix = &text[..end];
    if is_toml {
        return prefix.lines().rev().find_map(|l| {
            let (k, _) = l.split_once('=')?;
            let k = k.trim().trim_matches('"');
            (!k.is_empty() && k.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-'))
                .then(|| k.to_string())
        });
    }
    // JSON: scan strings; a string followed by `:` is a key.
    let b = prefix.as_bytes();
    let (mut i, mut last) = (0, None);
    while i < b.len() {
        if b[i] == b'"' {
            let start = i + 1;
            let mut j = start;
            while j < b.len() && b[j] != b'"' {
                j += if b[j] == b'\\' { 2 } else { 1 };
            }
            let mut k = j + 1;
            while k < b.len() && b[k].is_ascii_whitespace() {
                k += 1;
            }
            if k < b.len() && b[k] == b':' && j <= b.len() {
                last = Some(prefix[start..j.min(b.len())].to_string());
            }
            i = j + 1;
        } else {
            i += 1;
        }
    }
    last
}

/// `message`, prefixed with the parameter it is about when that is not already named.
fn name_parameter(message: String, text: &str, offset: usize, is_toml: bool) -> String {
    let about_keys = ["missing field", "unknown field", "duplicate field", "duplicate key"];
    if about_keys.iter().any(|k| message.contains(k)) {
        return message;
    }
    match key_before(text, offset, is_toml) {
        Some(k) if !message.contains(&format!("`{k}`")) => format!("parameter `{k}`: {message}"),
        _ => message,
    }
}

/// Parses `text` (JSON or TOML) into `T`; errors name `origin` with line and
/// column, and the parameter whose value is wrong.
pub fn parse_text<T: DeserializeOwned>(text: &str, origin: &str, is_toml: bool) -> Result<T, DataError> {
    let text = crate::text::strip_bom(text);
    if is_toml {
        toml::from_str::<T>(text).map_err(|e| {
            let start = e.span().map(|sp| sp.start.min(text.len()));
            let (line, column) = start
                .map(|start| {
                    let before = &text[..start];
                    let line = before.matches('\n').count() + 1;
                    let col = start - before.rfind('\n').map(|p| p + 1).unwrap_or(0) + 1;
                    (line, col)
                })
                .unwrap_or((0, 0));
            let message = e.message().to_string();
            DataError::Syntax {
                file: origin.to_string(),
                line,
                column,
                message: match start {
                    Some(o) => name_parameter(message, text, o, true),
                    None => message,
                },
            }
        })
    } else {
        serde_json::from_str::<T>(text).map_err(|e| {
            let message = e.to_string().split(" at line ").next().unwrap_or("").to_string();
            // Byte offset of (line, column); serde_json's column is 1-based in bytes.
            let offset = text
                .split_inclusive('\n')
                .take(e.line().saturating_sub(1))
                .map(str::len)
                .sum::<usize>()
                + e.column().saturating_sub(1);
            DataError::Syntax {
                file: origin.to_string(),
                line: e.line(),
                column: e.column(),
                message: name_parameter(message, text, offset, false),
            }
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
    fn byte_order_mark_is_ignored_in_json_and_toml() {
        // Issue 16: a UTF-8 BOM gave `1:1: expected value` for JSON files.
        let d = tempfile::tempdir().unwrap();
        let j = d.path().join("p.json");
        std::fs::write(&j, format!("\u{feff}{GOOD}")).unwrap();
        let p = load_params::<PaperParams>(j.to_str().unwrap()).unwrap();
        p.value.validate().unwrap();
        assert!(!p.text.starts_with('\u{feff}'));
        let t = d.path().join("p.toml");
        let toml = "\u{feff}d = 0.1\nsigma_a = 0.6\nsigma_s = 100\ng_f = 0.8\ng_b = -0.3\nw_b = 0.5\neta_f = 1.5\neta_b = 1.5\nm_f = 0.3\nm_b = 0.3\ndist_f = \"ggx\"\ndist_b = \"beckmann\"\n";
        std::fs::write(&t, toml).unwrap();
        load_params::<PaperParams>(t.to_str().unwrap()).unwrap();
        // Text given directly (not from a file) is handled the same way.
        parse_text::<PaperParams>(&format!("\u{feff}{GOOD}"), "<x>", false).unwrap();
    }

    #[test]
    fn wrong_length_rgb_names_parameter_and_forms() {
        // Issue 16: this said `data did not match any variant of untagged enum Colour`.
        let bad = GOOD.replace("[120,110,100]", "[120,110]");
        let e = load_params::<PaperParams>(&bad).unwrap_err().to_string();
        assert!(
            e.contains("parameter `sigma_s`") && e.contains("array of 2 numbers") && e.contains("RGB triple"),
            "{e}"
        );
        let bad = GOOD.replace("[120,110,100]", "[1,2,3,4]");
        let e = load_params::<PaperParams>(&bad).unwrap_err().to_string();
        assert!(e.contains("parameter `sigma_s`") && e.contains("array of 4"), "{e}");
        let bad = GOOD.replace("\"sigma_a\":0.6", "\"sigma_a\":\"red\"");
        let e = load_params::<PaperParams>(&bad).unwrap_err().to_string();
        assert!(
            e.contains("parameter `sigma_a`") && e.contains("a number or an RGB triple"),
            "{e}"
        );
        let toml = "d = 0.1\nsigma_a = 0.6\nsigma_s = [1, 2]\ng_f = 0.8\n";
        let e = parse_text::<PaperParams>(toml, "p.toml", true).unwrap_err().to_string();
        assert!(
            e.contains("p.toml:3:") && e.contains("sigma_s") && e.contains("RGB triple"),
            "{e}"
        );
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
        let e = load_params::<PaperParams>("mattte").unwrap_err().to_string();
        assert!(
            e.contains("mattte") && e.contains("presets: matte, luster, glossy"),
            "{e}"
        );
    }

    #[test]
    fn preset_by_name() {
        let l = load_params::<PaperParams>("glossy").unwrap();
        assert_eq!(l.value, paperbsdf_core::presets::glossy_photo());
        assert_eq!(l.origin, "preset `glossy`");
        let s = read_source_full("Matte").unwrap();
        assert_eq!(s.preset.as_deref(), Some("Matte"));
    }

    /// A FIT.json as `paperbsdf fit --out` writes it: the `params` object is
    /// read, and an error in it names the fit file's own line.
    #[test]
    fn fit_file_params() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("fit.json");
        let params: serde_json::Value = serde_json::from_str(GOOD).unwrap();
        let fit = serde_json::json!({"model": "paper", "params": params, "rms_log_error": 0.02,
            "data": ["m.csv"], "errors": [{"kind": "R", "theta_i": 0.0}]});
        let text = serde_json::to_string_pretty(&fit).unwrap();
        std::fs::write(&path, &text).unwrap();
        let p = path.to_str().unwrap();
        let l = load_params::<PaperParams>(p).unwrap();
        assert_eq!(l.value, load_params::<PaperParams>(GOOD).unwrap().value);
        assert_eq!(read_source_full(p).unwrap().fit_model.as_deref(), Some("paper"));
        // an out-of-range value: the line is that of `w_b` in the fit file
        let bad = text.replace("\"w_b\": 0.15", "\"w_b\": 1.15");
        let line = bad.lines().position(|l| l.contains("\"w_b\"")).unwrap() + 1;
        std::fs::write(&path, &bad).unwrap();
        let l = load_params::<PaperParams>(p).unwrap();
        let e = l.param_error(l.value.validate().unwrap_err()).to_string();
        assert!(e.starts_with(&format!("{p}:{line}:")) && e.contains("w_b"), "{e}");
        // an unknown key inside params: syntax error at its line in the fit file
        let bad = text.replace("\"g_b\"", "\"gb\"");
        let line = bad.lines().position(|l| l.contains("\"gb\"")).unwrap() + 1;
        std::fs::write(&path, &bad).unwrap();
        let e = load_params::<PaperParams>(p).unwrap_err().to_string();
        assert!(e.starts_with(&format!("{p}:{line}:")) && e.contains("gb"), "{e}");
    }
}
