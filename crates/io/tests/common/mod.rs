//! Where the tests find the independent reference data: the repository's
//! `data/reference` (provenance in its README), or `$PAPERBSDF_REFERENCE` if set.
//! Used by this crate's tests and, through `#[path]`, by the CLI's and the
//! renderer's.
#![allow(dead_code)]

use std::path::PathBuf;

/// Path of a reference file; panics naming the full path if it is missing.
pub fn reference(name: &str) -> PathBuf {
    let p = std::env::var_os("PAPERBSDF_REFERENCE")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data/reference"))
        .join(name);
    assert!(
        p.is_file(),
        "reference data {} is missing (see data/reference/README.md)",
        p.display()
    );
    p
}
