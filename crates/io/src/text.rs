//! Text input shared by every reader: a UTF-8 byte-order mark (U+FEFF, written
//! by some spreadsheet programs and Windows editors at the start of a file) is
//! not part of the content; it is stripped once, here, so that every format
//! (JSON and TOML parameter files, direction and measurement CSVs, scenes)
//! treats `BOM + text` exactly as `text`. And the one configuration of the
//! `csv` crate that every CSV reader of the project uses ([`csv_records`]).

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

/// One record of a CSV text (see [`csv_records`]).
#[derive(Debug, Clone)]
pub struct CsvRecord {
    /// 1-based line the record starts at.
    pub line: usize,
    /// Byte offset of the record's start in the text.
    pub byte: usize,
    /// The fields, trimmed of surrounding whitespace (quotes removed).
    pub fields: csv::StringRecord,
}

/// The records of the CSV text `text` (already without a byte-order mark), read
/// with the `csv` crate: fields trimmed, rows of any length, `"` quoting; lines
/// that start with `#` (after blanks) and blank lines are skipped, and each
/// record keeps its line and byte offset in `text`. `origin` names the file in errors.
pub fn csv_records<'a>(text: &'a str, origin: &'a str) -> impl Iterator<Item = Result<CsvRecord, DataError>> + 'a {
    // `csv` takes only a `#` in the first column for a comment: the `#` of an
    // indented comment is moved to the front (lines and offsets stay as they are).
    // The csv reader drops one byte-order mark at the start: give it one, so
    // that a second one (content, see [`strip_bom`]) stays in the text. It
    // counts in the positions of all but the first record.
    let mut data = String::with_capacity(text.len() + 3);
    data.push('\u{feff}');
    for l in text.split_inclusive('\n') {
        let rest = l.trim_start_matches([' ', '\t']);
        match rest.strip_prefix('#') {
            Some(comment) if rest.len() < l.len() => {
                data.push('#');
                data.push_str(&l[..l.len() - rest.len()]);
                data.push_str(comment);
            }
            _ => data.push_str(l),
        }
    }
    // The csv reader gives a record the position where it started looking for
    // it, before the empty and comment lines it skipped: the record starts at
    // the first line after those, and its line is counted here.
    let starts: Vec<usize> = std::iter::once(0)
        .chain(text.match_indices('\n').map(|(i, _)| i + 1))
        .collect();
    let locate = move |byte: u64| {
        let mut b = (byte as usize).saturating_sub(3);
        loop {
            // `b` is on line `k` (1-based), which ends before `next`.
            let k = starts.partition_point(|&s| s <= b);
            let Some(&next) = starts.get(k) else {
                return (k, b);
            };
            let l = text[b..next - 1].trim_end_matches('\r');
            if !(l.is_empty() || l.trim_start_matches([' ', '\t']).starts_with('#')) {
                return (k, b);
            }
            b = next;
        }
    };
    csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_reader(std::io::Cursor::new(data.into_bytes()))
        .into_records()
        .filter_map(move |r| match r {
            Ok(fields) => {
                let (line, byte) = locate(fields.position().expect("the csv reader sets positions").byte());
                // A line of blanks is one empty field.
                let blank = fields.len() == 1 && fields[0].is_empty();
                (!blank).then_some(Ok(CsvRecord { line, byte, fields }))
            }
            Err(e) => Some(Err(DataError::Syntax {
                file: origin.to_string(),
                line: e.position().map_or(0, |p| locate(p.byte()).0),
                column: 0,
                message: e.to_string(),
            })),
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
