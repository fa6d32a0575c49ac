//! Writes the cut-out masks of the built-in scenes: `scenes/lightbox_layer1.png`
//! (front) to `scenes/lightbox_layer4.png` (back) of `lightbox`, and
//! `scenes/checker_mask.png` (8 x 6 squares, one pixel each) of `checkerboard`.
//!
//! A mask is a greyscale PNG: white is paper, black is a hole. The image's top
//! row is the top of the sheet (`v = 1`). Run from the repository root:
//!
//! ```sh
//! cargo run -p paperbsdf-render --example scene_masks
//! ```

use std::f64::consts::PI;
use std::path::Path;

const W: u32 = 384;
const H: u32 = 288;

/// A layer: `solid(x, y)` with `x` in [0, 1] left to right and `y` in [0, 1] bottom to top.
fn write(path: &Path, solid: impl Fn(f64, f64) -> bool) {
    let mut img = image::GrayImage::new(W, H);
    for (px, py, p) in img.enumerate_pixels_mut() {
        // 4x4 supersampling for smooth (anti-aliased) cut edges.
        let mut s = 0u32;
        for k in 0..16 {
            let x = (px as f64 + (k % 4) as f64 * 0.25 + 0.125) / W as f64;
            let y = 1.0 - (py as f64 + (k / 4) as f64 * 0.25 + 0.125) / H as f64;
            s += solid(x, y) as u32;
        }
        p.0 = [(s * 255 / 16) as u8];
    }
    img.save(path).expect("write mask");
    println!("wrote {}", path.display());
}

/// A pine tree standing at `(x0, base)` with height `h`: three stacked triangles and a trunk.
fn tree(x: f64, y: f64, x0: f64, base: f64, h: f64) -> bool {
    let trunk = (x - x0).abs() < 0.06 * h && y >= base && y < base + 0.15 * h;
    let mut crown = false;
    for k in 0..3 {
        let b = base + (0.12 + 0.25 * k as f64) * h;
        let th = 0.45 * h;
        let half = (0.32 - 0.06 * k as f64) * h;
        if y >= b && y < b + th {
            crown |= (x - x0).abs() < half * (1.0 - (y - b) / th);
        }
    }
    trunk || crown
}

fn main() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    // One pixel per square: bilinear filtering and the mask's 1/2 threshold put
    // the edges exactly on the pixel boundaries. The top-left square is solid.
    let checker = image::GrayImage::from_fn(8, 6, |x, y| image::Luma([if (x + y) % 2 == 0 { 255 } else { 0 }]));
    checker.save(dir.join("checker_mask.png")).expect("write mask");
    // Front layer: a frame around the window and a foreground of grass and two trees.
    write(&dir.join("lightbox_layer1.png"), |x, y| {
        let frame = !(0.06..=0.94).contains(&x) || !(0.08..=0.92).contains(&y);
        let ground = y < 0.16 + 0.03 * (2.0 * PI * (3.0 * x)).sin() + 0.015 * (2.0 * PI * 11.0 * x).sin().abs();
        frame || ground || tree(x, y, 0.16, 0.15, 0.5) || tree(x, y, 0.85, 0.14, 0.38)
    });
    // Second layer: rolling hills with a row of small trees.
    write(&dir.join("lightbox_layer2.png"), |x, y| {
        let hill = 0.3 + 0.07 * (2.0 * PI * (1.3 * x + 0.1)).sin() + 0.03 * (2.0 * PI * 3.1 * x).cos();
        let trees = (0..7).any(|k| {
            let x0 = 0.3 + 0.075 * k as f64;
            tree(x, y, x0, hill - 0.02, 0.16 + 0.04 * ((k * 37 % 5) as f64 / 4.0))
        });
        y < hill || trees
    });
    // Third layer: a mountain range.
    write(&dir.join("lightbox_layer3.png"), |x, y| {
        let peaks = [(0.2, 0.62, 0.5), (0.45, 0.55, 0.7), (0.72, 0.68, 0.6), (0.95, 0.5, 0.8)];
        let ridge = peaks
            .iter()
            .map(|&(px, py, slope)| py - slope * (x - px).abs() * 1.6)
            .fold(0.35f64, f64::max);
        y < ridge
    });
    // Back layer: the sky, a solid sheet with a round moon cut out and a few stars.
    write(&dir.join("lightbox_layer4.png"), |x, y| {
        let aspect = W as f64 / H as f64;
        let d = |cx: f64, cy: f64| (((x - cx) * aspect).powi(2) + (y - cy).powi(2)).sqrt();
        let moon = d(0.7, 0.74) < 0.09;
        let stars = [
            (0.15, 0.85),
            (0.3, 0.7),
            (0.42, 0.88),
            (0.55, 0.8),
            (0.88, 0.6),
            (0.22, 0.62),
        ]
        .iter()
        .any(|&(sx, sy)| d(sx, sy) < 0.012);
        !(moon || stars)
    });
}
