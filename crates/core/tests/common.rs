//! Helpers shared by the integration tests: where the reference data lives.
#![allow(dead_code)]

use std::path::PathBuf;

/// The in-repository copy of the independent reference data, `data/reference`
/// (see its README for provenance), or `$PAPERBSDF_REFERENCE` if set.
pub fn reference_dir() -> PathBuf {
    std::env::var_os("PAPERBSDF_REFERENCE")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data/reference"))
}

/// The text of a reference file; a missing file panics with its full path.
pub fn read_text(name: &str) -> String {
    let path = reference_dir().join(name);
    std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("reference data {}: {e} (see data/reference/README.md)", path.display()))
}

/// Rows of a CSV file with `#` comment lines, as header -> value maps.
pub fn read_csv(name: &str) -> Vec<std::collections::HashMap<String, String>> {
    let text = read_text(name);
    let mut lines = text.lines().filter(|l| !l.starts_with('#') && !l.trim().is_empty());
    let header: Vec<String> = lines
        .next()
        .expect("header")
        .split(',')
        .map(|s| s.trim().to_string())
        .collect();
    lines
        .map(|l| {
            header
                .iter()
                .cloned()
                .zip(l.split(',').map(|s| s.trim().to_string()))
                .collect()
        })
        .collect()
}
