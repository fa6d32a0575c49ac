//! Every built-in scene loads (with its embedded masks) and renders finite,
//! non-black pixels at a tiny size.

use paperbsdf_render::{builtin, RenderOptions};
use std::sync::atomic::AtomicBool;

#[test]
fn every_builtin_scene_loads_and_renders() {
    let names = builtin::names();
    for expected in ["scene_ref", "checkerboard", "backlit", "lightbox"] {
        assert!(
            names.contains(&expected),
            "built-in `{expected}` missing from {names:?}"
        );
    }
    for name in names {
        let mut scene = builtin::load(name)
            .unwrap()
            .unwrap_or_else(|e| panic!("built-in `{name}`: {e}"));
        assert!(builtin::source(name).is_some());
        assert!(!scene.lights.is_empty(), "`{name}` has no light");
        scene.settings.width = 24;
        scene.settings.height = 16;
        let out = paperbsdf_render::render(
            &scene,
            &RenderOptions {
                spp: 4,
                pass_spp: 4,
                progress: false,
            },
            &AtomicBool::new(false),
        );
        let img = out.film.image();
        assert!(img.iter().all(|p| p.is_finite()), "`{name}`: non-finite pixel");
        let mean: f64 = img.iter().map(|p| p.0.iter().sum::<f64>()).sum::<f64>() / img.len() as f64;
        assert!(mean > 0.0, "`{name}` renders black");
        eprintln!("{name}: mean radiance {:.4}", mean / 3.0);
    }
    assert!(builtin::load("no_such_scene").is_none());
}

/// The lightbox has three or more layers cut along masks (embedded PNG files).
#[test]
fn lightbox_masks_are_embedded() {
    let scene = builtin::load("lightbox").unwrap().unwrap();
    let masked = scene.objects.iter().filter(|o| o.mask.is_some()).count();
    assert!(masked >= 3, "lightbox has {masked} masked layers, expected 3 or more");
}
