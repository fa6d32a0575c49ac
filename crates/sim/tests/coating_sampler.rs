//! Chi-square test of the sampler of a rough front over a coating
//! (`paperbsdf_sim::faces::StochFace::sample`: the sub-walk between the rough
//! air/coating interface and the smooth coating/base interface) against the
//! independent path estimate of the same face's BSDF (`StochFace::eval`, which
//! walks from the other end and connects by the top interface's value).
//!
//! The top interface is Walter's (`face_scattering = "single"`), whose value is
//! exact, so the only randomness of the estimate is the coating's paths. The
//! sampler's draws carry weights (Walter's face loses the shadowed light), so
//! the observed value of a bin is the sum of the weights of its draws, with
//! variance estimated by the sum of their squares; in importance transport
//! the expected value is `n * integral_bin eval(w, w_from, Importance) |cos w| dw`
//! (the delta part, the coating/base mirror reflection of light from the base,
//! carries `n F`). Directions are binned over both hemispheres (uniform in
//! `cos^2 theta` and azimuth); the expected value of each bin is a stratified
//! integral of the eval estimate, whose own variance is added. The statistic
//! `sum (O - E)^2 / (var O + var E)` over `k` bins is chi-square with about `k`
//! degrees of freedom; it must stay below `k + 5 sqrt(2 k)` (5 sigma of the
//! chi-square's normal approximation).
//!
//! With the multiple-scattering top (every weight 1) the comparison needs many
//! more evaluations per bin: the microsurface walk's estimate of the BSDF value
//! is heavy-tailed in some bins, so with a few hundred its sample means mostly
//! fall short and its sample variances understate the error (chi-square 3 to
//! 10 times the limit with 400 per bin, within it with 20000).

use paperbsdf_core::params::FaceScattering;
use paperbsdf_core::{DVec3, Distribution, RoughDielectric, TransportMode};
use paperbsdf_sim::faces::FaceOptics;
use rand::{Rng, SeedableRng};
use std::f64::consts::PI;

const N_COS: usize = 8;
const N_PHI: usize = 8;

/// Bin of a direction: hemisphere (0 up, 1 down), `cos^2` band, azimuth sector.
fn bin(w: DVec3) -> usize {
    let h = (w.z < 0.0) as usize;
    let c2 = (w.z * w.z).min(1.0 - 1e-15);
    let i = (c2 * N_COS as f64) as usize;
    let phi = w.y.atan2(w.x) + PI;
    let j = ((phi / (2.0 * PI) * N_PHI as f64) as usize).min(N_PHI - 1);
    (h * N_COS + i) * N_PHI + j
}

fn chi_square(eta_f: f64, eta_b: f64, m: f64, dist: Distribution, w_from: DVec3, seed: u64) {
    chi_square_with(eta_f, eta_b, m, dist, FaceScattering::Single, 2000, w_from, seed);
}

/// The test with the given faces and evaluations of the estimate per bin.
#[allow(clippy::too_many_arguments)]
fn chi_square_with(
    eta_f: f64,
    eta_b: f64,
    m: f64,
    dist: Distribution,
    fs: FaceScattering,
    per: usize,
    w_from: DVec3,
    seed: u64,
) {
    let top = RoughDielectric::new(dist, eta_f, m).unwrap();
    let coat = (eta_f != eta_b).then_some(eta_b / eta_f);
    let FaceOptics::Stochastic(face) = FaceOptics::new(top, fs, coat) else {
        panic!("a rough coated front is stochastic")
    };
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
    let n_bins = 2 * N_COS * N_PHI;
    let n = 400_000usize;
    let mut observed = vec![0.0; n_bins];
    let mut var_o = vec![0.0; n_bins];
    let mut delta = 0.0;
    for _ in 0..n {
        let mut rnd = || rng.gen::<f64>();
        let Some(s) = face.sample(w_from, TransportMode::Importance, &mut rnd) else {
            continue; // shadowed: lost
        };
        // A visible-normal draw of Walter's face carries G1 <= 1; Beckmann's
        // rational G1 (Walter 2007) overshoots 1 by up to about 2e-5.
        // (products over the coating's bounces: up to about 1e-3 here).
        assert!(s.weight > 0.0 && s.weight <= 1.0 + 1e-2, "weight {}", s.weight);
        if s.delta {
            assert_eq!(s.weight, 1.0);
            delta += 1.0;
        } else {
            observed[bin(s.dir)] += s.weight;
            var_o[bin(s.dir)] += s.weight * s.weight;
        }
    }
    // Expected counts: stratified points in each bin (solid angle dw = d(cos) dphi,
    // with cos = sqrt(c2): dw = dc2 / (2 cos) dphi, so f |cos| dw = f dc2 dphi / 2).
    let mut expected = vec![0.0; n_bins];
    let mut var_e = vec![0.0; n_bins];
    for h in 0..2 {
        for i in 0..N_COS {
            for j in 0..N_PHI {
                let (mut s1, mut s2) = (0.0, 0.0);
                for k in 0..per {
                    let c2 = (i as f64 + (k as f64 + rng.gen::<f64>()) / per as f64) / N_COS as f64;
                    let phi = (j as f64 + rng.gen::<f64>()) / N_PHI as f64 * 2.0 * PI - PI;
                    let (c, s) = (c2.sqrt(), (1.0 - c2).max(0.0).sqrt());
                    let w = DVec3::new(s * phi.cos(), s * phi.sin(), if h == 0 { c } else { -c });
                    let mut rnd = || rng.gen::<f64>();
                    let v = face.eval(w, w_from, TransportMode::Importance, &mut rnd) * 0.5;
                    s1 += v;
                    s2 += v * v;
                }
                let vol = (1.0 / N_COS as f64) * (2.0 * PI / N_PHI as f64);
                let mean = s1 / per as f64;
                let var = (s2 / per as f64 - mean * mean).max(0.0) / per as f64;
                let b = (h * N_COS + i) * N_PHI + j;
                expected[b] = n as f64 * mean * vol;
                var_e[b] = (n as f64 * vol).powi(2) * var;
            }
        }
    }
    // The delta lobe's probability is the coating/base Fresnel reflectance.
    let f_delta = if w_from.z < 0.0 {
        paperbsdf_core::fresnel::fresnel_dielectric(w_from.z, eta_b / eta_f)
    } else {
        0.0
    };
    // Pool bins with fewer than 20 expected draws.
    let (mut chi2, mut k) = (0.0, 0usize);
    let (mut po, mut pe, mut pv) = (0.0, 0.0, 0.0);
    for b in 0..n_bins {
        if expected[b] < 20.0 {
            po += observed[b];
            pe += expected[b];
            pv += var_e[b] + var_o[b];
            continue;
        }
        chi2 += (observed[b] - expected[b]).powi(2) / (var_o[b] + var_e[b]);
        k += 1;
    }
    if pe > 5.0 {
        chi2 += (po - pe).powi(2) / pv.max(1.0);
        k += 1;
    }
    let de = n as f64 * f_delta;
    if de > 5.0 {
        chi2 += (delta - de).powi(2) / de;
        k += 1;
    }
    let total_e: f64 = expected.iter().sum::<f64>() + de;
    let total_o: f64 = observed.iter().sum::<f64>() + delta;
    let se_total = (var_e.iter().sum::<f64>() + var_o.iter().sum::<f64>()).sqrt();
    let half = N_COS * N_PHI;
    eprintln!(
        "  totals: (O - E) / se = {:.2}; up O {:.4} E {:.4}, down O {:.4} E {:.4}",
        (total_o - total_e) / se_total,
        observed[..half].iter().sum::<f64>() / n as f64,
        expected[..half].iter().sum::<f64>() / n as f64,
        observed[half..].iter().sum::<f64>() / n as f64,
        expected[half..].iter().sum::<f64>() / n as f64
    );
    assert!(
        (total_o - total_e).abs() < 5.0 * se_total,
        "totals {total_o} vs {total_e} (se {se_total})"
    );
    let limit = k as f64 + 5.0 * (2.0 * k as f64).sqrt();
    eprintln!(
        "coating {eta_f} over {eta_b}, m {m} {dist:?}, from {w_from:?}: chi2 {chi2:.1} over {k} bins (limit {limit:.1}); expected total {:.4}, observed {:.4}",
        total_e / n as f64,
        (observed.iter().sum::<f64>() + delta) / n as f64
    );
    assert!(chi2 < limit, "chi2 {chi2} over {k} bins");
    // A single-scattering face loses energy, never gains.
    assert!(total_e / n as f64 <= 1.0 + 0.01, "total {}", total_e / n as f64);
}

#[test]
fn coating_sampler_matches_its_path_estimate() {
    let from_air = DVec3::new(0.5, 0.0, 0.75f64.sqrt());
    let from_base = DVec3::new(0.3, 0.1, -(0.9f64).sqrt());
    // A rough coating of higher and of lower index than the base, lit from each side.
    chi_square(1.8, 1.3, 0.5, Distribution::Ggx, from_air, 1);
    chi_square(1.8, 1.3, 0.5, Distribution::Ggx, from_base, 2);
    chi_square(1.3, 2.0, 0.7, Distribution::Beckmann, from_air, 3);
    chi_square(1.3, 2.0, 0.7, Distribution::Beckmann, from_base, 4);
}

#[test]
fn coating_sampler_with_multiple_scattering_top() {
    let from_base = DVec3::new(0.3, 0.1, -(0.9f64).sqrt());
    chi_square_with(
        1.8,
        1.3,
        0.5,
        Distribution::Ggx,
        FaceScattering::Multiple,
        20_000,
        from_base,
        21,
    );
}
