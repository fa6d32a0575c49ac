//! Times the construction and evaluation of the fitted models (the fit's cost).
//! Run: `cargo run --release -p paperbsdf-fit --example bench_model`
use paperbsdf_core::paper::{PaperBsdf, PaperOptions};
fn main() {
    let mut p = paperbsdf_core::presets::luster_photo();
    p.sigma_s = paperbsdf_core::Colour::Scalar(100.0);
    for (name, o) in [
        ("paper", PaperOptions::default()),
        (
            "no energy bound",
            PaperOptions {
                energy_bound: false,
                ..Default::default()
            },
        ),
        (
            "no bound, no direct",
            PaperOptions {
                energy_bound: false,
                direct: false,
                ..Default::default()
            },
        ),
        (
            "reduced",
            PaperOptions {
                use_att: false,
                energy_bound: false,
                direct: true,
            },
        ),
    ] {
        let t = std::time::Instant::now();
        let n = 50;
        for _ in 0..n {
            let _ = PaperBsdf::with_options(&p, o).unwrap();
        }
        let tb = t.elapsed().as_secs_f64() / n as f64;
        let b = PaperBsdf::with_options(&p, o).unwrap();
        let t = std::time::Instant::now();
        let mut s = 0.0;
        for k in 0..100000 {
            let (wi, wo) = paperbsdf_core::geometry::in_plane_directions(30.0, (k % 170) as f64 - 85.0, k % 2 == 0);
            s += paperbsdf_core::Bsdf::eval(&b, wi, wo).0[0];
        }
        let te = t.elapsed().as_secs_f64() / 100000.0;
        println!("{name}: build {:.1} us, eval {:.3} us ({s:.3})", tb * 1e6, te * 1e6);
    }
}
