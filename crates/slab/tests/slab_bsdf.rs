//! The model `slab` as a BSDF (crates/slab/src/bsdf.rs): sampling against its
//! density (chi-square, core's harness as pbrt-v4's and Mitsuba 3's), exact
//! reciprocity of the interpolated tables for unequal faces, energy (albedo
//! by integration over the outgoing argument with every component and the
//! delta lobes included), agreement with the solution at the nodes, the
//! closed-form delta lobes of smooth sheets, and bad input.
//!
//! Sheets: the matte, luster and glossy presets (luster: Beckmann 0.15
//! front, GGX 0.3 back; glossy: a coated front, eta 1.55 over a base of
//! 1.5, Beckmann 0.04), a thin tissue (optical thickness ~3), a weak
//! scatterer, a sheet with smooth faces (delta lobes), smooth and rough
//! coated sheets (the base denser than the coating and the reverse), an
//! index-matched one, and non-absorbing sheets with `face_scattering =
//! "multiple"` (energy closes), one of them coated.

#[path = "../../core/tests/support/chi2.rs"]
mod chi2;

mod support;

use paperbsdf_core::bsdf::albedo_from;
use paperbsdf_core::geometry::spherical_direction;
use paperbsdf_core::models::{Component, ComponentModel};
use paperbsdf_core::paper::Side;
use paperbsdf_core::presets::preset;
use paperbsdf_core::{Bsdf, Colour, DVec3, Distribution, FaceScattering, PaperBsdf, PaperParams};
use paperbsdf_slab::{face_albedo, SlabBsdf, SlabOptions, SlabSpec};
use std::f64::consts::PI;
use support::grid_albedo;

fn sheet(d: f64, sa: f64, ss: f64, faces: [(f64, f64, Distribution); 2], fs: FaceScattering) -> PaperParams {
    PaperParams {
        name: None,
        d,
        sigma_a: Colour::Scalar(sa),
        sigma_s: Colour::Scalar(ss),
        g_f: 0.8,
        g_b: -0.4,
        w_b: 0.2,
        eta_f: faces[0].0,
        m_f: faces[0].1,
        dist_f: faces[0].2,
        eta_b: faces[1].0,
        m_b: faces[1].1,
        dist_b: faces[1].2,
        face_scattering: fs,
    }
}

/// Optical thickness 0.3 between GGX 0.01 faces, without absorption: the
/// unscattered light is most of the transmission, and the table's lobes are
/// the narrowest (near the normal; seen backwards at grazing angles its
/// parts ring below zero).
fn thin_between_smooth_faces() -> PaperParams {
    sheet(
        0.001,
        0.0,
        300.0,
        [(1.5, 0.01, Distribution::Ggx), (1.5, 0.01, Distribution::Ggx)],
        FaceScattering::Multiple,
    )
}

fn cases() -> Vec<(&'static str, PaperParams)> {
    use Distribution::{Beckmann, Ggx};
    let mut v = vec![
        ("matte", preset("matte").unwrap()),
        ("luster", preset("luster").unwrap()),
        (
            "thin-tissue",
            sheet(
                0.03,
                0.5,
                100.0,
                [(1.5, 0.2, Ggx), (1.5, 0.35, Beckmann)],
                FaceScattering::Multiple,
            ),
        ),
        (
            "weak-scatter",
            sheet(
                0.1,
                2.0,
                10.0,
                [(1.5, 0.3, Ggx), (1.5, 0.3, Ggx)],
                FaceScattering::Single,
            ),
        ),
        // Unequal faces smoother than the grid on a thin sheet: the
        // unscattered transmission's narrow lobe and its own sampling lobe.
        (
            "thin-narrow",
            sheet(
                0.02,
                0.5,
                30.0,
                [(1.5, 0.05, Ggx), (1.5, 0.02, Beckmann)],
                FaceScattering::Multiple,
            ),
        ),
    ];
    v.push((
        "smooth",
        sheet(
            0.05,
            1.0,
            40.0,
            [(1.5, 0.0, Ggx), (1.5, 0.0, Ggx)],
            FaceScattering::Single,
        ),
    ));
    v.push(("glossy", preset("glossy").unwrap()));
    v.push((
        "coated-smooth",
        sheet(
            0.05,
            1.0,
            40.0,
            [(1.55, 0.0, Ggx), (1.45, 0.0, Ggx)],
            FaceScattering::Single,
        ),
    ));
    // A thin coated sheet (optical thickness 0.6): its unscattered
    // transmission crosses the coating/base boundary (a base less dense
    // than the coating: total reflection there), analytic since 2026-12-07.
    v.push((
        "thin-coated",
        sheet(
            0.02,
            0.5,
            30.0,
            [(1.5, 0.3, Ggx), (1.4, 0.1, Beckmann)],
            FaceScattering::Multiple,
        ),
    ));
    v.push((
        "coated-rough",
        sheet(
            0.04,
            0.5,
            60.0,
            [(1.45, 0.2, Beckmann), (1.6, 0.3, Ggx)],
            FaceScattering::Multiple,
        ),
    ));
    v.push((
        "index-matched",
        sheet(
            0.05,
            1.0,
            40.0,
            [(1.0, 0.0, Ggx), (1.0, 0.0, Ggx)],
            FaceScattering::Single,
        ),
    ));
    v
}

fn dir(theta_deg: f64, phi: f64, side: f64) -> DVec3 {
    let w = spherical_direction(theta_deg.to_radians(), phi);
    DVec3::new(w.x, w.y, side * w.z)
}

/// Each case is tested at viewers where its sampling is hardest: just off
/// normal (between the two largest nodes), off the nodes at 47 degrees and
/// grazing at 84, from the front and from behind. 40,000 draws per test.
#[test]
fn sampling_matches_the_density() {
    let mut failures = Vec::new();
    let mut p_min = 1.0f64;
    let mut n = 0;
    let viewers = [(0.3, 1.0), (47.0, -1.0), (84.0, 1.0), (84.0, -1.0)];
    for (name, p) in cases() {
        let b = SlabBsdf::new(&p).unwrap();
        for (k, &(theta, side)) in viewers.iter().enumerate() {
            if name != "luster" && k == 3 {
                continue;
            }
            let wo = dir(theta, 0.7, side);
            let r = chi2::chi2_test(
                &format!("{name} theta_o={theta} side={side}"),
                |u| {
                    b.sample(wo, u[0], [u[1], u[2]])
                        .filter(|s| !s.flags.is_specular())
                        .map(|s| s.wi)
                },
                |wi| b.pdf(wi, wo),
                40_000,
                7 + n as u64,
            );
            n += 1;
            match r {
                Ok(pv) => {
                    eprintln!("{name} theta_o={theta} side={side}: p = {pv:.3e}");
                    p_min = p_min.min(pv)
                }
                Err(e) => failures.push(e),
            }
        }
    }
    eprintln!("{n} chi-square tests, smallest p = {p_min:.3e}");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// `sample` returns `eval` and `pdf` at the direction it draws. Its density
/// is not `pdf`'s code path: a draw from the table's cells hands its cell
/// to the density (no `acos` of the azimuth, no bin search), so the two
/// agree only if the cell is the one `pdf` finds from `wi`; viewers at
/// normal incidence (azimuth reference `+x`), in the last interval of
/// nodes, off the nodes and grazing, from both sides.
#[test]
fn sample_returns_eval_and_pdf() {
    for (name, p) in cases() {
        let b = SlabBsdf::new(&p).unwrap();
        for wo in [
            dir(0.0, 0.0, 1.0),
            dir(2.0, 0.4, -1.0),
            dir(38.0, 1.1, -1.0),
            dir(47.0, 2.9, 1.0),
            dir(84.0, 5.0, 1.0),
            dir(84.0, 0.3, -1.0),
        ] {
            sample_agrees(name, &b, wo);
        }
    }
}

/// 400 draws of `b.sample` at `wo`: each draw's `f` and `pdf` against
/// `eval` and `pdf` at its `wi`, to 1e-12 (rounding); the pdf to 1e-11:
/// `pdf` places `wi` in the table's cells by the azimuth difference from
/// its cosine (`acos`, which loses digits where that difference is small),
/// the sampler by its own draw, and where a thin sheet with narrow faces
/// sends the light straight through (`thin-narrow`) the density changes
/// fast across the cell: 1.2e-12 measured there.
fn sample_agrees(name: &str, b: &SlabBsdf, wo: DVec3) {
    for i in 0..400 {
        let u = [
            (i as f64 + 0.5) / 400.0,
            ((i * 7) % 400) as f64 / 400.0,
            ((i * 13) % 397) as f64 / 397.0,
        ];
        let Some(s) = b.sample(wo, u[0], [u[1], u[2]]) else {
            continue;
        };
        assert!((s.wi.length() - 1.0).abs() < 1e-9, "{name}: non-unit {:?}", s.wi);
        if s.flags.is_specular() {
            continue;
        }
        let (f, pdf) = (b.eval(s.wi, wo), b.pdf(s.wi, wo));
        for c in 0..3 {
            assert!(
                (s.f.0[c] - f.0[c]).abs() <= 1e-12 * f.0[c].abs().max(1e-300),
                "{name} at wo {wo:?}: f {s:?} vs {f:?}"
            );
        }
        assert!(
            (s.pdf - pdf).abs() <= 1e-11 * pdf,
            "{name} at wo {wo:?}, wi {:?}: pdf {} vs {pdf}",
            s.wi,
            s.pdf
        );
    }
}

#[test]
fn reciprocity_holds_for_unequal_faces() {
    let mut worst = 0.0f64;
    for (name, p) in cases() {
        let b = SlabBsdf::new(&p).unwrap();
        // 9, 12 and 17 degrees: between the nodes where the odd orders take
        // their ratio (both directions at once, too).
        for a in [0.0, 3.0, 9.0, 21.0, 55.0, 79.0, 88.0] {
            for c in [1.0, 12.0, 17.0, 40.0, 66.0, 87.0] {
                for (sa, sc) in [(1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)] {
                    let (wi, wo) = (dir(a, 0.3, sa), dir(c, 2.2, sc));
                    let (f, r) = (b.eval(wi, wo), b.eval(wo, wi));
                    for k in 0..3 {
                        let e = (f.0[k] - r.0[k]).abs() / f.0[k].abs().max(1e-6);
                        worst = worst.max(e);
                        assert!(e < 1e-9, "{name}: f({a},{c},{sa},{sc}) = {f:?}, reversed {r:?}");
                    }
                }
            }
        }
    }
    eprintln!("reciprocity: worst relative difference {worst:.2e}");
}

/// `albedo_from` integrates over the outgoing argument with every component
/// and the delta lobes: no albedo above 1 (96 x 96 stratified samples; the
/// quasi-random estimator's own error is a few 1e-4, see below).
#[test]
fn energy_is_bounded() {
    for (name, p) in cases() {
        let b = SlabBsdf::new(&p).unwrap();
        for side in [1.0, -1.0] {
            for theta in [0.0, 30.0, 60.0, 80.0, 89.0] {
                let (r, t) = albedo_from(&b, dir(theta, 0.2, side), 96);
                let a = (r + t).max_channel();
                assert!(a <= 1.0 + 3e-3, "{name}: albedo {a} at theta {theta} side {side}");
            }
        }
    }
}

/// Non-absorbing sheets with energy-conserving faces (`face_scattering =
/// "multiple"`) close: `R + T = 1 +- 1e-4`, by [`grid_albedo`]
/// (deterministic: `albedo_from`'s quasi-random estimate carries a bias of
/// about -2e-4 of its own here, from its correlated strata over the table's
/// discontinuous cells, so it cannot show 1e-4). Rough faces only (the rule
/// has no delta lobes), among them a coated front and a thin, weakly
/// scattering sheet (optical thickness 0.2 with a GGX 0.1 front: its
/// unscattered light makes the narrowest table lobes, where the
/// interpolation in `mu_o` integrated 4% above 1 before the tables were
/// balanced), and one of optical thickness 0.3 between GGX 0.01 faces
/// (the unscattered light most of the transmission), both sides, every 5
/// degrees from normal to 85 degrees (nodes and between them, where the
/// interpolation in `mu_i` left 4e-4 before the crossing shapes), at 1, 2
/// and 3 degrees (within the last node interval, where the orders `m >= 1`
/// are carried from the node before the pole: until 2026-12-06 their sum
/// went below zero away from a narrow lobe and `eval`'s clamp gave the GGX
/// 0.01 sheet up to 2.2e-3 more light than it received, `fourier_sum_pole`
/// in src/bsdf.rs) and at 88 degrees (the table and analytic terms only,
/// as on the GGX 0.01 sheet everywhere: the rule over `wo` does not
/// resolve the face's lobe there).
///
/// What `slab` adds to the lit face is `eval` less the lit face's lobe
/// (component `surface`; the table, clamped as `eval` clamps it, and the
/// analytic terms): its integral plus the face's reflectance as `slab`
/// takes it (`SlabBsdf::face_reflectance`: the analytic lobe's albedo
/// integrated at the nodes over the micro-normal, `face_albedo`) must be 1
/// within 1e-4, the bound (measured: 9.1e-5 at 88 degrees on the
/// GGX 0.01 sheet, 5.5e-5 at 70 degrees on the thin one with a GGX 0.1
/// front; 1.0e-5 with the analytic terms integrated by the rule the build
/// balances them with, which cannot see that rule's own error: that was
/// this test's rule until 2026-12-06, when the build's rule had one point
/// per table interval and `eval` was 3.6e-3 off on the GGX 0.01 sheet and
/// 1.2e-3 on the GGX 0.1 one, see [`ANALYTIC_RULE`]; the rule for the
/// table is exact for the table's Fourier sum in
/// azimuth and, with three points on each of [`SURFACE_SPLIT`] parts per
/// interval, nearly so in `mu_o`: 8.2e-6 with six points on 32 parts, where
/// it is exact for the crossing shapes' linear steps; six points on the
/// whole interval, enough for the bilinear interpolation, read 5.9e-5 since
/// the ridge ratios bend the shapes within the intervals).
/// The interpolation's triangles alone, without the ridge ratios that
/// restore the albedo between the nodes of `mu_i`, were 6.1e-4 off (the
/// first sheet at 15 degrees; 3e-7 with bilinear weights, which are 3.7%
/// low on a thin sheet's transmission peak between the nodes). The analytic lobe (component `surface`) is
/// integrated by the same rule over `wo`, finer ([`SURFACE_SPLIT`],
/// [`SURFACE_PHI`]: doubling both moves no sum by 1e-7), which checks
/// `face_reflectance` independently (within 1e-4; measured 1.6e-5), and
/// table plus lobe, the whole `eval`, must be 1 within 1e-4 at every angle
/// (measured 1.6e-5). With core's tabulated reflectance in
/// place of `face_albedo`, which differs from its own lobe's integral by
/// 1e-4 at normal incidence (the coated Beckmann 0.25 front) and up to
/// 1.7e-3 at grazing, this was 1.15e-4 up to 50 degrees.
/// Points per table interval in `x` and in azimuth of the rule that
/// integrates the analytic lobes (`SlabBsdf::analytic_albedo_with`): three
/// and five times the build's (2 and 48). With the build's own rule the
/// test cannot see that rule's error: until 2026-12-06 it had one point
/// per interval and left `eval` 2-4e-3 of the term's albedo from its
/// integral at 80 degrees (a thin sheet's unscattered light through GGX
/// 0.01 faces), which this test, then using that rule, passed (measured
/// with this one: examples/two_crossings.rs prints the build's rule against
/// it).
const ANALYTIC_RULE: (usize, usize) = (6, 256);
/// Parts per node interval of the rule in `mu_o`.
const SURFACE_SPLIT: usize = 8;
/// Azimuth points of the table's albedo: above the default walk orders
/// (256), and above the most orders the sheet keeps where a face's walk has
/// more (`SlabBsdf::most_orders`; the midpoint rule on the circle integrates
/// `cos(m phi)` exactly for `m` below its points: with 272 points a GGX 0.1
/// front's 384 orders aliased, 2.8e-4 at 85 degrees).
const TABLE_PHI: usize = 272;
/// Azimuths of the rule for the analytic lobe.
const SURFACE_PHI: usize = 768;

#[test]
fn energy_closes_without_absorption() {
    let sheets = [
        sheet(
            0.05,
            0.0,
            60.0,
            [(1.5, 0.2, Distribution::Ggx), (1.5, 0.45, Distribution::Beckmann)],
            FaceScattering::Multiple,
        ),
        sheet(
            0.05,
            0.0,
            60.0,
            [(1.6, 0.25, Distribution::Beckmann), (1.45, 0.3, Distribution::Ggx)],
            FaceScattering::Multiple,
        ),
        sheet(
            0.02,
            0.0,
            10.0,
            [(1.5, 0.1, Distribution::Ggx), (1.5, 0.3, Distribution::Beckmann)],
            FaceScattering::Multiple,
        ),
        thin_between_smooth_faces(),
        // Thin and coated (optical thickness 0.6, a base less dense than
        // the coating): the unscattered term through the boundary (since
        // 2026-12-07).
        sheet(
            0.02,
            0.0,
            30.0,
            [(1.5, 0.15, Distribution::Ggx), (1.4, 0.3, Distribution::Beckmann)],
            FaceScattering::Multiple,
        ),
    ];
    let (mut worst_table, mut worst_total, mut worst_lobe) = (0.0f64, 0.0f64, 0.0f64);
    for (k, p) in sheets.iter().enumerate() {
        let b = SlabBsdf::new(p).unwrap();
        for side in [1.0, -1.0] {
            let face = if side > 0.0 { Side::Front } else { Side::Back };
            let thetas = (0..18).map(|i| 5.0 * i as f64).chain([1.0, 2.0, 3.0, 88.0]);
            for theta in thetas {
                let wi = dir(theta, 0.2, side);
                // The analytic lobes (a coated front's round trip, the
                // unscattered transmission) by a finer rule than the one
                // the build balances them with (ANALYTIC_RULE).
                let (r_analytic, t_analytic) = b.analytic_albedo_with(wi, ANALYTIC_RULE.0, ANALYTIC_RULE.1);
                let table = grid_albedo(
                    |wo| (b.eval(wi, wo) - b.eval_component(wi, wo, Component::Surface) - b.analytic_at(wi, wo)).mean(),
                    b.nodes(),
                    wi.z.abs(),
                    3,
                    SURFACE_SPLIT,
                    TABLE_PHI.max(b.most_orders() + 16),
                ) + (r_analytic + t_analytic).mean();
                let e = table + b.face_reflectance(face, wi.z.abs()) - 1.0;
                worst_table = worst_table.max(e.abs());
                assert!(
                    e.abs() < 1e-4,
                    "sheet {k}: table + face = 1 {e:+.2e} at theta {theta} side {side}"
                );
                // At 88 degrees the rule over `wo` does not resolve the
                // face's lobe two degrees from the horizon (GGX 0.1: 1.7e-3
                // off face_reflectance), nor GGX 0.01's anywhere (1.3e-4
                // at 60 degrees); the table is checked there.
                if theta > 85.0 || k == 3 {
                    continue;
                }
                let surface = grid_albedo(
                    |wo| b.eval_component(wi, wo, Component::Surface).mean(),
                    b.nodes(),
                    wi.z.abs(),
                    6,
                    SURFACE_SPLIT,
                    SURFACE_PHI,
                );
                // The lobe's albedo as slab balances against it, by an
                // independent rule (here over wo, there over the micro-normal).
                let lobe = (surface - b.face_reflectance(face, wi.z.abs())).abs();
                worst_lobe = worst_lobe.max(lobe);
                assert!(
                    lobe < 1e-4,
                    "sheet {k}: the surface lobe integrates to {surface}, face_reflectance {} at theta {theta} side {side}",
                    b.face_reflectance(face, wi.z.abs())
                );
                let total = table + surface;
                worst_total = worst_total.max((total - 1.0).abs());
                assert!(
                    (total - 1.0).abs() < 1e-4,
                    "sheet {k}: R + T = 1 {:+.2e} at theta {theta} side {side}",
                    total - 1.0
                );
            }
        }
    }
    eprintln!(
        "conservative sheets: |table + face - 1| <= {worst_table:.2e}, |surface lobe - face_reflectance| <= {worst_lobe:.2e}, |R + T - 1| <= {worst_total:.2e}"
    );
}

/// At the nodes, in transmission, `eval` is the solution's BSDF with the
/// faces' crossings rescaled (`crossing_factors`, which must stay within 3%
/// of 1: the projected faces' R/T split is good to about 1e-3 in albedo),
/// split (`split_factors`) and balanced (`balance_factors`; the two within
/// 2%; the crossing shapes are 1 at the nodes).
#[test]
fn eval_at_the_nodes_is_the_solution() {
    let p = preset("luster").unwrap();
    let opts = SlabOptions::default();
    let b = SlabBsdf::with_options(&p, &opts).unwrap();
    let spec = SlabSpec::from_params(&p, 0).unwrap();
    let disc = paperbsdf_slab::Discretisation {
        nodes: opts.nodes,
        tir_nodes: opts.tir_nodes,
        orders: opts.orders,
        ..Default::default()
    };
    let sol = spec.solve(&disc).unwrap();
    let mu = b.nodes().to_vec();
    let n = mu.len();
    for side in paperbsdf_core::paper::Side::BOTH {
        for &s in b.crossing_factors(side) {
            assert!((s - 1.0).abs() < 0.03, "crossing factor {s}");
        }
        // The interpolation's balance moves the nodes' values by little
        // (luster's narrowest lobe is its Beckmann 0.15 front's).
        for x in b.balance_factors(side) {
            assert!((x.0[0] - 1.0).abs() < 0.02, "balance factor {}", x.0[0]);
        }
        for transmit in [false, true] {
            for y in b.split_factors(transmit, side) {
                assert!((y.0[0] - 1.0).abs() < 0.02, "split factor {}", y.0[0]);
            }
        }
    }
    for &j in &[3usize, 12, 20, n - 2] {
        for &o in &[5usize, 17, 25] {
            let (si, so) = ((1.0 - mu[j] * mu[j]).sqrt(), (1.0 - mu[o] * mu[o]).sqrt());
            // Transmission, front: light from wi = (-si, 0, mu_j) propagating forward
            // leaves at wo = (so cos phi, so sin phi, -mu_o).
            for phi in [0.0f64, 1.3, 3.0] {
                let wi = DVec3::new(-si, 0.0, mu[j]);
                let wo = DVec3::new(so * phi.cos(), so * phi.sin(), -mu[o]);
                // The table's crossings of the two faces are rescaled by
                // the factors that make the faces' transmittance match their
                // exact reflection (crossing_factors).
                // and balanced (balance_factors).
                let (front, back) = (paperbsdf_core::paper::Side::Front, paperbsdf_core::paper::Side::Back);
                let s = b.crossing_factors(front)[j]
                    * b.crossing_factors(back)[o]
                    * b.split_factors(true, front)[j].0[0]
                    * b.split_factors(true, back)[o].0[0]
                    * b.balance_factors(front)[j].0[0]
                    * b.balance_factors(back)[o].0[0];
                let want = s * sol.bsdf_at_nodes(paperbsdf_slab::Side::Front, true, o, j, phi);
                let got = b.eval(wi, wo).0[0];
                assert!(
                    (got - want).abs() <= 1e-9 * want.abs() + 1e-12,
                    "T at nodes ({o}, {j}, {phi}): {got} vs {want}"
                );
            }
        }
    }
}

#[test]
fn smooth_sheets_have_closed_form_delta_lobes() {
    // Two smooth faces: the delta transmission of the unscattered light is
    // (1-F)^2 a / (1 - F^2 a^2), a = exp(-tau / mu_t).
    let p = sheet(
        0.05,
        1.0,
        40.0,
        [(1.5, 0.0, Distribution::Ggx), (1.5, 0.0, Distribution::Ggx)],
        FaceScattering::Single,
    );
    let b = SlabBsdf::new(&p).unwrap();
    let tau = 0.05 * 41.0;
    for theta in [0.0f64, 40.0, 75.0] {
        let wo = dir(theta, 0.0, 1.0);
        let mu = wo.z;
        let f = paperbsdf_core::fresnel::fresnel_dielectric(mu, 1.5);
        let mu_t = paperbsdf_core::fresnel::cos_transmitted(mu, 1.5).unwrap().abs();
        let a = (-tau / mu_t).exp();
        let t_want = (1.0 - f) * (1.0 - f) * a / (1.0 - f * f * a * a);
        let mut t_got = 0.0;
        for i in 0..1000 {
            let uc = (i as f64 + 0.5) / 1000.0;
            if let Some(s) = b.sample(wo, uc, [0.3, 0.6]) {
                if s.flags.is_specular() && s.wi.z < 0.0 {
                    assert!((s.wi + wo).length() < 1e-12);
                    t_got = s.f.0[0] * mu;
                }
            }
        }
        assert!(
            (t_got - t_want).abs() < 1e-12,
            "theta {theta}: delta T {t_got} vs {t_want}"
        );
    }
}

/// A coated sheet with two smooth faces: the closed-form delta lobes
/// (`SmoothSheet`, with the coating's interreflections) against the
/// adding-doubling solution without scattering at the nodes (whose smooth
/// interfaces are exact diagonal maps), from both sides.
#[test]
fn coated_smooth_delta_lobes_match_the_solver() {
    for (eta_f, eta_b) in [(1.55, 1.45), (1.4, 1.6)] {
        let p = sheet(
            0.05,
            1.0,
            40.0,
            [(eta_f, 0.0, Distribution::Ggx), (eta_b, 0.0, Distribution::Ggx)],
            FaceScattering::Single,
        );
        let b = SlabBsdf::new(&p).unwrap();
        let spec = SlabSpec::from_params(&p, 0).unwrap();
        let prep = spec.prepare(&paperbsdf_slab::Discretisation::default()).unwrap();
        let unscattered = prep.solve(0.0, spec.medium.tau).unwrap();
        let mu = b.nodes().to_vec();
        for &j in &[5usize, 18, mu.len() - 1] {
            for (side, sgn) in [(paperbsdf_slab::Side::Front, 1.0), (paperbsdf_slab::Side::Back, -1.0)] {
                let (r_want, t_want) = unscattered.totals_collimated(side, j);
                let wo = DVec3::new((1.0 - mu[j] * mu[j]).sqrt(), 0.0, sgn * mu[j]);
                let (mut r, mut t) = (0.0, 0.0);
                for i in 0..2000 {
                    if let Some(s) = b.sample(wo, (i as f64 + 0.5) / 2000.0, [0.3, 0.6]) {
                        if s.flags.is_specular() {
                            if s.wi.z * wo.z > 0.0 {
                                r = s.f.0[0] * mu[j];
                            } else {
                                t = s.f.0[0] * mu[j];
                            }
                        }
                    }
                }
                assert!(
                    (r - r_want).abs() < 1e-10 && (t - t_want).abs() < 1e-10,
                    "eta {eta_f}/{eta_b} node {j} {side:?}: delta R {r} T {t}, solver {r_want} {t_want}"
                );
            }
        }
    }
}

/// The components sum to `eval` on the accuracy cases and on a sheet
/// whose table's parts ring below zero (optical thickness 0.3 between GGX
/// 0.01 faces: grazing directions seen backwards), on a grid of directions
/// near the normal and at grazing angles, reflection and transmission, both
/// sides: `eval` clamps the table at 0, and the components clamp its
/// unscattered part at 0 and at the clamped table, its first-order part
/// (`single`, since 2026-12-07) at 0 and at what the unscattered part
/// leaves; each is at least 0. Until 2026-12-06 each
/// component was clamped on its own, and their sum exceeded `eval` where
/// one rang: on this sheet by 3.4 times `eval` at 86 T 87 degrees, phi 3.51
/// (a probe over such sheets; GGX 0.001 faces 1.8 times).
#[test]
fn components_sum_to_eval() {
    let mut sheets = cases();
    sheets.push(("tau 0.3 between GGX 0.01 faces", thin_between_smooth_faces()));
    for (name, p) in sheets {
        let b = SlabBsdf::new(&p).unwrap();
        let mut pairs = vec![
            (dir(20.0, 0.0, 1.0), dir(50.0, 2.0, 1.0)),
            (dir(70.0, 0.0, -1.0), dir(10.0, 0.5, 1.0)),
            (dir(5.0, 0.0, 1.0), dir(35.0, 3.0, -1.0)),
        ];
        // Near the normal, and at grazing angles seen backwards (phi near
        // pi), where the table's parts ring on this sheet.
        for (ti, to) in [1.0, 2.5, 4.0, 8.0, 61.0, 76.0, 86.0]
            .into_iter()
            .flat_map(|ti| [1.5, 3.0, 6.0, 12.0, 62.0, 77.0, 87.0].map(move |to| (ti, to)))
        {
            {
                for phi in [0.3, 1.6, 3.0, 3.24, 3.51] {
                    for (si, so) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0)] {
                        pairs.push((dir(ti, 0.0, si), dir(to, phi, so)));
                    }
                }
            }
        }
        assert_eq!(
            b.components(),
            [
                Component::Surface,
                Component::Single,
                Component::Multiple,
                Component::Direct
            ]
        );
        for (wi, wo) in pairs {
            let total = b.eval(wi, wo);
            let sum = b
                .components()
                .iter()
                .fold(paperbsdf_core::Rgb::ZERO, |s, &c| s + b.eval_component(wi, wo, c));
            for k in 0..3 {
                assert!(
                    (total.0[k] - sum.0[k]).abs() <= 1e-9 * total.0[k].abs().max(1e-9),
                    "{name}: components {sum:?} vs eval {total:?}"
                );
            }
            for &c in b.components() {
                let v = b.eval_component(wi, wo, c);
                assert!(v.0.iter().all(|x| *x >= 0.0), "{name}: {c:?} {v:?} below 0");
            }
        }
        // Every sheet here scatters: light scattered once leaves.
        let single = b.eval_component(dir(20.0, 0.0, 1.0), dir(20.0, 3.1, 1.0), Component::Single);
        assert!(single.0.iter().all(|x| *x > 0.0), "{name}: single {single:?}");
    }
}

/// A grey sheet (one medium for all channels) stores and sums one channel
/// instead of three (`Tables::channels`): its eval, every component and
/// both sides, equals channel 0 of the same sheet with a different
/// absorption in channels 1 and 2 (three channels stored, channel 0 the same
/// medium and solve), at grazing, near-normal and off-node directions, in
/// reflection and transmission. They agree to rounding: the same operations,
/// except that the RGB sheet sums the walk's orders past the solution's apart
/// from the orders below (stored once for its three channels,
/// `Tables::head`), a different grouping of the same sum, so the tolerance
/// has an absolute floor of 1e-15 (1e-12 of 1e-3; the coefficients are of
/// order 1e-3 to 10, and a component near 1e-8 moved by 1e-10 of itself).
/// One exception, by design: where the lit face's walk rings at grazing
/// reflection pairs, the pair takes a share of Fejer's weights that no
/// channel rings with (src/bsdf.rs, `FEJER_SHARE_STEPS`), one share for the
/// three channels so that their orders past the solution's stay
/// proportional and are summed once; the RGB sheet's more absorbing
/// channels can ask for a little more than the grey sheet's own. There
/// (reflection with a direction beyond 80 degrees) within 1e-5 of the
/// value (measured 1.9e-6).
#[test]
fn grey_sheet_is_the_rgb_sheet_channel() {
    let grey = preset("luster").unwrap();
    let Colour::Scalar(sa) = grey.sigma_a else {
        panic!("luster's sigma_a is grey")
    };
    let rgb = PaperParams {
        sigma_a: Colour::Rgb([sa, 2.0 * sa + 0.1, 3.0 * sa + 0.2]),
        ..grey.clone()
    };
    let (g, c) = (SlabBsdf::new(&grey).unwrap(), SlabBsdf::new(&rgb).unwrap());
    let (mut n, mut worst_grazing) = (0, 0.0f64);
    for (ti, pi) in [(0.2, 0.0), (33.0, 0.4), (61.0, 1.1), (84.0, 2.9)] {
        for (to, po) in [(0.5, 0.3), (17.0, 2.0), (47.0, 0.0), (79.0, 3.1), (88.0, 1.6)] {
            for (si, so) in [(1.0, 1.0), (1.0, -1.0), (-1.0, -1.0), (-1.0, 1.0)] {
                let (wi, wo) = (dir(ti, pi, si), dir(to, po, so));
                let want = c.eval(wi, wo).0[0];
                let got = g.eval(wi, wo);
                // Reflection with either direction beyond 80 degrees may
                // meet a pair whose walk window the other channels set.
                let tol = if si == so && ti.max(to) > 80.0 { 1e-5 } else { 1e-12 };
                let e = (got.0[0] - want).abs() / want.abs().max(1e-3);
                worst_grazing = worst_grazing.max(if tol > 1e-12 { e } else { 0.0 });
                assert!(
                    e <= tol,
                    "eval({ti},{pi},{si} -> {to},{po},{so}): grey {got:?}, rgb channel 0 {want}"
                );
                assert!(got.0[0] == got.0[1] && got.0[1] == got.0[2], "grey eval {got:?}");
                for &k in g.components() {
                    let (a, b) = (g.eval_component(wi, wo, k).0[0], c.eval_component(wi, wo, k).0[0]);
                    // The share's change is of the pair's whole value.
                    let scale = if tol > 1e-12 { want.abs() } else { b.abs() };
                    assert!((a - b).abs() <= tol * scale.max(1e-3), "{k:?}: {a} vs {b}");
                }
                n += 1;
            }
        }
    }
    assert_eq!(n, 80);
    eprintln!("grey against the RGB sheet's channel 0 in grazing reflection: {worst_grazing:.1e}");
    assert!(g.memory_bytes() < c.memory_bytes());
}

/// [`face_albedo`] (the surface lobe's albedo that `slab` balances its
/// table against): (a) as the roughness goes to 0 it tends to Fresnel's
/// reflectance (closed form; Walter's lobe of GGX and Beckmann m = 0.003,
/// whose masking and spread are below 1e-4 away from grazing), (b) its rule
/// has converged at the model's panels (against 4 times as many, at
/// grazing and normal incidence, where the masking's and the horizon's
/// kinks are hardest, for rough, smooth and coated faces; the
/// wo-space rule of `energy_closes_without_absorption` checks it
/// independently).
#[test]
fn face_albedo_is_fresnel_when_smooth_and_converged() {
    use paperbsdf_core::fresnel::fresnel_dielectric;
    use paperbsdf_slab::bsdf::FACE_ALBEDO_PANELS;
    let mk = |eta_f: f64, m: f64, d: Distribution| {
        let p = sheet(
            0.05,
            0.1,
            60.0,
            [(eta_f, m, d), (1.45, 0.3, Distribution::Ggx)],
            FaceScattering::Single,
        );
        PaperBsdf::new(&p).unwrap()
    };
    for d in [Distribution::Ggx, Distribution::Beckmann] {
        let paper = mk(1.5, 0.003, d);
        for mu in [1.0, 0.7, 0.3] {
            let a = face_albedo(&paper, Side::Front, mu, FACE_ALBEDO_PANELS);
            let f = fresnel_dielectric(mu, 1.5);
            assert!((a - f).abs() < 1e-4, "{d:?} m 0.003 mu {mu}: {a} vs Fresnel {f}");
        }
    }
    for (eta, m, d) in [
        (1.5, 0.1, Distribution::Ggx),
        (1.6, 0.25, Distribution::Beckmann),
        (1.5, 0.8, Distribution::Ggx),
        (1.5, 0.04, Distribution::Beckmann),
    ] {
        let paper = mk(eta, m, d);
        for mu in [1.0, 0.5, 0.1, 0.03, 0.005] {
            let a = face_albedo(&paper, Side::Front, mu, FACE_ALBEDO_PANELS);
            let fine = face_albedo(&paper, Side::Front, mu, 4 * FACE_ALBEDO_PANELS);
            assert!(
                (a - fine).abs() < 5e-5,
                "{d:?} {m} mu {mu}: {a} vs {fine} with 4x the panels"
            );
        }
    }
}

#[test]
fn bad_input_is_an_error() {
    let p = preset("matte").unwrap();
    let e = SlabBsdf::with_options(
        &p,
        &SlabOptions {
            orders: 0,
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(e.to_string().contains("orders"), "{e}");
    let e = SlabBsdf::with_options(
        &p,
        &SlabOptions {
            orders: 64,
            walk_orders: 48,
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(e.to_string().contains("walk_orders"), "{e}");
    // A coated front (eta_f != eta_b: the glossy preset) is no longer an
    // error since the solver has the coating (tests/coated.rs).
    let glossy = preset("glossy").unwrap();
    if let Err(e) = SlabBsdf::new(&glossy) {
        panic!("glossy: {e}");
    }
    let mut bad = p.clone();
    bad.m_f = 2.0;
    let e = SlabBsdf::new(&bad).unwrap_err();
    assert!(e.to_string().contains("m_f"), "{e}");
}

/// Near the normal (inside the last interval of nodes, `theta < 4.85`
/// degrees with 32 nodes) the table's orders `m >= 1` follow `sin^m theta`,
/// as a smooth function's on the sphere do, interpolated in the other
/// direction's `mu` (`pole_corners` in src/bsdf.rs). The transmission of a
/// thin sheet with unequal faces agrees with the same sheet on twice the
/// nodes (whose last interval ends at 2.4 degrees), on both sides of the
/// normal and both sides of incidence:
/// - lit at 30 degrees, seen within 4.5 degrees of the normal: within 0.5%
///   (measured 0.21%, 0.16% with the odd orders' ratio alone, 0.36%
///   before it; the sine law below). Linear
///   weights in `mu`, which make every order fall like `theta^2` and so
///   halve order 1 in the middle of the interval, were 3.2% apart (and 8%
///   for the accuracy tables' thin tissue at 2.5 degrees, of opposite signs
///   either side of the normal);
/// - lit at 2.5 degrees, seen 5 to 10 degrees off the normal: within 0.5%
///   (measured 0.16%, with the other direction's sine law on the pole's
///   corners; 0.24% with the odd orders' ratio alone, 0.19% before it, 2.84% before the walk's
///   orders per face and the analytic terms' finer rule, 4.29% when the
///   orders `m >= 1` came from the triangles' one node of `mu_o` in the
///   column before the pole);
/// - lit 5.5 to 15 degrees from the normal (between the nodes past the
///   pole's interval, 4.85, 8.87, 12.85 and 16.81 degrees), seen 12 to 40
///   degrees off it: within 0.6% (measured 0.39%; 0.32% with the odd
///   orders' ratio alone, 1.01% with linear weights in `mu`, which took
///   order 1 as a chord of `sin theta`, lit at 6.5 degrees). There every
///   order `m` follows `sin^m theta` between the nodes (`SIN_LAW_BAND`);
/// - lit and seen at the same angle, 17.5 to 30 degrees, the viewer on the
///   light's side (the far flank of the forward lobe, where the value is
///   the small remainder of orders 0 and 1): within 0.3% (measured 0.14%;
///   1.1% at 18.5 degrees when only the odd orders took a ratio, within
///   20 degrees).
#[test]
fn transmission_near_the_normal_converges() {
    let p = cases().into_iter().find(|(n, _)| *n == "thin-tissue").unwrap().1;
    let (b0, b1) = support::default_and_doubled_nodes(&p);
    // The two builds' values at `(wi, wo)` and how far apart they are.
    let apart = |wi, wo| {
        let (x, y) = (b0.eval(wi, wo).mean(), b1.eval(wi, wo).mean());
        (x, y, (x / y - 1.0).abs())
    };
    let (mut worst, mut worst_in) = (0.0f64, 0.0f64);
    for side in [1.0, -1.0] {
        for t in [-4.5, -3.6, -2.7, -1.8, -0.9, 0.9, 1.8, 2.7, 3.6, 4.5] {
            let wi = dir(30.0, PI, side);
            // In the plane of incidence, `t > 0` on the far side of the normal.
            let wo = dir(t, 0.0, -side);
            let (x, y, e) = apart(wi, wo);
            worst = worst.max(e);
            assert!(e < 0.005, "side {side}, theta_o {t}: {x} with 32 nodes, {y} with 64");
        }
        // Lit near the normal, seen off it.
        for t in [-10.0, -7.5, -5.0, 5.0, 7.5, 10.0] {
            let wi = dir(2.5, PI, side);
            let wo = dir(t, 0.0, -side);
            let (x, y, e) = apart(wi, wo);
            worst_in = worst_in.max(e);
            assert!(
                e < 0.005,
                "side {side}, lit at 2.5, theta_o {t}: {x} with 32 nodes, {y} with 64"
            );
        }
    }
    // Lit between the nodes past the pole's interval, seen in transmission
    // further out (the sine law, `SIN_LAW_BAND`).
    let mut worst_band = 0.0f64;
    for side in [1.0, -1.0] {
        for ti in [5.5, 6.5, 7.5, 10.0, 11.0, 14.0, 15.0] {
            for t in [-40.0, -26.0, -18.0, -12.0, 12.0, 18.0, 26.0, 40.0] {
                let wi = dir(ti, PI, side);
                let wo = dir(t, 0.0, -side);
                let (x, y, e) = apart(wi, wo);
                worst_band = worst_band.max(e);
                assert!(
                    e < 0.006,
                    "side {side}, lit at {ti}, theta_o {t}: {x} with 32 nodes, {y} with 64"
                );
            }
        }
    }
    // The far flank of the forward lobe: lit and seen at the same angle,
    // the viewer on the light's side (twice the angle from straight
    // through), across the intervals of nodes at 16.81-20.74, 20.74-24.64
    // and 28.51-32.34 degrees, where the value is the small remainder of
    // orders 0 and 1 (the sine law on every order, `SIN_LAW_BAND`).
    let mut worst_flank = 0.0f64;
    for side in [1.0, -1.0] {
        for t in [17.5, 18.25, 18.5, 19.0, 22.0, 23.0, 26.0, 30.0] {
            let wi = dir(t, PI, side);
            let wo = dir(-t, 0.0, -side);
            let (x, y, e) = apart(wi, wo);
            worst_flank = worst_flank.max(e);
            assert!(
                e < 0.003,
                "side {side}, lit and seen at {t} on the light's side: {x} with 32 nodes, {y} with 64"
            );
        }
    }
    eprintln!(
        "near the normal: 32 against 64 nodes within {:.2}% (seen), {:.2}% (lit), {:.2}% (lit 5-15 degrees), {:.2}% (the forward lobe's far flank)",
        100.0 * worst,
        100.0 * worst_in,
        100.0 * worst_band,
        100.0 * worst_flank
    );
}

/// A thin sheet's forward lobe converges in the nodes where it is lit and
/// seen 20 to 40 degrees from the normal (docs/accuracy.md's weak scatter:
/// `g_f` 0.8, tau 3.05, GGX 0.3 faces; single scattering is most of what
/// moves there): on its ridge (straight through, lit between the nodes)
/// and 4 degrees either side of it, and far off it (seen at 10.5 degrees
/// on the ridge's side), both sides of incidence, 32 nodes against 64.
/// There every order follows the sine law between the nodes
/// (`SIN_LAW_BAND`), which assumes a smooth function's change of shape
/// from node to node; the lobe's orders barely change shape along its
/// ridge. With the whole law at every pair (a probe build with the fit
/// forced to 1; this test at c7c9e90) the ridge's points were 0.37% to
/// 0.45% apart; with each pair's share measured from its neighbours
/// along the diagonal (`Tables::law_exponent` in src/bsdf.rs) 0.10% to
/// 0.27% (asserted 0.3%). Far off the ridge the measured share changes
/// little (0.25-0.34% -> 0.23-0.33%, asserted 0.4%): the largest change
/// left on this sheet, in examples/convergence.rs too (0.34% at 10.5 T
/// -18.5).
#[test]
fn forward_lobe_converges_along_its_ridge() {
    // docs/accuracy.md's weak scatter (this file's `cases` has another).
    let p = PaperParams {
        g_b: -0.3,
        ..sheet(
            0.1,
            0.5,
            30.0,
            [(1.5, 0.3, Distribution::Ggx), (1.5, 0.3, Distribution::Ggx)],
            FaceScattering::Multiple,
        )
    };
    let (b0, b1) = support::default_and_doubled_nodes(&p);
    let (mut ridge, mut far) = (0.0f64, 0.0f64);
    for side in [1.0, -1.0] {
        for ti in [22.5, 26.0, 30.0, 34.0] {
            for to in [ti - 4.0, ti, ti + 4.0, 10.5] {
                let (wi, wo) = (dir(ti, PI, side), dir(to, 0.0, -side));
                let (x, y) = (b0.eval(wi, wo).mean(), b1.eval(wi, wo).mean());
                let e = (x / y - 1.0).abs();
                let (worst, tol) = if to == 10.5 {
                    (&mut far, 0.004)
                } else {
                    (&mut ridge, 0.003)
                };
                *worst = worst.max(e);
                assert!(
                    e < tol,
                    "side {side}, lit at {ti}, seen at {to}: {x} with 32 nodes, {y} with 64"
                );
            }
        }
    }
    eprintln!(
        "forward lobe: 32 against 64 nodes within {:.3}% on and near the ridge, {:.3}% far off it",
        100.0 * ridge,
        100.0 * far
    );
}

/// A face closest to index-matched (eta 1.001, m 0.3), which `slab` cannot
/// project yet (crate::interface `normalise_face`: its raw projection
/// cannot be scaled to the face's albedo, Newton's method stays 3.4e-3
/// off; refused at 1.001 from m 0.1 on, at 1.01 from 0.8, none from
/// 1.02 on), is refused with an error that names the face and points to
/// the model that handles it, not a panic and not a setting nobody can
/// choose. (Until 2026-12-07 this test used eta 1.02, m 0.2, which `slab`
/// now builds.)
#[test]
fn near_index_matched_faces_are_refused_clearly() {
    let p = sheet(
        0.1,
        0.5,
        30.0,
        [(1.001, 0.3, Distribution::Beckmann), (1.001, 0.3, Distribution::Ggx)],
        FaceScattering::Multiple,
    );
    let Err(e) = SlabBsdf::new(&p) else {
        panic!("eta 1.001 was not refused");
    };
    let e = e.to_string();
    for part in ["index 1.001", "beckmann, m = 0.3", "model `paper`"] {
        assert!(e.contains(part), "the error does not say {part:?}: {e}");
    }
}
