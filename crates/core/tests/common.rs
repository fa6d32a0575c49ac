//! Helpers shared by the integration tests: where the reference data lives.
#![allow(dead_code)]

use std::path::PathBuf;

/// `../shared/reference` beside the repository (as in CI), or `$PAPERBSDF_SHARED/reference`.
pub fn reference_dir() -> PathBuf {
    let shared = std::env::var_os("PAPERBSDF_SHARED")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared"));
    shared.join("reference")
}

/// Rows of a CSV file with `#` comment lines, as header -> value maps.
pub fn read_csv(name: &str) -> Vec<std::collections::HashMap<String, String>> {
    let path = reference_dir().join(name);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
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
