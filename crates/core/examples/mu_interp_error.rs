//! Error of the per-surface `mu` interpolation alone (no (eta, m) interpolation):
//! a surface's nodes computed directly, against direct quadrature at random `mu`.
//! Run: `cargo run --release -p paperbsdf-core --example mu_interp_error`.
use paperbsdf_core::boundary::{dir_at_mu, directional_albedo_n, SurfaceIntegrals};
use paperbsdf_core::*;
use rand::{Rng, SeedableRng};
fn main() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(9);
    let mut worst: [(f64, String); 4] = Default::default();
    for k in 0..60 {
        let dist = if k % 2 == 0 {
            Distribution::Ggx
        } else {
            Distribution::Beckmann
        };
        let eta = (1.0 + 4.0 * rng.gen::<f64>().powi(2)).max(1.05);
        let m = (std::f64::consts::FRAC_PI_2 * rng.gen::<f64>().powi(2)).max(0.003);
        let b = RoughDielectric::new(dist, eta, m).unwrap();
        let s = SurfaceIntegrals::direct(&b, 96);
        for _ in 0..8 {
            let mu: f64 = rng.gen_range(0.005..1.0);
            let (ro, to) = directional_albedo_n(&b, dir_at_mu(mu, 1.0), 96);
            let (ri, ti) = directional_albedo_n(&b, dir_at_mu(mu, -1.0), 96);
            for (q, e) in [
                (s.att(mu) - to),
                (s.r_out(mu) - ro),
                (s.r_in(mu) - ri),
                (s.t_in(mu) - ti),
            ]
            .iter()
            .enumerate()
            {
                if e.abs() > worst[q].0 {
                    worst[q] = (e.abs(), format!("{dist} eta {eta:.3} m {m:.4} mu {mu:.3}"));
                }
            }
        }
    }
    for (q, w) in worst.iter().enumerate() {
        println!("q{q} worst {:.1e} at {}", w.0, w.1);
    }
}
