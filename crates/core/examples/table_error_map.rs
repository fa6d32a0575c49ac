//! Maps the error of the boundary tables against direct quadrature over the
//! parameter domain, by region. Run:
//! `cargo run --release -p paperbsdf-core --example table_error_map`.
use paperbsdf_core::boundary::*;
use paperbsdf_core::*;
use rand::{Rng, SeedableRng};
fn main() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(77);
    // regions: eta<1.1, m<0.05, mu<0.1, else
    let mut worst = std::collections::BTreeMap::new();
    for k in 0..600 {
        let dist = if k % 2 == 0 {
            Distribution::Ggx
        } else {
            Distribution::Beckmann
        };
        let eta = 1.0 + 4.0 * rng.gen::<f64>().powi(2);
        let m = std::f64::consts::FRAC_PI_2 * rng.gen::<f64>().powi(2);
        let (eta, m) = (eta.max(1.005), m.max(0.003));
        let mu: f64 = rng.gen_range(0.01..1.0);
        let b = RoughDielectric::new(dist, eta, m).unwrap();
        let t = SurfaceIntegrals::new(&b);
        let (ro, to) = directional_albedo_n(&b, dir_at_mu(mu, 1.0), 192);
        let (ri, ti) = directional_albedo_n(&b, dir_at_mu(mu, -1.0), 192);
        let region = format!(
            "eta{} m{} mu{}",
            if eta < 1.1 { "<1.1" } else { ">1.1" },
            if m < 0.05 { "<.05" } else { ">.05" },
            if mu < 0.1 { "<.1" } else { ">.1" }
        );
        for (q, e) in [t.att(mu) - to, t.r_out(mu) - ro, t.r_in(mu) - ri, t.t_in(mu) - ti]
            .iter()
            .enumerate()
        {
            let key = format!("{region} q{q}");
            let w = worst.entry(key).or_insert((0.0f64, String::new(), 0usize));
            w.2 += 1;
            if e.abs() > w.0 {
                *w = (e.abs(), format!("{dist} eta {eta:.3} m {m:.4} mu {mu:.3}"), w.2);
            }
        }
    }
    for (k, (e, s, n)) in worst {
        println!("{k:32} n={n:4} worst {e:.1e} at {s}");
    }
}
