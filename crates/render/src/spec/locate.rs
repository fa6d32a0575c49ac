//! Locating an error in a scene file: the entry (table and key) and the line
//! at a byte offset, from the headers before it. TOML parse errors carry the
//! offset of the key or value at fault; this turns it into the entry that
//! messages name.

/// The entry that byte `offset` of a scene file lies in, and its line: the table
/// and the key the line assigns, e.g. `materials.NAME.d, line 12`,
/// `shapes[2].radius, line 40`, `camera, line 3`.
pub(super) fn entry_at(text: &str, offset: usize) -> String {
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    // The headers up to the end of this line: an offset at a header (a table's
    // own error, such as a missing key) lies in that table.
    let line_end = text[offset..].find('\n').map_or(text.len(), |i| offset + i);
    let mut table: Option<String> = None;
    let mut shapes = 0usize;
    // A header's name is a dotted key: this excludes rows of multi-line arrays such as `[1, 2],`.
    let is_key = |h: &str| {
        !h.is_empty()
            && h.chars()
                .all(|c| c.is_alphanumeric() || matches!(c, '_' | '-' | '.' | ' ' | '"' | '\''))
    };
    for l in text[..line_end].lines() {
        let t = l.trim();
        let t = t.split('#').next().unwrap_or("").trim_end();
        if !t.ends_with(']') {
            continue;
        }
        let t = &t[..t.len() - 1];
        if let Some(h) = t
            .strip_prefix("[[")
            .and_then(|r| r.strip_suffix(']'))
            .filter(|h| is_key(h))
        {
            let h = h.trim();
            if h == "shapes" {
                table = Some(format!("shapes[{shapes}]"));
                shapes += 1;
            } else {
                table = Some(h.to_string());
            }
        } else if let Some(h) = t.strip_prefix('[').filter(|h| is_key(h)) {
            table = Some(h.trim().to_string());
        }
    }
    // The key the line assigns, if it is a `key = value` line.
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let this_line = text[line_start..].lines().next().unwrap_or("");
    let key = this_line
        .split_once('=')
        .map(|(k, _)| k.trim())
        .filter(|k| is_key(k) && !k.contains(' '));
    let path = match (table, key) {
        (Some(t), Some(k)) => Some(format!("{t}.{k}")),
        (Some(t), None) => Some(t),
        (None, Some(k)) => Some(k.to_string()),
        (None, None) => None,
    };
    match path {
        Some(t) => format!("{t}, line {line}"),
        None => format!("line {line}"),
    }
}
