//! The renderer against Mitsuba 3: `reference/scene_ref.exr` (16384 spp, made
//! by `reference/tools/renderref.py`) and the same scene (`scenes/scene_ref.toml`)
//! rendered here. The whole-image mean and every 8x8-pixel block mean, per
//! channel, must agree within 3 standard errors plus 1% of the reference.
//! Standard errors come from the per-pixel sample variance (pixels are
//! independent, so a block mean's variance is the sum of its pixels' variances
//! of the mean over 64^2); the reference's own error is that of an estimator
//! with the same per-sample variance at 16384 spp.

use paperbsdf_core::Rgb;
use paperbsdf_render::{builtin, film, RenderOptions};
use std::sync::atomic::AtomicBool;

#[path = "../../io/tests/common/mod.rs"]
mod common;

const REF_SPP: f64 = 16384.0;

fn reference() -> (usize, usize, Vec<Rgb>) {
    let p = common::reference("scene_ref.exr");
    film::read_exr(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

#[test]
fn scene_ref_matches_mitsuba() {
    let (rw, rh, refimg) = reference();
    let scene = builtin::load("scene_ref").unwrap().unwrap();
    let (w, h) = (scene.settings.width, scene.settings.height);
    assert_eq!((w, h), (rw, rh), "image size of the reference");
    let spp = 256;
    let out = paperbsdf_render::render(
        &scene,
        &RenderOptions {
            spp,
            pass_spp: 16,
            progress: false,
        },
        &AtomicBool::new(false),
    );
    let film = &out.film;
    eprintln!(
        "scene_ref: {} spp in {:.2} s, {:.3} M samples/s",
        spp,
        out.elapsed.as_secs_f64(),
        out.samples_per_second() / 1e6
    );
    let ref_scale = spp as f64 / REF_SPP;
    // Block statistics, blocks of 8x8 (96x72 -> 12x9 blocks) plus the whole image as one block.
    let mut blocks: Vec<(String, Vec<usize>)> = vec![];
    for by in 0..h / 8 {
        for bx in 0..w / 8 {
            let px = (0..64).map(|k| (by * 8 + k / 8) * w + bx * 8 + k % 8).collect();
            blocks.push((format!("block ({bx},{by})"), px));
        }
    }
    blocks.push(("whole image".into(), (0..w * h).collect()));
    let mut worst = (0.0f64, String::new());
    let mut failures = vec![];
    for (name, px) in &blocks {
        let n = px.len() as f64;
        let mut mine = Rgb::ZERO;
        let mut var = Rgb::ZERO;
        let mut refm = Rgb::ZERO;
        for &i in px {
            mine += film.mean(i);
            var += film.var_of_mean(i);
            refm += refimg[i];
        }
        mine = mine / n;
        refm = refm / n;
        var = var / (n * n);
        for c in 0..3 {
            let se = (var.0[c] * (1.0 + ref_scale)).sqrt();
            let diff = (mine.0[c] - refm.0[c]).abs();
            let tol = 3.0 * se + 0.01 * refm.0[c];
            let sig = diff / se.max(1e-12);
            if sig > worst.0 {
                worst = (
                    sig,
                    format!(
                        "{name} channel {c}: mine {:.5} ref {:.5} se {:.5}",
                        mine.0[c], refm.0[c], se
                    ),
                );
            }
            if diff > tol {
                failures.push(format!(
                    "{name} channel {c}: mine {:.5} ref {:.5} |diff| {diff:.5} > tol {tol:.5} ({sig:.2} sigma)",
                    mine.0[c], refm.0[c]
                ));
            }
            if name == "whole image" {
                eprintln!(
                    "whole image channel {c}: mine {:.5} ref {:.5} ({sig:.2} sigma, se {se:.2e})",
                    mine.0[c], refm.0[c]
                );
            }
        }
    }
    eprintln!("worst deviation {:.2} sigma at {}", worst.0, worst.1);
    assert!(
        failures.is_empty(),
        "{} of {} comparisons out of tolerance:\n{}",
        failures.len(),
        blocks.len() * 3,
        failures.join("\n")
    );
}

/// The same seed gives the same image whatever the pass split or thread count.
#[test]
fn deterministic_for_a_seed() {
    let mut scene = builtin::load("scene_ref").unwrap().unwrap();
    scene.settings.width = 24;
    scene.settings.height = 18;
    let a = paperbsdf_render::render(
        &scene,
        &RenderOptions {
            spp: 8,
            pass_spp: 8,
            progress: false,
        },
        &AtomicBool::new(false),
    );
    let (b, _) = paperbsdf_render::render_with_threads(
        &scene,
        &RenderOptions {
            spp: 8,
            pass_spp: 3,
            progress: false,
        },
        &AtomicBool::new(false),
        Some(1),
    )
    .unwrap();
    // Equal up to the order of floating-point additions.
    for (x, y) in a.film.sum.iter().zip(&b.film.sum) {
        for c in 0..3 {
            assert!((x[c] - y[c]).abs() <= 1e-12 * (1.0 + x[c].abs()), "{x:?} vs {y:?}");
        }
    }
    scene.settings.seed = 7;
    let c = paperbsdf_render::render(
        &scene,
        &RenderOptions {
            spp: 8,
            pass_spp: 8,
            progress: false,
        },
        &AtomicBool::new(false),
    );
    assert_ne!(a.film.sum, c.film.sum, "a different seed must give different samples");
}

/// A cancelled render keeps a consistent partial image (every pixel averages its own samples).
#[test]
fn cancel_keeps_partial_image() {
    let scene = builtin::load("scene_ref").unwrap().unwrap();
    let flag = AtomicBool::new(true);
    let out = paperbsdf_render::render(
        &scene,
        &RenderOptions {
            spp: 16,
            pass_spp: 4,
            progress: false,
        },
        &flag,
    );
    assert!(out.cancelled);
    assert_eq!(out.samples, out.film.count.iter().map(|&c| c as u64).sum::<u64>());
}
