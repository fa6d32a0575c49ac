//! White furnace tests: the renderer against energy conservation and against
//! the Paper BSDF's own directional albedo.
//!
//! 1. Non-absorbing, energy-conserving objects (white Lambertian spheres, a
//!    white Lambertian cube from an OBJ file, a two-sided white Lambertian
//!    floor, a smooth lossless glass sphere) in a uniform environment of
//!    radiance `L`: every path ends in the environment with weight one in
//!    expectation, so every pixel is `L`.
//! 2. One flat paper sheet in a uniform environment `L`: a ray from the camera
//!    meets the sheet once and every path leaves it to the environment (a flat
//!    sheet cannot see itself), so the pixel is `L (R + T)(wo)`, the model's
//!    directional albedo for the view direction `wo`, computed by the routine
//!    `paperbsdf albedo` uses (`paperbsdf_core::bsdf::sampled_albedo`, 512 x
//!    512 stratified samples). The single-scattering microfacet faces lose
//!    energy, so `R + T < 1`, and that is what the render must reproduce.
//! 3. The same with a thickness map and with an ink map: the render must be
//!    the albedo of the mapped parameters, which differs from the unmapped
//!    sheet's by far more than the tolerance.
//!
//! Tolerances are in standard errors of the render, from the per-pixel sample
//! variance (`Film::var_of_mean`); a block's or the image's standard error is
//! that of the mean of independent pixels. The renders are deterministic for
//! their seed.

use paperbsdf_core::bsdf::sampled_albedo;
use paperbsdf_core::paper::PaperBsdf;
use paperbsdf_core::{presets, Rgb};
use paperbsdf_render::spec::Resources;
use paperbsdf_render::{load_scene_str, Film, RenderOptions, Scene};
use rayon::prelude::*;
use std::collections::HashMap;
use std::path::Path;
use std::sync::atomic::AtomicBool;

fn render(scene: &Scene, spp: u32) -> Film {
    let out = paperbsdf_render::render(
        scene,
        &RenderOptions {
            spp,
            pass_spp: spp,
            progress: false,
        },
        &AtomicBool::new(false),
    );
    eprintln!(
        "{}x{} at {spp} spp in {:.2} s",
        scene.settings.width,
        scene.settings.height,
        out.elapsed.as_secs_f64()
    );
    out.film
}

fn resources(dir: &Path) -> Resources {
    Resources {
        base_dir: dir.to_path_buf(),
        embedded: HashMap::new(),
    }
}

/// A unit cube `[-1, 1]^3` with outward faces.
const CUBE_OBJ: &str = "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n\
f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";

const ENV: [f64; 3] = [0.5, 0.7, 1.0];

#[test]
fn white_furnace_returns_the_environment() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("cube.obj"), CUBE_OBJ).unwrap();
    let text = format!(
        r#"
[render]
width = 48
height = 36
# Paths between white surfaces keep weight one; Russian roulette ends them
# without bias. max_depth is large so that truncation loses nothing measurable.
max_depth = 512
seed = 3

[camera]
origin = [0, -4, 1.6]
target = [0, 0, 0.5]
fov = 50

[environment]
radiance = [{}, {}, {}]

[materials.white]
type = "diffuse"
reflectance = 1

[materials.glass]
type = "dielectric"
eta = 1.5
m = 0

[[shapes]]
type = "rectangle"
material = "white"
transform = [{{ scale = [2.5, 2.5, 1] }}]

[[shapes]]
type = "sphere"
center = [-0.9, 0, 0.6]
radius = 0.6
material = "white"

[[shapes]]
type = "sphere"
center = [0.6, -0.8, 0.45]
radius = 0.45
material = "glass"

[[shapes]]
type = "obj"
file = "cube.obj"
material = "white"
transform = [{{ scale = 0.4 }}, {{ rotate = [0, 0, 1], angle = 30 }}, {{ translate = [0.8, 0.6, 0.4] }}]
"#,
        ENV[0], ENV[1], ENV[2]
    );
    let scene = load_scene_str(&text, "furnace.toml", &resources(dir.path())).unwrap();
    let film = render(&scene, 512);
    let (w, h) = (film.width, film.height);
    // 6x6-pixel blocks and the whole image; 4.5 standard errors (plus 1e-9 for
    // the pixels that see only the environment and have no variance).
    let mut blocks: Vec<Vec<usize>> = vec![];
    for by in 0..h / 6 {
        for bx in 0..w / 6 {
            blocks.push((0..36).map(|k| (by * 6 + k / 6) * w + bx * 6 + k % 6).collect());
        }
    }
    blocks.push((0..w * h).collect());
    let mut worst = 0.0f64;
    for (bi, px) in blocks.iter().enumerate() {
        let n = px.len() as f64;
        let (mut m, mut v) = (Rgb::ZERO, Rgb::ZERO);
        for &i in px {
            m += film.mean(i);
            v += film.var_of_mean(i);
        }
        let (m, v) = (m / n, v / (n * n));
        for (c, &env) in ENV.iter().enumerate() {
            let se = v.0[c].sqrt();
            let diff = (m.0[c] - env).abs();
            worst = worst.max(diff / se.max(1e-12));
            if bi + 1 == blocks.len() {
                eprintln!(
                    "whole image channel {c}: {:.5} vs environment {} (se {se:.1e}, {:.2} sigma)",
                    m.0[c],
                    env,
                    diff / se
                );
            }
            assert!(
                diff <= 4.5 * se + 1e-9,
                "block {bi} channel {c}: {:.5} vs environment {} (se {se:.2e})",
                m.0[c],
                env
            );
        }
    }
    eprintln!("worst block deviation {worst:.2} sigma");
}

/// Renders one paper sheet (the unit rectangle scaled to 4 x 4, normal +z) in a
/// uniform environment of radiance 1 from `origin`, and compares every pixel
/// with the model's directional albedo for that pixel's view direction.
fn paper_sheet_furnace(preset: &str, origin: [f64; 3]) {
    let p = presets::preset(preset).unwrap();
    paper_sheet_furnace_with(&format!("preset = \"{preset}\""), &p, preset, origin, Path::new("."));
}

/// [`paper_sheet_furnace`] for the material lines `material` (inside
/// `[materials.sheet]`, after `type = "paper"`), whose BSDF everywhere on the
/// sheet must be the Paper BSDF of `params`; `dir` holds the files it names.
fn paper_sheet_furnace_with(
    material: &str,
    params: &paperbsdf_core::PaperParams,
    label: &str,
    origin: [f64; 3],
    dir: &Path,
) {
    let preset = label;
    let text = format!(
        r#"
[render]
width = 8
height = 6
seed = 11

[camera]
origin = [{}, {}, {}]
target = [0, 0, 0]
up = [0, 1, 0]
fov = 30

[environment]
radiance = 1

[materials.sheet]
type = "paper"
{material}

[[shapes]]
type = "rectangle"
material = "sheet"
transform = [{{ scale = [4, 4, 1] }}]
"#,
        origin[0], origin[1], origin[2]
    );
    let scene = load_scene_str(&text, "sheet.toml", &resources(dir)).unwrap();
    let film = render(&scene, 16384);
    let bsdf = PaperBsdf::new(params).unwrap();
    let (w, h) = (film.width, film.height);
    let cam = &scene.camera;
    // Per pixel: the view direction at the pixel centre, in the sheet's frame
    // (the model is isotropic, so only the polar angle and the side matter).
    // Over one pixel (3.75 degrees) the albedo changes by far less than the
    // render's standard error at these angles (25 to 65 degrees from the normal).
    let expected: Vec<Rgb> = (0..w * h)
        .into_par_iter()
        .map(|i| {
            let ray = cam.ray((i % w) as f64 + 0.5, (i / w) as f64 + 0.5, w, h);
            let c = -ray.d.z;
            assert!(c.abs() > 0.3 && c.abs() < 0.95, "view angle outside the tested range");
            let wo = paperbsdf_core::DVec3::new((1.0 - c * c).max(0.0).sqrt(), 0.0, c);
            let (r, t) = sampled_albedo(&bsdf, wo, 512);
            r + t
        })
        .collect();
    let (mut dsum, mut vsum) = (Rgb::ZERO, Rgb::ZERO);
    let mut worst = (0.0f64, String::new());
    for (i, &e) in expected.iter().enumerate() {
        let m = film.mean(i);
        let v = film.var_of_mean(i);
        dsum += m - e;
        vsum += v;
        for c in 0..3 {
            let se = v.0[c].sqrt();
            let d = m.0[c] - e.0[c];
            let msg = format!(
                "{preset} from {origin:?}, pixel ({}, {}) channel {c}: render {:.5}, albedo R+T {:.5}, se {se:.1e}",
                i % w,
                i / w,
                m.0[c],
                e.0[c]
            );
            if d.abs() / se > worst.0 {
                worst = (d.abs() / se, msg.clone());
            }
            // 4.5 standard errors per pixel (144 comparisons per view).
            assert!(d.abs() <= 4.5 * se, "{msg}");
        }
    }
    let n = (w * h) as f64;
    for c in 0..3 {
        let se = vsum.0[c].sqrt() / n;
        let d = dsum.0[c] / n;
        eprintln!(
            "{preset} from {origin:?} channel {c}: mean(render - albedo) = {d:.2e}, se {se:.1e} ({:.2} sigma); albedo at the centre {:.4}",
            d / se,
            expected[w * (h / 2) + w / 2].0[c]
        );
        // The image mean: 4 standard errors.
        assert!(d.abs() <= 4.0 * se, "{preset}: image mean off by {d:.2e} (se {se:.1e})");
    }
    eprintln!("worst pixel: {:.2} sigma at {}", worst.0, worst.1);
}

#[test]
fn paper_sheet_furnace_matte_front() {
    paper_sheet_furnace("matte", [0.0, -2.0, 2.0]);
}

/// Luster paper has different faces (Beckmann 0.15 front, GGX 0.3 back): both are checked.
#[test]
fn paper_sheet_furnace_luster_front_and_back() {
    paper_sheet_furnace("luster", [0.0, -2.0, 2.0]);
    paper_sheet_furnace("luster", [0.0, -2.0, -2.0]);
}

/// Thickness and ink maps (DESIGN: a watermark is thinner paper, print is
/// absorption): a sheet whose maps are black everywhere must render as the
/// Paper BSDF of the mapped parameters, `d (min + (1 - min) 0)` and
/// `sigma_a + ink (1 - 0)` (docs/scenes.md), not as the unmapped sheet. The
/// parameters absorb enough (`sigma_a` 3/mm over 0.2 mm) that the albedo moves
/// by far more than the tolerance when a map is applied: the test would fail
/// if the maps were ignored, which is checked first.
#[test]
fn paper_sheet_furnace_with_thickness_and_ink_maps() {
    let dir = tempfile::tempdir().unwrap();
    image::GrayImage::from_pixel(2, 2, image::Luma([0u8]))
        .save(dir.path().join("black.png"))
        .unwrap();
    let base = r#"d = 0.2
sigma_a = 3.0
sigma_s = 60.0
g_f = 0.7
g_b = -0.3
w_b = 0.2
eta_f = 1.5
eta_b = 1.5
m_f = 0.3
m_b = 0.3
dist_f = "ggx"
dist_b = "ggx""#;
    let params = |d: f64, sigma_a: f64| paperbsdf_core::PaperParams {
        name: None,
        d,
        sigma_a: paperbsdf_core::Colour::Scalar(sigma_a),
        sigma_s: paperbsdf_core::Colour::Scalar(60.0),
        g_f: 0.7,
        g_b: -0.3,
        w_b: 0.2,
        eta_f: 1.5,
        eta_b: 1.5,
        m_f: 0.3,
        m_b: 0.3,
        dist_f: paperbsdf_core::Distribution::Ggx,
        dist_b: paperbsdf_core::Distribution::Ggx,
        face_scattering: Default::default(),
    };
    let wo = paperbsdf_core::DVec3::new(0.6, 0.0, 0.8);
    let albedo = |p: &paperbsdf_core::PaperParams| {
        let (r, t) = sampled_albedo(&PaperBsdf::new(p).unwrap(), wo, 512);
        (r + t).0[0]
    };
    let (plain, thin, inked) = (
        albedo(&params(0.2, 3.0)),
        albedo(&params(0.05, 3.0)),
        albedo(&params(0.2, 23.0)),
    );
    eprintln!(
        "albedo R+T at 37 degrees: plain {plain:.4}, thickness map (d 0.05) {thin:.4}, ink map (sigma_a 23) {inked:.4}"
    );
    assert!((thin - plain).abs() > 0.05 && (inked - plain).abs() > 0.05);
    paper_sheet_furnace_with(
        &format!("{base}\nthickness_map = {{ file = \"black.png\", min = 0.25 }}"),
        &params(0.05, 3.0),
        "thickness map",
        [0.0, -2.0, 2.0],
        dir.path(),
    );
    paper_sheet_furnace_with(
        &format!("{base}\nink_map = {{ file = \"black.png\", sigma_a = 20 }}"),
        &params(0.2, 23.0),
        "ink map",
        [0.0, -2.0, 2.0],
        dir.path(),
    );
}
