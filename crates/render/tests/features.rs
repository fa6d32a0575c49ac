//! Emitters and cut-outs: one- and two-sided area lights, the constant
//! environment, and cut-out masks (holes where the mask is black). Expected
//! values are the emitted radiance itself (a camera ray that meets an emitter
//! directly carries its radiance), checked within stated standard errors.

use paperbsdf_render::spec::Resources;
use paperbsdf_render::{load_scene_str, RenderOptions, Scene};
use std::collections::HashMap;
use std::path::Path;
use std::sync::atomic::AtomicBool;

fn scene(text: &str, dir: &Path) -> Scene {
    load_scene_str(
        text,
        "test.toml",
        &Resources {
            base_dir: dir.to_path_buf(),
            embedded: HashMap::new(),
        },
    )
    .unwrap()
}

fn image(s: &Scene, spp: u32) -> Vec<paperbsdf_core::Rgb> {
    paperbsdf_render::render(
        s,
        &RenderOptions {
            spp,
            pass_spp: spp,
            progress: false,
        },
        &AtomicBool::new(false),
    )
    .film
    .image()
}

/// A square light facing away from the camera (its normal is +y, the camera
/// looks along +y): one-sided it is invisible, two-sided it shows its radiance.
#[test]
fn one_and_two_sided_lights() {
    let text = |two: bool| {
        format!(
            r#"
[render]
width = 8
height = 8
[camera]
origin = [0, -3, 0]
target = [0, 0, 0]
fov = 20
[[shapes]]
type = "rectangle"
emission = 2.5
two_sided = {two}
transform = [{{ rotate = [1, 0, 0], angle = -90 }}]
"#
        )
    };
    let dir = Path::new(".");
    let one = image(&scene(&text(false), dir), 4);
    let two = image(&scene(&text(true), dir), 4);
    // fov 20 at distance 3: the 2 x 2 light covers the whole image.
    for (a, b) in one.iter().zip(&two) {
        assert_eq!(a.0, [0.0; 3], "a one-sided light is black from behind");
        for c in 0..3 {
            assert!(
                (b.0[c] - 2.5).abs() < 1e-12,
                "a two-sided light shows its radiance: {b:?}"
            );
        }
    }
}

/// A black sheet with a cut-out mask (the left half black = hole) in front of a
/// light: through the hole the light is seen, elsewhere the sheet; behind the
/// camera there is a constant environment, which the black sheet does not
/// reflect.
#[test]
fn cut_out_mask_makes_holes() {
    let dir = tempfile::tempdir().unwrap();
    // 4 x 1 mask: columns 0, 1 black (hole), 2, 3 white (paper).
    let img = image::GrayImage::from_fn(4, 1, |x, _| image::Luma([if x < 2 { 0 } else { 255 }]));
    img.save(dir.path().join("half.png")).unwrap();
    let text = r#"
[render]
width = 16
height = 8
[camera]
origin = [0, -3, 0]
target = [0, 0, 0]
fov = 20
[environment]
radiance = 0.25
[materials.black]
type = "black"
[[shapes]]
type = "rectangle"
material = "black"
mask = "half.png"
transform = [{ scale = [2, 2, 1] }, { rotate = [1, 0, 0], angle = 90 }]
[[shapes]]
type = "rectangle"
emission = 4
transform = [{ scale = [4, 4, 1] }, { rotate = [1, 0, 0], angle = 90 }, { translate = [0, 1, 0] }]
"#;
    let s = scene(text, dir.path());
    let px = image(&s, 4);
    let w = 16;
    for y in 0..8 {
        // Well inside each half (the boundary is at the image's centre column).
        for x in [0, 1, 2, 3, 4, 5] {
            assert_eq!(px[y * w + x].0, [4.0; 3], "hole at ({x}, {y})");
        }
        for x in [10, 11, 12, 13, 14, 15] {
            assert_eq!(px[y * w + x].0, [0.0; 3], "paper at ({x}, {y})");
        }
    }
}

/// A camera ray that leaves the scene sees the constant environment.
#[test]
fn constant_environment_is_seen() {
    let text = r#"
[render]
width = 4
height = 4
[camera]
origin = [0, 0, 0]
target = [0, 1, 0]
fov = 60
[environment]
radiance = [0.1, 0.2, 0.3]
"#;
    for p in image(&scene(text, Path::new(".")), 2) {
        assert_eq!(p.0, [0.1, 0.2, 0.3]);
    }
}
