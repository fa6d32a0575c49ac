//! What the CLI's end-to-end tests share: running the `paperbsdf` binary and
//! checking that a failure is one clean error (exit code 2, `error: ...`, no panic).
#![allow(dead_code)]

use std::path::Path;
use std::process::{Command, Output};

/// The repository's root, where the tests' relative paths (`data/...`, `params/...`) start.
pub const ROOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");

/// Runs `paperbsdf ARGS` in `dir`.
pub fn output_in(dir: impl AsRef<Path>, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_paperbsdf"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

/// Runs `paperbsdf ARGS` in the repository's root.
pub fn output(args: &[&str]) -> Output {
    output_in(ROOT, args)
}

/// Bytes of an output stream as text.
pub fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// Runs `paperbsdf ARGS` in `dir`: whether it succeeded, its standard output and error.
pub fn run_in(dir: impl AsRef<Path>, args: &[&str]) -> (bool, String, String) {
    let o = output_in(dir, args);
    (o.status.success(), text(&o.stdout), text(&o.stderr))
}

/// [`run_in`] the repository's root.
pub fn run(args: &[&str]) -> (bool, String, String) {
    run_in(ROOT, args)
}

/// Checks that `stderr` is one clean error (no panic) containing every part.
pub fn assert_clean_error(stderr: &str, parts: &[&str]) {
    assert!(stderr.starts_with("error: "), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    for p in parts {
        assert!(stderr.contains(p), "expected `{p}` in: {stderr}");
    }
}

/// Runs `paperbsdf ARGS` in the repository's root, which must fail with exit
/// code 2 and one clean error containing every part; returns the error.
pub fn fails_with(args: &[&str], parts: &[&str]) -> String {
    let o = output(args);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    assert_clean_error(&err, parts);
    err
}
