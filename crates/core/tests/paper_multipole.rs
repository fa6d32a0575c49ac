//! The multipole closed forms of the Paper BSDF against the supplement:
//! `R_d`, `T_d` of `paper::multipole::Multipole::rd_td` (infinite sum over
//! dipole pairs) versus direct numerical integration of the profiles `R(r)`
//! and `T(r)` (supplement equations 1 and 3, written out again here) and
//! versus the supplement's finite-sum closed forms (equations 2 and 4).

use paperbsdf_core::paper::multipole::Multipole;
use paperbsdf_core::quadrature::gauss_legendre_01;
use std::f64::consts::PI;

/// Pairs needed for the neglected terms of every sum to be below 1e-15.
fn pairs(m: &Multipole) -> i64 {
    let p = m.d + m.zb_entry + m.zb_exit;
    ((36.0 / (2.0 * m.sigma_tr * p)).ceil() as i64).max(4) + 2
}

fn z_r(m: &Multipole, i: i64) -> f64 {
    2.0 * i as f64 * (m.d + m.zb_entry + m.zb_exit) + m.l
}
fn z_v(m: &Multipole, i: i64) -> f64 {
    2.0 * i as f64 * (m.d + m.zb_entry + m.zb_exit) - m.l - 2.0 * m.zb_entry
}

/// Supplement eq. 1: `R(r)`, dipole pairs `-n..n`.
fn r_profile(m: &Multipole, r: f64, n: i64) -> f64 {
    let s = m.sigma_tr;
    let term = |z: f64| {
        let dd = (r * r + z * z).sqrt();
        m.alpha_p * z * (1.0 + s * dd) * (-s * dd).exp() / (4.0 * PI * dd * dd * dd)
    };
    (-n..=n).map(|i| term(z_r(m, i)) - term(z_v(m, i))).sum()
}

/// Supplement eq. 3: `T(r)`.
fn t_profile(m: &Multipole, r: f64, n: i64) -> f64 {
    let s = m.sigma_tr;
    let term = |z: f64| {
        let dz = m.d - z;
        let dd = (r * r + dz * dz).sqrt();
        m.alpha_p * dz * (1.0 + s * dd) * (-s * dd).exp() / (4.0 * PI * dd * dd * dd)
    };
    (-n..=n).map(|i| term(z_r(m, i)) - term(z_v(m, i))).sum()
}

/// `2 pi int_0^inf f(r) r dr` by 24-point Gauss-Legendre on geometric panels
/// from 1e-7 mm to 1e7 mm (ratio 1.25), plus the first panel [0, 1e-7].
fn radial_integral(f: impl Fn(f64) -> f64) -> f64 {
    let (x, w) = gauss_legendre_01(24);
    let mut edges = vec![0.0, 1e-7];
    while *edges.last().unwrap() < 1e7 {
        let e = *edges.last().unwrap() * 1.25;
        edges.push(e);
    }
    let mut s = 0.0;
    for k in 0..edges.len() - 1 {
        let (a, b) = (edges[k], edges[k + 1]);
        for (xi, wi) in x.iter().zip(&w) {
            let r = a + (b - a) * xi;
            s += wi * (b - a) * f(r) * r;
        }
    }
    2.0 * PI * s
}

fn sign(a: f64) -> f64 {
    if a >= 0.0 {
        1.0
    } else {
        -1.0
    }
}

/// Supplement eqs. 2 and 4, last lines, with pairs `-n..n`.
fn finite_sums(m: &Multipole, n: i64) -> (f64, f64) {
    let s = m.sigma_tr;
    let (mut rd, mut td) = (0.0, 0.0);
    for i in -n..=n {
        let (zr, zv) = (z_r(m, i), z_v(m, i));
        rd += sign(zr) * (-s * zr.abs()).exp() - sign(zv) * (-s * zv.abs()).exp();
        let (ar, av) = (m.d - zr, m.d - zv);
        td += sign(ar) * (-s * ar.abs()).exp() - sign(av) * (-s * av.abs()).exp();
    }
    (0.5 * m.alpha_p * rd, 0.5 * m.alpha_p * td)
}

fn grid() -> Vec<Multipole> {
    let mut v = Vec::new();
    for &d in &[0.05, 0.1, 0.3] {
        for &(sigma_s_p, sigma_a) in &[(200.0, 0.5), (30.0, 2.0), (80.0, 20.0), (5.0, 1.0)] {
            for &(rho0, rho1) in &[(0.0, 0.0), (0.6, 0.4), (0.9, 0.55)] {
                let st: f64 = sigma_s_p + sigma_a;
                let dcoef = 1.0 / (3.0 * st);
                let zb = |rho: f64| 2.0 * (1.0 + rho) / (1.0 - rho) * dcoef;
                // Sources at the dipole depth when inside the slab, and at d/2, d/10.
                for l in [1.0 / st, d / 2.0, d / 10.0] {
                    if l > d {
                        continue;
                    }
                    let m = Multipole {
                        alpha_p: sigma_s_p / st,
                        sigma_tr: (3.0 * sigma_a * st).sqrt(),
                        d,
                        l,
                        zb_entry: zb(rho0),
                        zb_exit: zb(rho1),
                    };
                    if m.sigma_tr * (m.d + m.zb_entry + m.zb_exit) >= 0.05 {
                        v.push(m);
                    }
                }
            }
        }
    }
    v
}

#[test]
fn closed_forms_match_numerical_integration_of_profiles() {
    let g = grid();
    assert!(g.len() >= 60, "grid too small: {}", g.len());
    let mut worst: f64 = 0.0;
    for m in &g {
        let n = pairs(m);
        let (rd, td) = m.rd_td();
        let rn = radial_integral(|r| r_profile(m, r, n));
        let tn = radial_integral(|r| t_profile(m, r, n));
        worst = worst.max((rd - rn).abs()).max((td - tn).abs());
        assert!((rd - rn).abs() < 1e-6, "{m:?}: R_d closed {rd} vs integral {rn}");
        assert!((td - tn).abs() < 1e-6, "{m:?}: T_d closed {td} vs integral {tn}");
        assert!(rd > 0.0 && td > 0.0);
    }
    eprintln!("{} parameter sets, worst |closed - integral| = {worst:.2e}", g.len());
}

#[test]
fn closed_forms_match_supplement_finite_sums() {
    for m in &grid() {
        let n = pairs(m);
        let (rd, td) = m.rd_td();
        let (rs, ts) = finite_sums(m, n);
        assert!((rd - rs).abs() < 1e-12, "{m:?}: {rd} vs {rs}");
        assert!((td - ts).abs() < 1e-12, "{m:?}: {td} vs {ts}");
    }
}

/// Without absorption every unit of source flux leaves: `R_d + T_d = a'`,
/// with the split of 1D diffusion between extrapolated boundaries, which the
/// finite sum only approaches with thousands of pairs.
#[test]
fn no_absorption_conserves_source_flux() {
    let m = Multipole {
        alpha_p: 1.0,
        sigma_tr: 1e-9,
        d: 0.1,
        l: 0.01,
        zb_entry: 0.02,
        zb_exit: 0.04,
    };
    let (rd, td) = m.rd_td();
    assert!((rd + td - 1.0).abs() < 1e-6, "{rd} + {td}");
    let (rs, _) = finite_sums(&Multipole { sigma_tr: 1e-3, ..m }, 20_000);
    assert!((rs - rd).abs() < 1e-3, "finite sum {rs} vs {rd}");
}

/// The model's source depth keeps `R_d`, `T_d` non-negative where the
/// dipole depth `1/sigma_t'` lies below the slab (docs/design.md 4.5).
#[test]
fn thin_sheets_never_negative() {
    for d in [1e-6, 1e-3, 0.01, 0.1] {
        for sp in [0.0, 0.1, 1.0, 10.0, 1e3] {
            for sa in [0.0, 0.01, 1.0, 100.0] {
                for rho in [0.0, 0.5, 0.95] {
                    if let Some(m) = Multipole::new(sp, sa, d, rho, 0.3) {
                        let (r, t) = m.rd_td();
                        assert!(r >= 0.0 && t >= 0.0 && r.is_finite() && t.is_finite(), "{m:?}: {r} {t}");
                        assert!(r + t <= m.alpha_p + 1e-9, "{m:?}: {r} + {t} > a'");
                        assert!(m.l > 0.0 && m.l <= d / 2.0 + 1e-15);
                    }
                }
            }
        }
    }
}
