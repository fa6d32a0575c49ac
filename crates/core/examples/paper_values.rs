//! Prints `eval` of the Paper BSDF over a fixed grid of parameters (presets
//! and pseudo-random sets over the whole valid range) and directions, one
//! value per line, to compare two builds of the library (e.g. before and
//! after a speed change): `cargo run --release -p paperbsdf-core --example paper_values > a.txt`.
use paperbsdf_core::paper::PaperBsdf;
use paperbsdf_core::{presets, Bsdf, Colour, DVec3, Distribution, PaperParams};
use rand::Rng;
use rand::SeedableRng;
use rand_pcg::Pcg64;

fn random_params(rng: &mut Pcg64) -> PaperParams {
    let pick = |rng: &mut Pcg64, special: f64, lo: f64, hi: f64| {
        if rng.gen::<f64>() < 0.15 {
            special
        } else {
            lo + (hi - lo) * rng.gen::<f64>()
        }
    };
    let logu = |rng: &mut Pcg64, lo: f64, hi: f64| (lo.ln() + (hi.ln() - lo.ln()) * rng.gen::<f64>()).exp();
    let colour =
        |rng: &mut Pcg64, lo: f64, hi: f64| Colour::Rgb([logu(rng, lo, hi), logu(rng, lo, hi), logu(rng, lo, hi)]);
    let dist = |rng: &mut Pcg64| {
        if rng.gen::<bool>() {
            Distribution::Ggx
        } else {
            Distribution::Beckmann
        }
    };
    PaperParams {
        name: None,
        d: logu(rng, 1e-3, 2.0),
        sigma_a: colour(rng, 1e-3, 50.0),
        sigma_s: colour(rng, 1e-2, 2000.0),
        g_f: pick(rng, 0.0, -0.99, 0.99),
        g_b: pick(rng, -0.5, -0.99, 0.99),
        w_b: pick(rng, 0.0, 0.0, 1.0),
        eta_f: pick(rng, 1.0, 1.0, 5.0),
        eta_b: pick(rng, 1.0, 1.0, 5.0),
        m_f: pick(rng, 0.0, 0.01, 1.5),
        m_b: pick(rng, 0.0, 0.01, 1.5),
        dist_f: dist(rng),
        dist_b: dist(rng),
        face_scattering: Default::default(),
    }
}

fn main() {
    let mut params: Vec<PaperParams> = presets::PRESET_NAMES
        .iter()
        .map(|n| presets::preset(n).unwrap())
        .collect();
    let mut rng = Pcg64::seed_from_u64(7);
    for _ in 0..60 {
        params.push(random_params(&mut rng));
    }
    let dirs: Vec<DVec3> = (0..9)
        .flat_map(|i| {
            (0..5).map(move |j| {
                let th = (i as f64 + 0.5) / 9.0 * std::f64::consts::PI;
                let ph = j as f64 * 1.3;
                DVec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos())
            })
        })
        .collect();
    for (k, p) in params.iter().enumerate() {
        let b = PaperBsdf::new(p).unwrap();
        for (a, wi) in dirs.iter().enumerate() {
            for (c, wo) in dirs.iter().enumerate() {
                let f = b.eval(*wi, *wo);
                let pdf = b.pdf(*wi, *wo);
                println!("{k} {a} {c} {:e} {:e} {:e} {:e}", f.0[0], f.0[1], f.0[2], pdf);
            }
        }
    }
}
