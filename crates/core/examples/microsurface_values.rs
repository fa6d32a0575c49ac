//! Prints the orders >= 2 energy of the multiple-scattering face from the
//! tables (`paperbsdf_core::microsurface_tables::lost_energy`) at a few faces,
//! beside Walter's single-scattering hemispherical R + T from outside and inside.
//! Run: `cargo run --release -p paperbsdf-core --example microsurface_values`.
use paperbsdf_core::boundary::SurfaceIntegrals;
use paperbsdf_core::microsurface_tables::lost_energy;
use paperbsdf_core::quadrature::gauss_legendre_01;
use paperbsdf_core::{Distribution, RoughDielectric};

fn main() {
    let (x, w) = gauss_legendre_01(64);
    println!("dist      eta   m     r_out2   t_out2   r_in2    t_in2    1-(R+T)_out 1-(R+T)_in");
    for dist in [Distribution::Ggx, Distribution::Beckmann] {
        for (eta, m) in [
            (1.5, 0.05),
            (1.5, 0.2),
            (1.5, 0.48),
            (1.5, 0.8),
            (1.5, 1.5),
            (3.0, 0.5),
            (3.0, 1.5),
        ] {
            let b = RoughDielectric::new(dist, eta, m).unwrap();
            let s = SurfaceIntegrals::new(&b);
            // Walter's hemispherical R + T for diffuse light from outside.
            let out: f64 = x
                .iter()
                .zip(&w)
                .map(|(&mu, &wk)| 2.0 * wk * (s.att(mu) + s.r_out(mu)) * mu)
                .sum();
            let e = lost_energy(dist, eta, m);
            println!(
                "{:<9} {eta:<5} {m:<5} {:.5}  {:.5}  {:.5}  {:.5}  {:.5}     {:.5}",
                dist.name(),
                e.r_out2,
                e.t_out2,
                e.r_in2,
                e.t_in2,
                1.0 - out,
                1.0 - s.rho_in - s.tbar_in
            );
        }
    }
}
