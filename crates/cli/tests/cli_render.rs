//! `paperbsdf render`: built-in scenes by name, `--spp`/`--out`, scene-file
//! errors, and Ctrl-C (SIGINT) still writing the image accumulated so far.

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_paperbsdf"))
}

#[test]
fn renders_a_builtin_scene_with_spp_and_out() {
    let dir = tempfile::tempdir().unwrap();
    let stem = dir.path().join("bl");
    let out = bin()
        .args(["render", "backlit", "--spp", "1", "--width", "24", "--out"])
        .arg(stem.with_extension("png"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("24x16 at 1 spp"), "{err}");
    assert!(stem.with_extension("exr").exists() && stem.with_extension("png").exists());
}

#[test]
fn scene_file_errors_name_file_and_entry() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("bad.toml");
    std::fs::write(
        &p,
        "[camera]\norigin = [0, -3, 1]\ntarget = [0, 0, 0]\nfov = 40\n\n[materials.sheet]\ntype = \"paper\"\npreset = \"matte\"\nroughness = 0.3\n",
    )
    .unwrap();
    let out = bin().arg("render").arg(&p).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("bad.toml") && err.contains("materials.sheet") && err.contains("roughness"),
        "{err}"
    );
    let out = bin().args(["render", "no_such_builtin"]).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(err.contains("checkerboard") && err.contains("lightbox"), "{err}");
}

/// SIGINT (what Ctrl-C sends) stops the render; the partial image is written
/// and the command exits with 130 (issue 16: it exited 0), saying it was interrupted.
#[cfg(unix)]
#[test]
fn sigint_writes_the_partial_image() {
    let dir = tempfile::tempdir().unwrap();
    let stem = dir.path().join("partial");
    let mut child = bin()
        .args(["render", "scene_ref", "--spp", "10000000", "--threads", "1", "--out"])
        .arg(&stem)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(1500));
    let st = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(st.success(), "kill -INT failed");
    let t0 = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if t0.elapsed() > Duration::from_secs(30) {
            let _ = child.kill();
            panic!("the render did not stop within 30 s of SIGINT");
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let mut err = String::new();
    std::io::Read::read_to_string(child.stderr.as_mut().unwrap(), &mut err).unwrap();
    assert_eq!(status.code(), Some(130), "exit status {status}: {err}");
    assert!(err.contains("INTERRUPTED"), "{err}");
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left.len(), 2, "only the two images, no temporary file: {left:?}");
    let exr = stem.with_extension("exr");
    assert!(exr.exists() && stem.with_extension("png").exists(), "{err}");
    let (w, h, img) = paperbsdf_render::film::read_exr(&exr).unwrap();
    assert_eq!((w, h), (96, 72));
    assert!(
        img.iter().map(|p| p.0[0]).sum::<f64>() > 0.0,
        "the partial image is black"
    );
}
