//! An interrupted render still writes the image accumulated so far: the
//! library's cancellation flag (what Ctrl-C sets in `paperbsdf render`) stops
//! the render, and the partial film is written and read back.

use paperbsdf_render::{builtin, film, RenderOptions};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

#[test]
fn cancelled_render_writes_the_partial_image() {
    let scene = builtin::load("scene_ref").unwrap().unwrap();
    let (w, h) = (scene.settings.width, scene.settings.height);
    let flag = AtomicBool::new(false);
    // Far more samples than can be taken before the flag is raised after 0.3 s.
    let opts = RenderOptions {
        spp: 1_000_000,
        pass_spp: 4,
        progress: false,
    };
    let out = std::thread::scope(|s| {
        s.spawn(|| {
            std::thread::sleep(Duration::from_millis(300));
            flag.store(true, Ordering::SeqCst);
        });
        paperbsdf_render::render(&scene, &opts, &flag)
    });
    assert!(out.cancelled, "the render was not cancelled");
    assert!(out.samples > 0, "nothing was accumulated before the interruption");
    assert!(out.samples < 1_000_000 * (w * h) as u64);
    assert_eq!(out.samples, out.film.count.iter().map(|&c| c as u64).sum::<u64>());
    // Passes completed before the flag cover every pixel: a pass that was cut
    // short leaves some tiles with one pass fewer, never with none.
    assert!(out.film.min_count() >= 4, "min count {}", out.film.min_count());
    let img = out.film.image();
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("partial.exr");
    let png = dir.path().join("partial.png");
    film::write_exr(&exr, w, h, &img).unwrap();
    film::write_png(&png, w, h, &img, 1.0).unwrap();
    let (rw, rh, back) = film::read_exr(&exr).unwrap();
    assert_eq!((rw, rh), (w, h));
    for (a, b) in img.iter().zip(&back) {
        for c in 0..3 {
            // 32-bit float storage.
            assert!((a.0[c] - b.0[c]).abs() <= 1e-6 * (1.0 + a.0[c].abs()), "{a:?} vs {b:?}");
        }
    }
    let mean: f64 = img.iter().map(|p| p.0[0]).sum::<f64>() / img.len() as f64;
    assert!(mean > 0.0, "the partial image is black");
    assert!(std::fs::metadata(&png).unwrap().len() > 0);
}
