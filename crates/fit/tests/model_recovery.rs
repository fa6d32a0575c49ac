//! Recovery: in-plane data made by each real model (paper, reduced-multilayer,
//! lambert-glass from paperbsdf-core) from random parameters inside the search
//! box are fitted back to an RMS log error below 1e-3, starting from the
//! default start plus the global stage. To keep the test fast the microfacet
//! distributions are given (the variant is not searched); every continuous
//! parameter is free except in `paper_recovers_medium_with_faces_given`. The
//! data are two incident angles, theta_o in steps of 20 degrees, reflection
//! and transmission (36 points).

use paperbsdf_core::geometry::in_plane_directions;
use paperbsdf_core::Distribution;
use paperbsdf_fit::models::candidates;
use paperbsdf_fit::{fit, parse_measurement, ComponentModel, FitModel, FitOptions, Point, Subset};
use rand::{Rng, SeedableRng};

fn synthetic(model: &dyn ComponentModel) -> Vec<Point> {
    let mut text = String::from("kind,theta_i_deg,theta_o_deg,f\n");
    for ti in [0.0, 45.0] {
        for k in ["R", "T"] {
            for to in (-80..=80).step_by(20) {
                let (wi, wo) = in_plane_directions(ti, to as f64, k == "T");
                text += &format!("{k},{ti},{to},{:.17e}\n", model.eval(wi, wo).0[0]);
            }
        }
    }
    parse_measurement(&text, "synthetic").unwrap().points
}

fn recover(name: &str, dists: &[Distribution], seed: u64, trials: usize) {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    for trial in 0..trials {
        let cands: Vec<Box<dyn FitModel>> = candidates(name, Some(0.15), false, Some(dists)).unwrap();
        let truth_model = &cands[0];
        let u: Vec<f64> = (0..truth_model.specs().len())
            .map(|_| rng.gen_range(0.2..0.8))
            .collect();
        let x = truth_model.values(&u);
        let truth = truth_model.build(&x).unwrap();
        let pts = synthetic(truth.as_ref());
        let mut opts = FitOptions::default();
        if let Ok(b) = std::env::var("BROYDEN") {
            opts.lm.broyden_steps = b.parse().unwrap();
        }
        let out = fit(&pts, 1, &cands, &opts).unwrap();
        assert!(
            out.rms_log_error < 1e-3,
            "{name} trial {trial}: truth {}, fitted {} rms {}",
            truth_model.params_json(&x),
            out.params,
            out.rms_log_error
        );
    }
}

#[test]
fn paper_recovers_medium_with_faces_given() {
    // Fewer free parameters (the five of the medium; the faces are given), a
    // smaller global stage. The all-free cases are `paper_recovers_beckmann`
    // and `paper_recovers_all_free_ggx` below.
    let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
    for trial in 0..2 {
        let truth_model = &candidates("paper", Some(0.15), false, Some(&[Distribution::Ggx])).unwrap()[0];
        let u: Vec<f64> = (0..truth_model.specs().len())
            .map(|_| rng.gen_range(0.2..0.8))
            .collect();
        let x = truth_model.values(&u);
        let truth = truth_model.build(&x).unwrap();
        let pts = synthetic(truth.as_ref());
        let inner = candidates("paper", Some(0.15), false, Some(&[Distribution::Ggx]))
            .unwrap()
            .remove(0);
        let sub = Subset::new(inner, &["sigma_a", "sigma_s", "g_f", "g_b", "w_b"], x.clone()).unwrap();
        let cands: Vec<Box<dyn FitModel>> = vec![Box::new(sub)];
        let out = fit(
            &pts,
            1,
            &cands,
            &FitOptions {
                global_samples: 32,
                local_starts: 6,
                ..Default::default()
            },
        )
        .unwrap();
        assert!(
            out.rms_log_error < 1e-3,
            "paper trial {trial}: truth {}, fitted {} rms {}",
            truth_model.params_json(&x),
            out.params,
            out.rms_log_error
        );
    }
}

#[test]
fn paper_recovers_beckmann() {
    // All nine continuous parameters free.
    recover("paper", &[Distribution::Beckmann], 12, 3);
}

#[test]
fn reduced_multilayer_recovers() {
    recover("reduced-multilayer", &[Distribution::Ggx], 13, 2);
}

#[test]
fn lambert_glass_recovers() {
    recover("lambert-glass", &[Distribution::Ggx], 14, 3);
    recover("lambert-glass", &[Distribution::Beckmann], 15, 2);
}

#[test]
fn paper_needs_thickness() {
    let e = candidates("paper", None, false, None).err().unwrap().to_string();
    assert!(e.contains("--thickness"), "{e}");
    let e = candidates("papr", Some(0.1), false, None).err().unwrap().to_string();
    assert!(e.contains("unknown model `papr`"), "{e}");
}

/// All nine parameters free, GGX faces. Trial 0 of seed 11 (truth: a fairly
/// smooth back face, m_b = 0.14, weakly scattering medium, albedo 0.88) used to
/// end in a local minimum at RMS 0.0066 (m_b = 0.58, a different phase
/// function) that every start of the global stage fell into, even with 48
/// samples and 16 starts; the basin hopping stage after the local refinement
/// (`FitOptions::hop_rounds`) gets out of it.
#[test]
fn paper_recovers_all_free_ggx() {
    recover("paper", &[Distribution::Ggx], 11, 4);
}
