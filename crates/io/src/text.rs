//! Text input shared by every reader: a UTF-8 byte-order mark (U+FEFF, written
//! by some spreadsheet programs and Windows editors at the start of a file) is
//! not part of the content; it is stripped once, here, so that every format
//! (JSON and TOML parameter files, direction and measurement CSVs, scenes)
//! treats `BOM + text` exactly as `text`.

use crate::DataError;

/// `text` without one leading byte-order mark (U+FEFF); other text unchanged.
pub fn strip_bom(text: &str) -> &str {
    text.strip_prefix('\u{feff}').unwrap_or(text)
}

/// Reads the UTF-8 text file `path` without a leading byte-order mark; errors name the file.
pub fn read_text(path: &str) -> Result<String, DataError> {
    let text = std::fs::read_to_string(path).map_err(|e| DataError::Io {
        file: path.to_string(),
        source: e,
    })?;
    Ok(match text.strip_prefix('\u{feff}') {
        Some(rest) => rest.to_string(),
        None => text,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn strips_one_bom_only() {
        assert_eq!(strip_bom("\u{feff}a,b"), "a,b");
        assert_eq!(strip_bom("a,b"), "a,b");
        // Only one mark is a byte-order mark; a second one is content.
        assert_eq!(strip_bom("\u{feff}\u{feff}x"), "\u{feff}x");
        assert_eq!(strip_bom(""), "");
    }
}
