//! Convergence of the visible-normal Gauss-Legendre quadrature of `boundary::directional_albedo_n`
//! (light from inside converges slowly: F has a square-root kink at total internal reflection).
//! Run: `cargo run --release -p paperbsdf-core --example quadrature_convergence`.
use paperbsdf_core::*;
fn main() {
    for (dist, eta, a, side, th) in [
        ("ggx", 2.0, 0.8, -1.0, 0.0),
        ("ggx", 1.5, 0.3, -1.0, 60.0),
        ("ggx", 2.0, 0.05, -1.0, 0.0),
        ("beckmann", 2.0, 0.8, -1.0, 0.0),
        ("ggx", 1.5, 0.3, 1.0, 60.0),
    ] {
        let b = RoughDielectric::new(Distribution::parse(dist).unwrap(), eta, a).unwrap();
        let th: f64 = f64::to_radians(th);
        let w = DVec3::new(th.sin(), 0.0, side * th.cos());
        let t0 = std::time::Instant::now();
        let refv = boundary::directional_albedo_n(&b, w, 1024);
        print!(
            "{dist} {eta} {a} {side} {th:.2}: ref {:.6} {:.6} ({:?}) |",
            refv.0,
            refv.1,
            t0.elapsed()
        );
        for n in [16, 24, 32, 48, 64, 96, 128, 256] {
            let v = boundary::directional_albedo_n(&b, w, n);
            print!(" {n}:{:.1e},{:.1e}", v.0 - refv.0, v.1 - refv.1);
        }
        println!();
    }
}
