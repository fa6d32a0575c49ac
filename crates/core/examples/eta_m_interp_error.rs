//! Error of the (eta, m) interpolation of the boundary tables, with the four
//! neighbouring nodes computed directly (no table file needed), against direct
//! quadrature at random `mu`. Run:
//! `cargo run --release -p paperbsdf-core --example eta_m_interp_error`.
use paperbsdf_core::boundary::tables::*;
use paperbsdf_core::boundary::{dir_at_mu, directional_albedo_n, hemispherical_inside, SurfaceIntegrals};
use paperbsdf_core::*;
use rand::{Rng, SeedableRng};
fn main() {
    let n = 64;
    let mut rng = rand_pcg::Pcg64::seed_from_u64(4);
    let mut worst: [(f64, String); 5] = Default::default();
    for k in 0..40 {
        let dist = if k % 2 == 0 {
            Distribution::Ggx
        } else {
            Distribution::Beckmann
        };
        let eta = (1.0 + 4.0 * rng.gen::<f64>().powi(2)).max(1.05);
        let m = (std::f64::consts::FRAC_PI_2 * rng.gen::<f64>().powi(2)).max(0.003);
        let b = RoughDielectric::new(dist, eta, m).unwrap();
        let s = interpolate_nodes(eta, m, |i, j| {
            let bn = RoughDielectric::new(dist, eta_node(i).max(1.0 + 1e-9), m_node(j)).unwrap();
            let mut v = [0.0; NODE_LEN];
            for (a, b) in v.iter_mut().zip(encode_node(&SurfaceIntegrals::direct(&bn, n))) {
                *a = b as f64;
            }
            v
        });
        for _ in 0..6 {
            let mu: f64 = rng.gen_range(0.005..1.0);
            let (ro, to) = directional_albedo_n(&b, dir_at_mu(mu, 1.0), n);
            let (ri, ti) = directional_albedo_n(&b, dir_at_mu(mu, -1.0), n);
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
        let (rho, _) = hemispherical_inside(&b, n);
        let e = (s.rho_in - rho).abs();
        if e > worst[4].0 {
            worst[4] = (e, format!("{dist} eta {eta:.3} m {m:.4}"));
        }
    }
    for (q, w) in worst.iter().enumerate() {
        println!("q{q} worst {:.1e} at {}", w.0, w.1);
    }
}
