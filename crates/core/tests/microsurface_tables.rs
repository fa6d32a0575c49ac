//! The tables of the energy carried by orders >= 2 of the multiple-scattering
//! face (`paperbsdf_core::microsurface_tables`): energy against Walter's face
//! at every node, reciprocity `t_out2 = eta^2 t_in2` at every node, and the
//! interpolated values against direct walk estimates off the nodes.

use paperbsdf_core::boundary::SurfaceIntegrals;
use paperbsdf_core::boundary_tables::{eta_node, m_node, N_ETA, N_M};
use paperbsdf_core::microsurface_tables::{hemispherical_estimate, lost_energy, node};
use paperbsdf_core::{Distribution, RoughDielectric};
use rand::{Rng, SeedableRng};
use statrs::distribution::{ChiSquared, ContinuousCDF};

const DISTS: [Distribution; 2] = [Distribution::Ggx, Distribution::Beckmann];

/// Walter's hemispherical `R + T` for diffuse light from outside and from
/// inside, from the boundary tables at node (i, j) (`2 int (Att + R_out) mu dmu`
/// by the midpoint rule in `mu^2` with 4000 points, and `rho_in + Tbar_in`).
fn walter_hemispherical(dist: Distribution, i: usize, j: usize) -> (f64, f64) {
    let b = RoughDielectric::new(dist, eta_node(i), m_node(j)).unwrap();
    let s = SurfaceIntegrals::new(&b);
    let n = 4000;
    let out: f64 = (0..n)
        .map(|k| {
            let mu = ((k as f64 + 0.5) / n as f64).sqrt();
            s.att(mu) + s.r_out(mu)
        })
        .sum::<f64>()
        / n as f64;
    (out, s.rho_in + s.tbar_in)
}

/// Energy conservation of the walk, node by node: what orders >= 2 carry is
/// what Walter's single-scattering face loses, `r2 + t2 = 1 - (R + T)`, from
/// outside and from inside. The walk and the boundary tables are independent
/// computations (Monte Carlo walks; quadrature of Walter's BSDF). Tolerance:
/// 4 standard errors of the table plus the boundary tables' own error (their
/// hemispherical values are f32 quadratures, a few 1e-5), and for Beckmann the
/// difference between Walter's rational `G1` (boundary tables, Mitsuba) and the
/// exact `G1` of the walk's order 1, bounded by the measured 2.5e-3 (see
/// `microsurface` module doc).
#[test]
fn higher_orders_carry_what_walter_loses() {
    for dist in DISTS {
        let (mut worst_z, mut worst_abs, mut z2, mut count) = (0.0f64, 0.0f64, 0.0, 0usize);
        for i in 1..N_ETA {
            for j in 1..N_M {
                let e = node(dist, i, j);
                let (out, inside) = walter_hemispherical(dist, i, j);
                for (side, walter) in [(0usize, out), (1, inside)] {
                    let lost = 1.0 - walter;
                    let got = e.value[2 * side] + e.value[2 * side + 1];
                    let sigma = (e.std_err[2 * side].powi(2) + e.std_err[2 * side + 1].powi(2)).sqrt();
                    let d = got - lost;
                    let z = d / sigma.max(1e-12);
                    let tol = match dist {
                        Distribution::Ggx => 4.0 * sigma + 1e-4,
                        Distribution::Beckmann => 4.0 * sigma + 2.5e-3,
                    };
                    assert!(
                        d.abs() < tol,
                        "{dist} eta {} m {} side {side}: orders>=2 {got} vs Walter's loss {lost} (sigma {sigma:.1e})",
                        eta_node(i),
                        m_node(j)
                    );
                    if dist == Distribution::Ggx {
                        z2 += z * z;
                        count += 1;
                    }
                    worst_z = worst_z.max(z.abs());
                    worst_abs = worst_abs.max(d.abs());
                }
            }
        }
        eprintln!(
            "{dist}: worst |difference| {worst_abs:.2e}, worst |z| {worst_z:.2}, mean z^2 {:.2}",
            z2 / count.max(1) as f64
        );
    }
}

/// Generalised reciprocity of the diffuse transmittances: `t_out2 = eta^2 t_in2`
/// at every node, within 5 standard errors (4802 nodes: a 4-sigma bound would
/// fail somewhere by chance), and the z-scores together pass a chi-square test.
#[test]
fn diffuse_transmission_is_reciprocal() {
    let (mut z2, mut n, mut worst) = (0.0, 0usize, 0.0f64);
    for dist in DISTS {
        for i in 0..N_ETA {
            for j in 1..N_M {
                let e = node(dist, i, j);
                let eta2 = eta_node(i).powi(2);
                let d = e.value[1] - eta2 * e.value[3];
                let sigma = (e.std_err[1].powi(2) + (eta2 * e.std_err[3]).powi(2)).sqrt();
                let z = d / sigma.max(1e-12);
                assert!(
                    z.abs() < 5.0 || d.abs() < 1e-6,
                    "{dist} eta {} m {}: t_out2 {} vs eta^2 t_in2 {} (sigma {sigma:.1e})",
                    eta_node(i),
                    m_node(j),
                    e.value[1],
                    eta2 * e.value[3]
                );
                if sigma > 0.0 {
                    z2 += z * z;
                    n += 1;
                    worst = worst.max(z.abs());
                }
            }
        }
    }
    let p = 1.0 - ChiSquared::new(n as f64).unwrap().cdf(z2);
    eprintln!("{n} nodes: sum z^2 = {z2:.0}, p = {p:.3}, worst |z| = {worst:.2}");
    assert!(p > 1e-4, "sum of z^2 {z2} over {n} nodes: p = {p}");
}

/// Smooth faces lose nothing: the m = 0 nodes are 0, and the interpolation is
/// continuous toward them.
#[test]
fn smooth_limit() {
    for dist in DISTS {
        for eta in [1.0, 1.5, 3.0, 5.0] {
            let e = lost_energy(dist, eta, 0.0);
            assert_eq!((e.r_out2, e.t_out2, e.r_in2, e.t_in2), (0.0, 0.0, 0.0, 0.0));
            let e = lost_energy(dist, eta, 1e-4);
            for v in [e.r_out2, e.t_out2, e.r_in2, e.t_in2] {
                assert!((0.0..1e-4).contains(&v), "{dist} eta {eta} m 1e-4: {v}");
            }
        }
    }
}

/// The bilinear interpolation off the nodes against direct estimates of the
/// walk (1.6e5 walks per side), at the centres of cells (where interpolation
/// is worst) across the range: the difference must be within 4 combined
/// standard errors (direct estimate and the interpolated nodes) plus 1e-3 of
/// interpolation error (measured below 5e-4; printed).
#[test]
fn interpolation_against_direct_walks() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
    let mut worst = 0.0f64;
    for dist in DISTS {
        for (i, j) in [
            (3, 10),
            (10, 20),
            (20, 30),
            (30, 40),
            (40, 46),
            (14, 5),
            (24, 24),
            (47, 47),
        ] {
            // The cell centre in the tables' coordinates.
            let s = (i as f64 + 0.5) / (N_ETA - 1) as f64;
            let t = (j as f64 + 0.5) / (N_M - 1) as f64;
            let (eta, m) = (1.0 + 4.0 * s * s, std::f64::consts::FRAC_PI_2 * t * t);
            let direct = hemispherical_estimate(dist, eta, m, 160_000, &mut || rng.gen::<f64>());
            let table = lost_energy(dist, eta, m);
            let tv = [table.r_out2, table.t_out2, table.r_in2, table.t_in2];
            for k in 0..4 {
                // The four corners' standard errors, averaged (they are similar).
                let st = [(i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1)]
                    .iter()
                    .map(|&(a, b)| node(dist, a, b).std_err[k])
                    .sum::<f64>()
                    / 4.0;
                let sigma = (direct.std_err[k].powi(2) + st * st).sqrt();
                let d = tv[k] - direct.value[k];
                eprintln!(
                    "{dist} eta {eta:.3} m {m:.3} value {k}: table {:.5} direct {:.5} +- {:.1e}, diff {d:+.1e}",
                    tv[k], direct.value[k], direct.std_err[k]
                );
                worst = worst.max(d.abs());
                assert!(d.abs() < 4.0 * sigma + 1e-3, "{dist} eta {eta} m {m} value {k}");
            }
        }
    }
    eprintln!("worst |table - direct| {worst:.2e}");
}
