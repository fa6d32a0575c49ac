//! Issue 16, end to end: bad or extreme input never hangs, crashes or quietly
//! gives a wrong answer. Each test is one case of the issue.

mod support;

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};
use support::{fails_with, output as run, text, ROOT};

const P: &str = r#"{"d":0.05,"sigma_a":0.5,"sigma_s":40,"g_f":0.8,"g_b":-0.3,"w_b":0.2,"eta_f":1.5,"eta_b":1.5,"m_f":0.3,"m_b":0.3,"dist_f":"ggx","dist_b":"beckmann"}"#;
const GLASS: &str = r#"{"eta":1.5,"m":0.3,"dist":"ggx"}"#;

fn sim(extra: &[&str]) -> Vec<String> {
    let mut v: Vec<String> = ["simulate", "--params", P].iter().map(|s| s.to_string()).collect();
    v.extend(extra.iter().map(|s| s.to_string()));
    v
}

fn strs(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

#[test]
fn simulate_limits_are_range_errors() {
    // --max-samples 0 was accepted.
    fails_with(
        &strs(&sim(&[
            "--totals",
            "--theta-i",
            "0",
            "--rel-stderr",
            "0.1",
            "--max-samples",
            "0",
        ])),
        &["--max-samples = 0"],
    );
    // --batches 4000000000 aborted with SIGABRT allocating 64 GB.
    fails_with(
        &strs(&sim(&["--totals", "--theta-i", "0", "--batches", "4000000000"])),
        &["--batches = 4000000000", "[2, 100000]"],
    );
    // --theta-o -89:89:0.002 (89001 angles) was accepted.
    fails_with(
        &strs(&sim(&["--theta-i", "0", "--theta-o", "-89:89:0.002"])),
        &["--theta-o", "89001 angles", "limit of 1000"],
    );
}

#[test]
fn simulate_reports_a_missed_precision_target() {
    let o = run(&strs(&sim(&[
        "--totals",
        "--theta-i",
        "30",
        "--rel-stderr",
        "1e-12",
        "--max-samples",
        "4096",
        "--batches",
        "8",
    ])));
    let (out, err) = (text(&o.stdout), text(&o.stderr));
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("warning") && err.contains("not reached") && err.contains("1e-12"),
        "{err}"
    );
    let note = out
        .lines()
        .find(|l| l.starts_with("# theta_i 30:"))
        .unwrap_or_else(|| panic!("{out}"));
    assert!(
        note.contains("NOT reached") && note.contains("worst relative standard error"),
        "{note}"
    );
    // The achieved precision in the note is the one of the printed estimates.
    let row: Vec<f64> = out
        .lines()
        .find(|l| l.starts_with("30,"))
        .unwrap()
        .split(',')
        .map(|x| x.parse().unwrap())
        .collect();
    let worst = (row[2] / row[1]).max(row[4] / row[3]);
    let shown: f64 = note
        .split("error ")
        .nth(1)
        .unwrap()
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!((shown - worst).abs() <= 1e-3 * worst, "{shown} vs {worst}");
    // A target that is reached says so.
    let o = run(&strs(&sim(&[
        "--totals",
        "--theta-i",
        "30",
        "--rel-stderr",
        "0.2",
        "--batches",
        "8",
    ])));
    assert!(
        text(&o.stdout).contains("reached)") && !text(&o.stderr).contains("warning"),
        "{}",
        text(&o.stderr)
    );
}

/// Progress was not shown when standard error is not a terminal: now a line
/// every 10 s (here every 0.1 s, set by PAPERBSDF_PROGRESS_SECONDS).
#[test]
fn simulate_shows_progress_off_a_terminal() {
    let o = Command::new(env!("CARGO_BIN_EXE_paperbsdf"))
        .args(strs(&sim(&[
            "--totals",
            "--theta-i",
            "30",
            "--samples",
            "400000",
            "--batches",
            "8",
        ])))
        .env("PAPERBSDF_PROGRESS_SECONDS", "0.1")
        .current_dir(ROOT)
        .output()
        .unwrap();
    let err = text(&o.stderr);
    assert!(o.status.success(), "{err}");
    let lines: Vec<&str> = err
        .lines()
        .filter(|l| l.starts_with("totals: ") && l.contains(" walks ("))
        .collect();
    assert!(!lines.is_empty(), "no progress line: {err}");
    assert!(lines[0].contains("of 400000 walks"), "{err}");
}

/// sigma_s = 1e308 (or d = 1e6 with sigma_s = 1e6) ran for minutes without
/// output (100 walks in 32 s), and its answer was wrong (R + T = 0.64 for a
/// conservative slab, from rounding of depths): such slabs are refused with the
/// reason. Thick but representable slabs run with every walk bounded, cut
/// walks reported, or are refused up front with the predicted cost and time.
#[test]
fn simulate_with_huge_sigma_s_is_bounded() {
    for (d, s) in [("0.05", "1e308"), ("1e6", "1e6")] {
        let p = P
            .replace("\"sigma_s\":40", &format!("\"sigma_s\":{s}"))
            .replace("\"d\":0.05", &format!("\"d\":{d}"));
        let t = Instant::now();
        fails_with(
            &["simulate", "--params", &p, "--totals", "--theta-i", "30"],
            &["sigma_t * d", "1e9 mean free paths"],
        );
        assert!(t.elapsed() < Duration::from_secs(10));
    }
    // 5e5 mean free paths, nearly conservative (albedo 1 - 5e-8), between
    // smooth faces (m = 0; rough single-scattering faces lose energy themselves).
    let p = P
        .replace("\"sigma_s\":40", "\"sigma_s\":1e7")
        .replace("\"m_f\":0.3,\"m_b\":0.3", "\"m_f\":0,\"m_b\":0");
    let t = Instant::now();
    let o = run(&[
        "simulate",
        "--params",
        &p,
        "--totals",
        "--theta-i",
        "30",
        "--samples",
        "256",
        "--batches",
        "16",
    ]);
    let (out, err) = (text(&o.stdout), text(&o.stderr));
    assert!(t.elapsed() < Duration::from_secs(120), "took {:?}", t.elapsed());
    assert!(o.status.success(), "{err}");
    let row: Vec<f64> = out
        .lines()
        .find(|l| l.starts_with("30,"))
        .unwrap()
        .split(',')
        .map(|x| x.parse().unwrap())
        .collect();
    // Every walk's flux leaves as R or T (absorption is below 1e-3 of it), except what cut walks lost,
    // which the output states. 4 sigma of the two estimates (t with 15 degrees of freedom: p < 0.002).
    let cut: f64 = out
        .lines()
        .find(|l| l.contains("walks were cut"))
        .map(|l| {
            l.split("at most ")
                .nth(1)
                .unwrap()
                .split(' ')
                .next()
                .unwrap()
                .parse()
                .unwrap()
        })
        .unwrap_or(0.0);
    let (sum, tol) = (row[1] + row[3], 4.0 * (row[2] + row[4]) + 1e-3);
    assert!(sum <= 1.0 + tol && sum >= 1.0 - cut - tol, "{out}");
    // The default sample count with a small --max-collisions is refused before any walk, with reason and time.
    let e = fails_with(
        &[
            "simulate",
            "--params",
            &p,
            "--totals",
            "--theta-i",
            "30",
            "--max-collisions",
            "1e6",
        ],
        &["collisions", "mean free paths", "--max-collisions", "about", "albedo"],
    );
    assert!(e.contains("collisions/s"), "{e}");
}

/// The per-walk collision cap (default 1e7, `--max-walk-collisions`) is
/// reached and said: a conservative slab 1e4 mean free paths thick between
/// index-matched faces, where every walk carries unit flux until it leaves or
/// is cut. The warning (standard error) and the note (in the table) give the
/// cut walks and the flux they took, which is exactly what `R + T` lacks; the
/// header records the cap. A cap of 0 is a range error.
#[test]
fn simulate_reports_walks_cut_at_the_collision_cap() {
    let p = r#"{"d":1,"sigma_a":0,"sigma_s":1e4,"g_f":0,"g_b":0,"w_b":0,"eta_f":1,"eta_b":1,"m_f":0,"m_b":0,"dist_f":"ggx","dist_b":"ggx"}"#;
    let base = ["simulate", "--params", p, "--samples", "2048", "--batches", "8"];
    let t = Instant::now();
    let o = run(&[
        &base[..],
        &["--totals", "--theta-i", "30", "--max-walk-collisions", "1000"],
    ]
    .concat());
    let (out, err) = (text(&o.stdout), text(&o.stderr));
    assert!(o.status.success(), "{err}");
    assert!(t.elapsed() < Duration::from_secs(60), "took {:?}", t.elapsed());
    assert!(
        out.starts_with("# paperbsdf simulate") && out.lines().next().unwrap().contains("walks cut at 1000 collisions"),
        "{out}"
    );
    let warning = err
        .lines()
        .find(|l| l.starts_with("warning: theta_i 30: ") && l.contains("walks were cut at 1000 collisions"))
        .unwrap_or_else(|| panic!("no warning of cut walks: {err}"));
    let note = out
        .lines()
        .find(|l| l.starts_with("# WARNING theta_i 30: ") && l.contains("walks were cut at 1000 collisions"))
        .unwrap_or_else(|| panic!("no note of cut walks: {out}"));
    let cut: u64 = note
        .split(": ")
        .nth(1)
        .unwrap()
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let frac: f64 = note
        .split("at most ")
        .nth(1)
        .unwrap()
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(warning.contains(&format!("{cut} walks")), "{warning}");
    assert!(cut > 0 && (frac - cut as f64 / 2048.0).abs() < 1e-3 * frac, "{note}");
    let row: Vec<f64> = out
        .lines()
        .find(|l| l.starts_with("30,"))
        .unwrap()
        .split(',')
        .map(|x| x.parse().unwrap())
        .collect();
    // Unit flux per walk, nothing absorbed: R + T = 1 - cut / samples (to the printed digits).
    assert!((row[1] + row[3] - (1.0 - cut as f64 / 2048.0)).abs() < 1e-5, "{out}");
    // BSDF values: the same warning.
    let o = run(&[
        &base[..],
        &["--theta-i", "30", "--theta-o", "0", "--max-walk-collisions", "1000"],
    ]
    .concat());
    let err = text(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("walks were cut at 1000 collisions (--max-walk-collisions)"),
        "{err}"
    );
    // Without the option nothing is said about a cut of a thin slab.
    let o = run(&[
        "simulate",
        "--params",
        P,
        "--totals",
        "--theta-i",
        "30",
        "--samples",
        "256",
        "--batches",
        "8",
    ]);
    assert!(
        o.status.success() && !text(&o.stderr).contains("cut"),
        "{}",
        text(&o.stderr)
    );
    fails_with(
        &[
            &base[..],
            &["--totals", "--theta-i", "30", "--max-walk-collisions", "0"],
        ]
        .concat(),
        &["--max-walk-collisions = 0", "allowed range [1, "],
    );
}

#[test]
fn angles_print_cleanly_and_single_angles_work() {
    // `--theta-o 0:1:0.1` printed 0.30000000000000004.
    let o = run(&[
        "eval",
        "--model",
        "rough-dielectric",
        "--params",
        GLASS,
        "--theta-i",
        "30",
        "--theta-o",
        "0:1:0.1",
    ]);
    let out = text(&o.stdout);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let angles: Vec<&str> = out
        .lines()
        .skip(1)
        .filter(|l| l.starts_with("R,"))
        .map(|l| l.split(',').nth(2).unwrap())
        .collect();
    assert_eq!(
        angles,
        ["0", "0.1", "0.2", "0.3", "0.4", "0.5", "0.6", "0.7", "0.8", "0.9", "1"]
    );
    // Issue 17 item 7: `--theta-o 0` was rejected; a single angle works, in eval and simulate.
    let o = run(&[
        "eval",
        "--model",
        "rough-dielectric",
        "--params",
        GLASS,
        "--theta-i",
        "30",
        "--theta-o",
        "0",
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert_eq!(text(&o.stdout).lines().count(), 3);
    let o = run(&strs(&sim(&[
        "--theta-i",
        "30",
        "--theta-o",
        "-30",
        "--samples",
        "256",
        "--batches",
        "4",
    ])));
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(text(&o.stdout).lines().any(|l| l.starts_with("R,30,-30,")));
    // `--theta-o -90:90:inf` reported `--theta-o = NaN`.
    let e = fails_with(
        &[
            "eval",
            "--model",
            "rough-dielectric",
            "--params",
            GLASS,
            "--theta-i",
            "30",
            "--theta-o",
            "-90:90:inf",
        ],
        &["-90:90:inf", "STEP `inf`"],
    );
    assert!(!e.contains("NaN"), "{e}");
}

#[test]
fn albedo_refuses_grazing_light_as_its_help_says() {
    fails_with(
        &[
            "albedo",
            "--model",
            "rough-dielectric",
            "--params",
            GLASS,
            "--theta-i",
            "90",
        ],
        &["--theta-i = 90", "[0, 90)"],
    );
    let o = run(&[
        "albedo",
        "--model",
        "rough-dielectric",
        "--params",
        GLASS,
        "--theta-i",
        "89.9",
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
}

#[test]
fn errors_are_printed_once() {
    let e = fails_with(
        &[
            "eval",
            "--model",
            "paper",
            "--params",
            "/nonexistent/p.json",
            "--theta-i",
            "0",
            "--theta-o",
            "0",
        ],
        &["/nonexistent/p.json"],
    );
    assert!(!e.contains("caused by"), "{e}");
    assert_eq!(e.matches("No such file").count(), 1, "{e}");
}

#[test]
fn byte_order_mark_in_a_direction_file() {
    let d = tempfile::tempdir().unwrap();
    let f = d.path().join("dirs.csv");
    std::fs::write(&f, "\u{feff}wi_x,wi_y,wi_z,wo_x,wo_y,wo_z\n0,0,1,0,0,1\n").unwrap();
    let o = run(&[
        "eval",
        "--model",
        "rough-dielectric",
        "--params",
        GLASS,
        "--dirs",
        f.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(text(&o.stdout).starts_with("wi_x,"), "{}", text(&o.stdout));
}

#[cfg(unix)]
#[test]
fn out_through_links_fifos_and_devices() {
    let d = tempfile::tempdir().unwrap();
    let real = d.path().join("real.csv");
    std::fs::write(&real, "old").unwrap();
    let link = d.path().join("link.csv");
    std::os::unix::fs::symlink(&real, &link).unwrap();
    let eval = |out: &Path| {
        run(&[
            "eval",
            "--model",
            "rough-dielectric",
            "--params",
            GLASS,
            "--theta-i",
            "0",
            "--theta-o",
            "0",
            "--out",
            out.to_str().unwrap(),
        ])
    };
    // Through a symbolic link: the target is written, the link stays.
    assert!(eval(&link).status.success());
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
    assert!(std::fs::read_to_string(&real).unwrap().starts_with("kind,"));
    // A FIFO is refused and left as it was.
    let fifo = d.path().join("pipe");
    assert!(Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    let o = eval(&fifo);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("FIFO"), "{}", text(&o.stderr));
    use std::os::unix::fs::FileTypeExt;
    assert!(std::fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo());
    // A device node is never replaced.
    fails_with(
        &[
            "eval",
            "--model",
            "rough-dielectric",
            "--params",
            GLASS,
            "--theta-i",
            "0",
            "--theta-o",
            "0",
            "--out",
            "/dev/null",
        ],
        &["/dev/null", "device"],
    );
    let names: Vec<_> = std::fs::read_dir(d.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 3, "no temporary file left: {names:?}");
}

/// `fit --out` into a missing directory failed only after the whole fit;
/// every command now checks its output path before the work starts.
#[test]
fn output_paths_are_checked_before_the_work() {
    let missing = "/nonexistent_dir_16/out";
    for args in [
        vec![
            "fit",
            "data/matte.csv",
            "--model",
            "lambert-glass",
            "--out",
            "/nonexistent_dir_16/fit.json",
        ],
        vec![
            "simulate",
            "--params",
            P,
            "--totals",
            "--theta-i",
            "0",
            "--out",
            "/nonexistent_dir_16/s.csv",
        ],
        vec![
            "eval",
            "--model",
            "rough-dielectric",
            "--params",
            GLASS,
            "--theta-i",
            "0",
            "--theta-o",
            "0",
            "--out",
            "/nonexistent_dir_16/e.csv",
        ],
        vec!["plot", "data/matte.csv", "--out", "/nonexistent_dir_16/p.png"],
        vec!["render", "checkerboard", "--spp", "1", "--width", "8", "--out", missing],
    ] {
        let t = Instant::now();
        let o = run(&args);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains("/nonexistent_dir_16") && err.contains("does not exist"),
            "{err}"
        );
        // plot printed `BackendError(DrawingError(ImageError(IoError(Os {...}))))`.
        assert!(!err.contains("Os {") && !err.contains("Error("), "{err}");
        assert!(text(&o.stdout).is_empty(), "work was done first: {}", text(&o.stdout));
        assert!(t.elapsed() < Duration::from_secs(20), "{args:?} took {:?}", t.elapsed());
    }
}

#[test]
fn render_keeps_the_stem_as_given() {
    let d = tempfile::tempdir().unwrap();
    for stem in ["run.v2", "run.v3"] {
        let o = run(&[
            "render",
            "checkerboard",
            "--spp",
            "1",
            "--width",
            "8",
            "--out",
            d.path().join(stem).to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", text(&o.stderr));
    }
    let mut names: Vec<String> = std::fs::read_dir(d.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["run.v2.exr", "run.v2.png", "run.v3.exr", "run.v3.png"]);
}

/// `render --width 16384` started a 15 GB render and aborted under a memory
/// limit; it is refused before it starts when the memory is not there.
#[test]
fn render_refuses_an_image_larger_than_memory() {
    let need = paperbsdf_render::estimate_memory_bytes(16384, 16384);
    match paperbsdf_render::available_memory_bytes() {
        Some(avail) if avail < need => {
            let d = tempfile::tempdir().unwrap();
            let t = Instant::now();
            let e = fails_with(
                &[
                    "render",
                    "checkerboard",
                    "--width",
                    "16384",
                    "--height",
                    "16384",
                    "--out",
                    d.path().join("big").to_str().unwrap(),
                ],
                &["16384x16384", "GB of memory", "available"],
            );
            assert!(t.elapsed() < Duration::from_secs(20), "{e}");
        }
        _ => eprintln!("skipped: this machine has more than {need:e} bytes available"),
    }
}

/// Two Ctrl-C in a row (the second while the images may be being written)
/// leave no temporary file, and the exit code is 130.
#[cfg(unix)]
#[test]
fn double_sigint_leaves_no_temporary_file() {
    for delay_ms in [0u64, 5, 50] {
        let d = tempfile::tempdir().unwrap();
        let mut child = Command::new(env!("CARGO_BIN_EXE_paperbsdf"))
            .args([
                "render",
                "checkerboard",
                "--spp",
                "100000",
                "--width",
                "480",
                "--threads",
                "1",
                "--out",
            ])
            .arg(d.path().join("img"))
            .current_dir(ROOT)
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_millis(1500));
        let pid = child.id().to_string();
        Command::new("kill").args(["-INT", &pid]).status().unwrap();
        std::thread::sleep(Duration::from_millis(delay_ms));
        Command::new("kill").args(["-INT", &pid]).status().unwrap();
        let t0 = Instant::now();
        let status = loop {
            if let Some(s) = child.try_wait().unwrap() {
                break s;
            }
            if t0.elapsed() > Duration::from_secs(30) {
                let _ = child.kill();
                panic!("did not stop within 30 s of two SIGINTs");
            }
            std::thread::sleep(Duration::from_millis(20));
        };
        assert_eq!(status.code(), Some(130));
        let tmp: Vec<_> = std::fs::read_dir(d.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.contains("tmp"))
            .collect();
        assert!(tmp.is_empty(), "left behind: {tmp:?}");
    }
}
