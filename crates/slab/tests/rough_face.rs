//! (a) A rough face alone: the order-0 albedo of its projected matrices from
//! each side against core's quadrature of the same face, and energy
//! conservation of the compensated (`"multiple"`) face; (b) reciprocity of
//! the projected matrices, with the `eta^2` of generalised reciprocity, in
//! every order.
//!
//! Reference: `paperbsdf_core::boundary::directional_albedo_n` (Walter's
//! `R` and `T` by a 128 x 128 Gauss-Legendre rule in the square of visible
//! normals; it converges slowly itself, within 4e-4 of its 256-point rule for
//! m <= 0.5 and 1.2e-3 at m = 1, measured), made the albedo of
//! `RoughDielectric::eval_mode` for Beckmann (`interface::walter_albedo`:
//! core's rule holds the exact Smith `G1` of the incident direction,
//! `eval_mode` Walter's rational one; checked against `eval_mode`'s own
//! sampled albedo by `normalisation_targets_are_walters_own_albedo`), from
//! outside at each outside node and from inside at each inside node.
//!
//! The projection's error is that of the grids' quadrature in `mu` of a lobe
//! (the azimuth rule is converged: tests/rough_convergence.rs): the
//! refraction lobe ends with a kink where the microfacet turns its back to a
//! direction, which falls anywhere between nodes (its edge, where GGX's
//! transmission jumps to zero, is integrated over the cells it crosses:
//! `refraction_edge_is_integrated` below). Measured with 32 outside
//! nodes (16 in the cone of total internal reflection), eta = 1.5, largest
//! over the nodes: the raw projection's `R` and `T` are within 3.0e-2 of
//! core's (GGX m = 0.15 at normal incidence, the narrowest lobe; 9.0e-4 for
//! 0.5, 1.2e-2 with the edge sampled at the nodes). Normalised (the solver's default), from
//! inside `R` and `T` are core's each, within 1e-12 (measured 8.9e-13), and
//! from outside their sum is, with the split within 1.1e-3 (GGX m = 0.5;
//! 6.3e-4 at m = 0.15; 2.2e-3 and 1.3e-3 with the edge sampled). Until 2026-12-05 one factor per node made only the
//! sums core's, with the split within 1.0e-3 from outside and 5.1e-3 from
//! inside (GGX m = 0.5) and, for faces smoother than the nodes, far worse
//! (GGX m = 0.01 kept 0.2% of its 4% reflection from inside near the
//! normal); the split from outside takes the rest now, which the `slab`
//! model does not use: it replaces the lit face's reflection by the
//! analytic lobe and rescales what crosses the face to the transmittance
//! that lobe leaves (crates/slab/src/interface.rs, `normalise_face`).
//! Asked: raw 4e-2; normalised 1e-9 from inside and 3e-3 from outside.
//!
//! With `"multiple"` faces every node's `R + T` is 1 within 1e-12 (the
//! normalisation's tolerance; measured 9e-13), far inside issue 14's 2e-3,
//! and the transmitted shares of the multiply scattered light, which the
//! discretised walk decides (`paperbsdf_slab::face_walk`), agree with those
//! of core's Monte Carlo tables of the same walk
//! (`PaperBsdf::face_compensation`): `k_o` within 0.01, `k_i` within 2%.

mod support;

use nalgebra::DMatrix;
use paperbsdf_core::boundary::{dir_at_mu, directional_albedo_n};
use paperbsdf_core::quadrature::gauss_legendre_01;
use paperbsdf_core::{DVec3, TransportMode};
use paperbsdf_core::{Distribution, FaceScattering, RoughDielectric};
use paperbsdf_slab::interface::{face_interface, walter_albedo, Projection};
use paperbsdf_slab::{Grid, Layer};
use support::layer_asymmetry;

/// `sum_o w_o mu_o K[o][j] / (w_j mu_j)`.
fn albedo(k: &DMatrix<f64>, to: &Grid, from: &Grid, j: usize) -> f64 {
    (0..to.len()).map(|o| to.w[o] * to.mu[o] * k[(o, j)]).sum::<f64>() / (from.w[j] * from.mu[j])
}

fn grids(eta: f64, nodes: usize) -> (Grid, Grid) {
    let out = Grid::outside(nodes);
    let ins = Grid::inside(&out, eta, nodes / 2);
    (out, ins)
}

/// Walter's face's `(R, T)` as `eval_mode` has it (`walter_albedo` on core's
/// rule) from outside at the outside nodes and from inside at the inside nodes.
type References = (Vec<(f64, f64)>, Vec<(f64, f64)>);

fn references(bd: &RoughDielectric, out: &Grid, ins: &Grid) -> References {
    let rule = gauss_legendre_01(REFERENCE_POINTS);
    let at = |g: &Grid, side: f64| -> Vec<(f64, f64)> {
        g.mu.iter()
            .map(|&mu| walter_albedo(bd, dir_at_mu(mu, side), &rule))
            .collect()
    };
    (at(out, 1.0), at(ins, -1.0))
}

/// Points per axis of core's rule for the references (as the normalisation's targets,
/// [`paperbsdf_slab::interface::ALBEDO_POINTS`]; within 4e-4 of the 256-point rule for m <= 0.5).
const REFERENCE_POINTS: usize = 128;

/// Largest `|R - R_core|`, `|T - T_core|` over the nodes from outside and from inside.
fn albedo_errors(refs: &References, l: &Layer, out: &Grid, ins: &Grid) -> (f64, f64) {
    let (mut e_out, mut e_in): (f64, f64) = (0.0, 0.0);
    for (j, (r, t)) in refs.0.iter().enumerate() {
        let (rp, tp) = (albedo(&l.r_top, out, out, j), albedo(&l.t_down, ins, out, j));
        e_out = e_out.max((rp - r).abs()).max((tp - t).abs());
    }
    for (j, (r, t)) in refs.1.iter().enumerate() {
        let (rp, tp) = (albedo(&l.r_bot, ins, ins, j), albedo(&l.t_up, out, ins, j));
        e_in = e_in.max((rp - r).abs()).max((tp - t).abs());
    }
    (e_out, e_in)
}

#[test]
fn single_face_albedo_matches_cores_quadrature() {
    let (out, ins) = grids(1.5, 32);
    // GGX m = 0.3 and Beckmann m = 0.15 measured as well (module doc), left out for time
    for (dist, m) in [
        (Distribution::Ggx, 0.15),
        (Distribution::Ggx, 0.5),
        (Distribution::Beckmann, 0.3),
    ] {
        let bd = RoughDielectric::new(dist, 1.5, m).unwrap();
        let refs = references(&bd, &out, &ins);
        let raw = face_interface(&bd, FaceScattering::Single, &out, &ins, &proj_raw(1, 8)).unwrap();
        let (r_out, r_in) = albedo_errors(&refs, &raw.orders[0], &out, &ins);
        let face = face_interface(&bd, FaceScattering::Single, &out, &ins, &proj(1, 8)).unwrap();
        let (e_out, e_in) = albedo_errors(&refs, &face.orders[0], &out, &ins);
        let s_dev = face.scale.iter().map(|s| (s - 1.0).abs()).fold(0.0, f64::max);
        println!(
            "{dist:?} m = {m}: largest |albedo - core|, raw projection: from outside {r_out:.1e}, from inside {r_in:.1e}; normalised (largest |s - 1| {s_dev:.1e}): {e_out:.1e}, {e_in:.1e}"
        );
        assert!(r_out < 0.04 && r_in < 0.04, "{dist:?} m={m}: {r_out} {r_in}");
        assert!(e_out < 3e-3 && e_in < 1e-9, "{dist:?} m={m}: {e_out} {e_in}");
    }
}

/// The normalisation's targets (`interface::walter_albedo`) are the
/// albedo of the face that `eval` and the simulator have,
/// `RoughDielectric::eval_mode`: against the mean weight `f |cos| / pdf` of
/// its own sampling (`sample_mode`, 1M quasi-random draws; transmission
/// times `eta_rel^2`, the radiance factor, for the flux), from outside and
/// from inside, near the normal and at grazing incidence, for Beckmann
/// faces (smooth and near index-matched, paper-like) and a GGX one.
/// Tolerance 3e-4: the sampled mean's own error (on the GGX face, where
/// core's quadrature is `eval_mode`'s albedo already, it is up to 1.2e-4
/// here, from inside at 30 degrees; the Beckmann faces agree within
/// 8e-5). Core's albedo alone (exact `G1` of the incident
/// direction) is 2.9e-3 from it for Beckmann `eta` 1.1, `m` 0.05 at 86.1
/// degrees, which the last assertion checks, so the test sees the
/// difference it is about.
#[test]
fn normalisation_targets_are_walters_own_albedo() {
    let rule = gauss_legendre_01(REFERENCE_POINTS);
    let draws = 1_000_000u64;
    let sampled = |bd: &RoughDielectric, w: DVec3| -> (f64, f64) {
        let eta_rel = if w.z > 0.0 { bd.eta } else { 1.0 / bd.eta };
        let (mut r, mut t) = (0.0, 0.0);
        for k in 0..draws {
            let u0 = (k as f64 + 0.5) / draws as f64;
            let u1 = (0.5 + k as f64 * 0.618_033_988_749_894_9).fract();
            let uc = (0.5 + k as f64 * 0.754_877_666_246_692_7).fract();
            if let Some(s) = bd.sample_mode(w, uc, [u0, u1], TransportMode::Radiance) {
                let v = s.f.0[0] * s.wi.z.abs() / s.pdf;
                if s.wi.z * w.z > 0.0 {
                    r += v;
                } else {
                    t += v * eta_rel * eta_rel;
                }
            }
        }
        (r / draws as f64, t / draws as f64)
    };
    let mut worst: f64 = 0.0;
    for (dist, eta, m) in [
        (Distribution::Beckmann, 1.1, 0.05),
        (Distribution::Beckmann, 1.5, 0.1),
        (Distribution::Beckmann, 1.5, 0.3),
        (Distribution::Ggx, 1.5, 0.15),
    ] {
        let bd = RoughDielectric::new(dist, eta, m).unwrap();
        for (deg, side) in [(0.0f64, 1.0), (60.0, 1.0), (86.1, 1.0), (30.0, -1.0), (60.0, -1.0)] {
            let w = dir_at_mu(deg.to_radians().cos(), side);
            let (r, t) = walter_albedo(&bd, w, &rule);
            let (rs, ts) = sampled(&bd, w);
            let e = (r - rs).abs().max((t - ts).abs());
            println!(
                "{dist:?} eta {eta} m {m}, {deg} degrees ({}): targets R {r:.5} T {t:.5}, sampled R {rs:.5} T {ts:.5}",
                if side > 0.0 { "outside" } else { "inside" }
            );
            worst = worst.max(e);
            assert!(e < 3e-4, "{dist:?} eta {eta} m {m} at {deg} ({side}): {e:e}");
        }
    }
    println!("largest |target - sampled| {worst:.1e}");
    let bd = RoughDielectric::new(Distribution::Beckmann, 1.1, 0.05).unwrap();
    let w = dir_at_mu(86.1f64.to_radians().cos(), 1.0);
    let (r, t) = directional_albedo_n(&bd, w, REFERENCE_POINTS);
    let (rs, ts) = sampled(&bd, w);
    assert!(
        (rs + ts) - (r + t) > 1e-3,
        "core's albedo is not apart from eval_mode's here: {} against {}",
        r + t,
        rs + ts
    );
}

/// Faces close to index-matched that the normalisation left short of its
/// targets until Newton's method took over from its square-root iteration
/// (2026-12-07; crates/slab/src/interface.rs, `newton_scaling`): GGX `eta`
/// 1.05 with `m` 1.3 (a corner of the fit's bounds, 2.2e-6 off after
/// 20,000 iterations), 1.03 with 0.3, Beckmann 1.1 with 0.05. Each is
/// built, and its normalised albedos are the face's as for any face (the
/// references above, `walter_albedo`): from inside `R` and `T` each, from
/// outside `R + T` (the normalisation's own rule, so to its tolerance,
/// asked 1e-9).
#[test]
fn near_index_faces_are_normalised_to_their_albedo() {
    for (dist, eta, m) in [
        (Distribution::Ggx, 1.05, 1.3),
        (Distribution::Ggx, 1.03, 0.3),
        (Distribution::Beckmann, 1.1, 0.05),
    ] {
        let (out, ins) = grids(eta, 32);
        let bd = RoughDielectric::new(dist, eta, m).unwrap();
        let refs = references(&bd, &out, &ins);
        let face = face_interface(&bd, FaceScattering::Single, &out, &ins, &proj(1, 8))
            .unwrap_or_else(|e| panic!("{dist:?} eta {eta} m {m}: {e}"));
        let l = &face.orders[0];
        let mut worst: f64 = 0.0;
        for (j, (r, t)) in refs.0.iter().enumerate() {
            let sum = albedo(&l.r_top, &out, &out, j) + albedo(&l.t_down, &ins, &out, j);
            worst = worst.max((sum - (r + t)).abs());
        }
        for (j, (r, t)) in refs.1.iter().enumerate() {
            let (rp, tp) = (albedo(&l.r_bot, &ins, &ins, j), albedo(&l.t_up, &out, &ins, j));
            worst = worst.max((rp - r).abs()).max((tp - t).abs());
        }
        println!("{dist:?} eta {eta} m {m}: largest |albedo - reference| {worst:.1e}");
        assert!(worst < 1e-9, "{dist:?} eta {eta} m {m}: {worst:e}");
    }
}

#[test]
fn multiple_face_conserves_energy_and_keeps_cores_shares() {
    let (out, ins) = grids(1.5, 32);
    for (dist, m) in [
        (Distribution::Ggx, 0.15),
        (Distribution::Ggx, 0.5),
        (Distribution::Beckmann, 0.3),
    ] {
        {
            let bd = RoughDielectric::new(dist, 1.5, m).unwrap();
            let face = face_interface(&bd, FaceScattering::Multiple, &out, &ins, &proj(1, 8)).unwrap();
            let l = &face.orders[0];
            let c = face.compensation.as_ref().unwrap();
            let mut worst: f64 = 0.0;
            for j in 0..out.len() {
                let s = albedo(&l.r_top, &out, &out, j) + albedo(&l.t_down, &ins, &out, j);
                worst = worst.max((s - 1.0).abs());
            }
            for j in 0..ins.len() {
                let s = albedo(&l.r_bot, &ins, &ins, j) + albedo(&l.t_up, &out, &ins, j);
                worst = worst.max((s - 1.0).abs());
            }
            // core's shares for the same face (its tables' Lbar in place of the grid's)
            let params = paperbsdf_core::PaperParams {
                eta_f: 1.5,
                eta_b: 1.5,
                m_f: m,
                m_b: m,
                dist_f: dist,
                dist_b: dist,
                face_scattering: FaceScattering::Multiple,
                ..paperbsdf_core::presets::matte_office()
            };
            let model = paperbsdf_core::PaperBsdf::new(&params).unwrap();
            let (k_o, k_i) = model.face_compensation(paperbsdf_core::paper::Side::Front);
            println!(
                "{dist:?} m = {m}: |R + T - 1| <= {worst:.1e}, clipped {:.1e}; Lbar_o {:.4}, Lbar_i {:.4}; k_o {:.4} (core {k_o:.4}), k_i {:.4} (core {k_i:.4})",
                c.clipped, c.lbar_out, c.lbar_in, c.k_out, c.k_in
            );
            assert!(worst < 1e-11, "{worst}");
            // The split of the walk's light between R and T comes from the
            // discretised walk here and from core's Monte Carlo tables there:
            // two independent computations of one quantity.
            assert!(
                (c.k_out - k_o).abs() < 0.01 && (c.k_in - k_i).abs() < 0.02 * k_i.max(0.01),
                "{dist:?} m = {m}: k_o {} vs {k_o}, k_i {} vs {k_i}",
                c.k_out,
                c.k_in
            );
        }
    }
}

#[test]
fn projected_faces_are_reciprocal_in_every_order() {
    let (out, ins) = grids(1.5, 20);
    let mut worst: f64 = 0.0;
    for dist in [Distribution::Ggx, Distribution::Beckmann] {
        for fs in [FaceScattering::Single, FaceScattering::Multiple] {
            for m in [0.1, 0.4] {
                let bd = RoughDielectric::new(dist, 1.5, m).unwrap();
                let face = face_interface(&bd, fs, &out, &ins, &proj(12, 8)).unwrap();
                for l in &face.orders {
                    worst = worst.max(layer_asymmetry(l, &out, &ins));
                }
            }
        }
    }
    println!("worst relative asymmetry of the projected faces (12 orders): {worst:.2e}");
    assert!(worst < 1e-10, "{worst}");
}

fn proj(orders: usize, azimuth_points: usize) -> Projection {
    Projection {
        orders,
        azimuth_points,
        normalise: true,
        walk_orders: 0,
    }
}

fn proj_raw(orders: usize, azimuth_points: usize) -> Projection {
    Projection {
        normalise: false,
        walk_orders: 0,
        ..proj(orders, azimuth_points)
    }
}

/// The refraction edge (crates/slab/src/interface.rs, `transmission_cell_averages`):
/// light from outside at `mu_out` refracts through a GGX face only into
/// inside directions with `eta mu_in > mu_out`, where Walter's transmission
/// jumps from `D` of a horizontal micro-normal to zero. First the premise,
/// on the face itself at several azimuths: zero just short of the edge,
/// positive just beyond it in the forward azimuths (within 0.5 rad). Then the raw projection (no normalisation) of
/// the roughest faces, where the jump is largest (GGX m = 0.9 and 0.5 at
/// eta = 1.5, where the edge lies in the cone of total internal reflection,
/// and m = 0.9 at eta = 1.33, below sqrt 2, where it reaches beyond it:
/// until the pairs beyond the cone were integrated too, the same day, the
/// transmission from inside was off by 5.7e-3 there), against core's
/// quadrature with 512 points per axis (the reference must be better than
/// the 128 points of the normalisation's targets: 1.2e-3 at m = 1): the
/// transmission from every outside node and from every inside node.
/// Sampled at the nodes, as until 2026-12-05, it was off by up to 1.9e-2
/// from outside (m = 0.9; 1.2e-2 at 0.5) and 8e-3 from inside, alternating
/// from node to node, and the normalisation's factors, which made up for
/// it, alternated as much (neighbouring outside factors up to 3.8% apart at
/// m = 0.9), so the sheets' BSDF at grazing angles moved by up to 1.1% when
/// the nodes were doubled (very rough, examples/convergence.rs). Measured
/// now: 1.1e-3 and 1.3e-3 (m = 0.9), 5.3e-4 and 8.5e-4 (m = 0.5), 1.5e-3
/// and 1.6e-3 (eta 1.33), steps of 2.0e-3, 9.9e-4 and 3.5e-3. Asked: the
/// transmission within
/// 3e-3 and neighbouring outside factors within 1% of each other.
#[test]
fn refraction_edge_is_integrated() {
    use paperbsdf_core::{DVec3, TransportMode};
    for (eta, m) in [(1.5, 0.9), (1.5, 0.5), (1.33, 0.9)] {
        let (out, ins) = grids(eta, 32);
        let bd = RoughDielectric::new(Distribution::Ggx, eta, m).unwrap();
        for mu_out in [0.1, 0.3, 0.6, 0.95] {
            let wi = DVec3::new(-(1.0f64 - mu_out * mu_out).sqrt(), 0.0, mu_out);
            for phi in [0.0f64, 0.5, 1.5, 3.0] {
                let at = |mu_in: f64| {
                    let s = (1.0 - mu_in * mu_in).sqrt();
                    bd.eval_mode(
                        wi,
                        DVec3::new(s * phi.cos(), s * phi.sin(), -mu_in),
                        TransportMode::Radiance,
                    )
                };
                let edge = mu_out / eta;
                assert_eq!(
                    at(edge * (1.0 - 1e-6)),
                    0.0,
                    "m {m}: short of the edge at mu_out {mu_out}, phi {phi}"
                );
                // Beyond it the micro-normal must also face both directions,
                // which near the edge holds within about 0.8 of forward.
                if phi < 0.6 {
                    assert!(
                        at(edge * (1.0 + 1e-6)) > 0.0,
                        "m {m}: beyond the edge at mu_out {mu_out}, phi {phi}"
                    );
                }
            }
        }
        let at = |g: &Grid, side: f64| -> Vec<(f64, f64)> {
            g.mu.iter()
                .map(|&mu| directional_albedo_n(&bd, dir_at_mu(mu, side), 512))
                .collect()
        };
        let (ref_out, ref_in) = (at(&out, 1.0), at(&ins, -1.0));
        let raw = face_interface(&bd, FaceScattering::Single, &out, &ins, &proj_raw(1, 8)).unwrap();
        let l = &raw.orders[0];
        let e_out = (0..out.len())
            .map(|j| (albedo(&l.t_down, &ins, &out, j) - ref_out[j].1).abs())
            .fold(0.0, f64::max);
        let e_in = (0..ins.len())
            .map(|j| (albedo(&l.t_up, &out, &ins, j) - ref_in[j].1).abs())
            .fold(0.0, f64::max);
        let face = face_interface(&bd, FaceScattering::Single, &out, &ins, &proj(1, 8)).unwrap();
        let jump = face.scale[..out.len()]
            .windows(2)
            .map(|s| (s[1] / s[0] - 1.0).abs())
            .fold(0.0, f64::max);
        println!("GGX m = {m}, eta {eta}: raw T within {e_out:.1e} from outside, {e_in:.1e} from inside; outside factors' largest step {jump:.1e}");
        assert!(e_out < 3e-3 && e_in < 3e-3, "m {m}: {e_out} {e_in}");
        assert!(jump < 1e-2, "m {m}: {jump}");
    }
}
