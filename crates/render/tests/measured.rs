//! The `measured` material (an RGL `.bsdf` file, `paperbsdf_io::MeasuredBsdf`).
//!
//! 1. A furnace test: one flat sheet of the measured satin in a uniform
//!    environment of radiance 1. A ray from the camera meets the sheet once and
//!    every path leaves it to the environment (a flat sheet cannot see itself),
//!    so each pixel is `int f(wi, wo) cos(theta_i) dwi`, the directional albedo
//!    of the file's BRDF for that pixel's view direction `wo`, computed here
//!    from `MeasuredBsdf` by `paperbsdf_core::bsdf::sampled_albedo` (256 x 256
//!    stratified samples). Tolerance: 4.5 standard errors of the render per
//!    pixel, 4 for the image mean. The file's `.bsdf` path is relative to the
//!    scene file, as for every file a scene names.
//! 2. Seen from behind, the sheet is black (the format has no back side and no
//!    transmission): every pixel is exactly zero.
//! 3. A missing file and a file that is not a tensor file are errors that name
//!    the scene file, the material and the `.bsdf` path.

use paperbsdf_core::bsdf::sampled_albedo;
use paperbsdf_core::{DVec3, Rgb};
use paperbsdf_io::MeasuredBsdf;
use paperbsdf_render::{load_scene, Film, RenderOptions, Scene};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

fn satin() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/reference/rgl/satin_rosaline_rgb.bsdf")
}

fn render(scene: &Scene, spp: u32) -> Film {
    paperbsdf_render::render(
        scene,
        &RenderOptions {
            spp,
            pass_spp: spp,
            progress: false,
        },
        &AtomicBool::new(false),
    )
    .film
}

/// A scene with one 4 x 4 sheet (normal +z) of the material `materials.cloth`
/// (the lines `material`) in a uniform environment of radiance 1, seen from `origin`.
fn sheet_scene(material: &str, origin: [f64; 3]) -> String {
    format!(
        r#"
[render]
width = 8
height = 6
seed = 5

[camera]
origin = [{}, {}, {}]
target = [0, 0, 0]
up = [0, 1, 0]
fov = 30

[environment]
radiance = 1

[materials.cloth]
{material}

[[shapes]]
type = "rectangle"
material = "cloth"
transform = [{{ scale = [4, 4, 1] }}]
"#,
        origin[0], origin[1], origin[2]
    )
}

/// Writes the scene `text` as `dir/scene.toml` (with the satin file beside it
/// as `cloth/satin.bsdf`) and loads it.
fn load_in(dir: &Path, text: &str) -> Result<Scene, String> {
    std::fs::create_dir_all(dir.join("cloth")).unwrap();
    std::fs::copy(satin(), dir.join("cloth/satin.bsdf")).unwrap();
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    load_scene(&path).map_err(|e| e.to_string())
}

#[test]
fn measured_sheet_renders_its_directional_albedo() {
    let dir = tempfile::tempdir().unwrap();
    let origin = [0.0, -2.0, 2.0];
    let scene = load_in(
        dir.path(),
        &sheet_scene("type = \"measured\"\nfile = \"cloth/satin.bsdf\"", origin),
    )
    .unwrap();
    let film = render(&scene, 16384);
    let bsdf = MeasuredBsdf::load(satin()).unwrap();
    let (w, h) = (film.width, film.height);
    let cam = &scene.camera;
    // The material is isotropic: only the polar angle of the view matters.
    let expected: Vec<Rgb> = (0..w * h)
        .into_par_iter()
        .map(|i| {
            let ray = cam.ray((i % w) as f64 + 0.5, (i / w) as f64 + 0.5, w, h);
            let c = -ray.d.z;
            assert!(c > 0.3 && c < 0.95, "view angle outside the tested range");
            let wo = DVec3::new((1.0 - c * c).max(0.0).sqrt(), 0.0, c);
            let (r, t) = sampled_albedo(&bsdf, wo, 256);
            assert!(t.is_black(), "a measured BRDF transmits nothing");
            r
        })
        .collect();
    let (mut dsum, mut vsum) = (Rgb::ZERO, Rgb::ZERO);
    for (i, &e) in expected.iter().enumerate() {
        let (m, v) = (film.mean(i), film.var_of_mean(i));
        dsum += m - e;
        vsum += v;
        for c in 0..3 {
            let se = v.0[c].sqrt();
            let d = m.0[c] - e.0[c];
            assert!(
                d.abs() <= 4.5 * se,
                "pixel ({}, {}) channel {c}: render {:.5}, measured albedo {:.5}, se {se:.1e}",
                i % w,
                i / w,
                m.0[c],
                e.0[c]
            );
        }
    }
    let n = (w * h) as f64;
    let centre = expected[w * (h / 2) + w / 2];
    for c in 0..3 {
        let se = vsum.0[c].sqrt() / n;
        let d = dsum.0[c] / n;
        eprintln!(
            "channel {c}: mean(render - albedo) = {d:.2e}, se {se:.1e}; albedo at the centre {:.4}",
            centre.0[c]
        );
        assert!(d.abs() <= 4.0 * se, "image mean off by {d:.2e} (se {se:.1e})");
        // The check has teeth: the satin is far from black and from a white Lambertian sheet (1).
        assert!(centre.0[c] > 0.02 && centre.0[c] < 0.9, "albedo {centre:?}");
    }
    // The satin is coloured: its channels differ by much more than the tolerance.
    assert!((centre.0[0] - centre.0[2]).abs() > 0.02, "albedo {centre:?}");
}

#[test]
fn measured_sheet_is_black_from_behind() {
    let dir = tempfile::tempdir().unwrap();
    let scene = load_in(
        dir.path(),
        &sheet_scene("type = \"measured\"\nfile = \"cloth/satin.bsdf\"", [0.0, -2.0, -2.0]),
    )
    .unwrap();
    let film = render(&scene, 64);
    for i in 0..film.width * film.height {
        assert_eq!(film.mean(i), Rgb::ZERO, "pixel {i}");
    }
}

#[test]
fn measured_material_errors_name_scene_material_and_file() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml").display().to_string();
    // A missing file.
    let e = load_in(
        dir.path(),
        &sheet_scene("type = \"measured\"\nfile = \"cloth/nothere.bsdf\"", [0.0, -2.0, 2.0]),
    )
    .err()
    .expect("a missing .bsdf file is an error");
    for part in [scene.as_str(), "materials.cloth", "nothere.bsdf"] {
        assert!(e.contains(part), "`{part}` missing from: {e}");
    }
    // A file that is not a tensor file.
    std::fs::write(dir.path().join("cloth/text.bsdf"), "not a tensor file\n").unwrap();
    let e = load_in(
        dir.path(),
        &sheet_scene("type = \"measured\"\nfile = \"cloth/text.bsdf\"", [0.0, -2.0, 2.0]),
    )
    .err()
    .expect("a bad .bsdf file is an error");
    for part in [scene.as_str(), "materials.cloth", "text.bsdf", "tensor"] {
        assert!(e.contains(part), "`{part}` missing from: {e}");
    }
    // No `file`, and a key of another material type.
    let e = load_in(dir.path(), &sheet_scene("type = \"measured\"", [0.0, -2.0, 2.0]))
        .err()
        .unwrap();
    assert!(e.contains("materials.cloth") && e.contains("`file`"), "{e}");
    let e = load_in(
        dir.path(),
        &sheet_scene(
            "type = \"measured\"\nfile = \"cloth/satin.bsdf\"\nreflectance = 0.5",
            [0.0, -2.0, 2.0],
        ),
    )
    .err()
    .unwrap();
    assert!(e.contains("materials.cloth") && e.contains("reflectance"), "{e}");
    // `file` belongs to measured materials only.
    let e = load_in(
        dir.path(),
        &sheet_scene(
            "type = \"diffuse\"\nreflectance = 0.5\nfile = \"cloth/satin.bsdf\"",
            [0.0, -2.0, 2.0],
        ),
    )
    .err()
    .unwrap();
    assert!(e.contains("materials.cloth") && e.contains("`file`"), "{e}");
}
