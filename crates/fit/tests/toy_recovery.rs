//! The optimiser on a toy model defined here (Lambertian reflection and
//! transmission plus a Walter rough dielectric from paperbsdf-core): data made
//! by the toy from random parameters are fitted back to an RMS log error below
//! 1e-3 from the default start, and the bounds, extrapolation split and
//! non-convergence report behave as documented.

use paperbsdf_core::{Bsdf, BsdfFlags, BsdfSample, Component, DVec3, Distribution, Rgb, RoughDielectric};
use paperbsdf_fit::*;
use rand::{Rng, SeedableRng};

struct Toy {
    specs: Vec<ParamSpec>,
    dist: Distribution,
}

struct ToyModel {
    k_d: f64,
    k_t: f64,
    glass: RoughDielectric,
}

/// The fitter only evaluates models, so the toy does not sample.
impl Bsdf for ToyModel {
    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        self.eval_component(wi, wo, Component::Multiple) + self.eval_component(wi, wo, Component::Surface)
    }
    fn sample(&self, _wo: DVec3, _uc: f64, _u: [f64; 2]) -> Option<BsdfSample> {
        None
    }
    fn pdf(&self, _wi: DVec3, _wo: DVec3) -> f64 {
        0.0
    }
    fn flags(&self) -> BsdfFlags {
        BsdfFlags::REFLECTION | BsdfFlags::TRANSMISSION | BsdfFlags::DIFFUSE | BsdfFlags::GLOSSY
    }
}

/// `lambert` is the `Multiple` component, `rough glass` the `Surface` one.
impl ComponentModel for ToyModel {
    fn eval_component(&self, wi: DVec3, wo: DVec3, c: Component) -> Rgb {
        match c {
            Component::Multiple => {
                Rgb::splat(if wi.z * wo.z > 0.0 { self.k_d } else { self.k_t } / std::f64::consts::PI)
            }
            Component::Surface => Rgb::splat(self.glass.eval_mode(wi, wo, paperbsdf_core::TransportMode::Radiance)),
            _ => Rgb::ZERO,
        }
    }
    fn is_rgb(&self) -> bool {
        false
    }
    fn components(&self) -> &'static [Component] {
        &[Component::Surface, Component::Multiple]
    }
}

impl Toy {
    fn new(dist: Distribution) -> Self {
        Toy {
            specs: vec![
                ParamSpec::new("k_d", 0.0, 1.0, Scale::Linear, 0.5),
                ParamSpec::new("k_t", 0.0, 1.0, Scale::Linear, 0.3),
                ParamSpec::new("eta", 1.05, 3.0, Scale::Linear, 1.5),
                ParamSpec::new("m", 0.02, 1.0, Scale::Log, 0.2),
            ],
            dist,
        }
    }
}

impl FitModel for Toy {
    fn model_name(&self) -> &str {
        "toy"
    }
    fn variant(&self) -> String {
        format!("dist={}", self.dist.name())
    }
    fn specs(&self) -> &[ParamSpec] {
        &self.specs
    }
    fn build(&self, x: &[f64]) -> Result<Box<dyn ComponentModel>, FitError> {
        let glass = RoughDielectric::new(self.dist, x[2], x[3])?;
        Ok(Box::new(ToyModel {
            k_d: x[0],
            k_t: x[1],
            glass,
        }))
    }
    fn params_json(&self, x: &[f64]) -> serde_json::Value {
        serde_json::json!({"k_d": x[0], "k_t": x[1], "eta": x[2], "m": x[3], "dist": self.dist.name()})
    }
}

fn synthetic(model: &dyn ComponentModel, thetas: &[f64]) -> Vec<Point> {
    let mut text = String::from("kind,theta_i_deg,theta_o_deg,f\n");
    for &ti in thetas {
        for k in ["R", "T"] {
            for to in (-80..=80).step_by(10) {
                let (wi, wo) = paperbsdf_core::geometry::in_plane_directions(ti, to as f64, k == "T");
                text += &format!("{k},{ti},{to},{:.17e}\n", model.eval(wi, wo).0[0]);
            }
        }
    }
    parse_measurement(&text, "synthetic").unwrap().points
}

#[test]
fn recovers_random_parameters() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
    for trial in 0..4 {
        let dist = if trial % 2 == 0 {
            Distribution::Ggx
        } else {
            Distribution::Beckmann
        };
        let truth_model = Toy::new(dist);
        let u: Vec<f64> = (0..4).map(|_| rng.gen_range(0.1..0.9)).collect();
        let truth = truth_model.build(&truth_model.values(&u)).unwrap();
        let pts = synthetic(truth.as_ref(), &[0.0, 45.0]);
        let cands: Vec<Box<dyn FitModel>> = vec![
            Box::new(Toy::new(Distribution::Ggx)),
            Box::new(Toy::new(Distribution::Beckmann)),
        ];
        let opts = FitOptions {
            global_samples: 24,
            local_starts: 3,
            ..Default::default()
        };
        let out = fit(&pts, 1, &cands, &opts).unwrap();
        assert!(
            out.rms_log_error < 1e-3,
            "trial {trial}: truth {:?}, fitted {:?} rms {}",
            truth_model.values(&u),
            out.x,
            out.rms_log_error
        );
        assert_eq!(out.variant, format!("dist={}", dist.name()));
    }
}

#[test]
fn extrapolation_points_are_scored_separately() {
    let t = Toy::new(Distribution::Ggx);
    let truth = t.build(&[0.6, 0.2, 1.4, 0.3]).unwrap();
    let pts = synthetic(truth.as_ref(), &[0.0, 30.0, 60.0]);
    let cands: Vec<Box<dyn FitModel>> = vec![Box::new(Toy::new(Distribution::Ggx))];
    let opts = FitOptions {
        global_samples: 16,
        local_starts: 2,
        fit_theta_i: Some(vec![0.0, 60.0]),
        ..Default::default()
    };
    let out = fit(&pts, 1, &cands, &opts).unwrap();
    assert_eq!(out.counts, (2 * 2 * 17, 2 * 17));
    // Exact model: both scores are (near) zero; the extrapolation group is flagged.
    assert!(out.extrapolation_rms_log_error.unwrap() < 1e-3);
    let g30: Vec<_> = out.per_group.iter().filter(|g| g.theta_i == 30.0).collect();
    assert_eq!(g30.len(), 2);
    assert!(g30.iter().all(|g| g.extrapolation && g.points == 17));
    let json = out.to_json(&["synthetic".into()], opts.fit_theta_i.as_deref());
    assert!(json["extrapolation_rms_log_error"].is_number());
    // No extrapolation points -> null.
    let out = fit(
        &pts,
        1,
        &cands,
        &FitOptions {
            global_samples: 8,
            local_starts: 1,
            ..Default::default()
        },
    )
    .unwrap();
    assert!(out.to_json(&[], None)["extrapolation_rms_log_error"].is_null());
    // A list that matches nothing is an error.
    let e = fit(
        &pts,
        1,
        &cands,
        &FitOptions {
            fit_theta_i: Some(vec![10.0]),
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(e.to_string().contains("no measurement points"), "{e}");
}

#[test]
fn budget_too_small_is_reported_as_not_converged() {
    let t = Toy::new(Distribution::Ggx);
    let truth = t.build(&[0.6, 0.2, 1.4, 0.3]).unwrap();
    let pts = synthetic(truth.as_ref(), &[0.0, 30.0]);
    let cands: Vec<Box<dyn FitModel>> = vec![Box::new(Toy::new(Distribution::Ggx))];
    let mut opts = FitOptions {
        global_samples: 4,
        local_starts: 1,
        ..Default::default()
    };
    opts.lm.max_iter = 1;
    let e = fit(&pts, 1, &cands, &opts).unwrap_err();
    assert!(matches!(e, FitError::NotConverged { .. }), "{e}");
    assert!(e.to_string().contains("did not converge"));
}

#[test]
fn weights_follow_standard_errors() {
    // A model off by a factor 1.1 at one point with a tiny stderr and exact
    // elsewhere: the weighted error is dominated by that point.
    let text = "kind,theta_i_deg,theta_o_deg,f,stderr\nR,0,10,1.0,0.001\nR,0,20,1.0,1.0\n";
    let pts = parse_measurement(text, "w").unwrap().points;
    struct Const;
    impl Bsdf for Const {
        fn eval(&self, _: DVec3, wo: DVec3) -> Rgb {
            Rgb::splat(if wo.x < 0.2 { 1.1 } else { 1.0 })
        }
        fn sample(&self, _wo: DVec3, _uc: f64, _u: [f64; 2]) -> Option<BsdfSample> {
            None
        }
        fn pdf(&self, _wi: DVec3, _wo: DVec3) -> f64 {
            0.0
        }
        fn flags(&self) -> BsdfFlags {
            BsdfFlags::REFLECTION
        }
    }
    impl ComponentModel for Const {
        fn eval_component(&self, _: DVec3, _: DVec3, _: Component) -> Rgb {
            Rgb::ZERO
        }
        fn is_rgb(&self) -> bool {
            false
        }
        fn components(&self) -> &'static [Component] {
            &[]
        }
    }
    let refs: Vec<&Point> = pts.iter().collect();
    let (w, u) = objective::rms_log_error(&Const, &refs, 1).unwrap();
    let r = ((1.1f64 + 1e-3) / (1.0 + 1e-3)).ln();
    // sigma_1 = 0.001/1.001 (~1e-3), sigma_2 = 1/1.001: weights ~1e6 and ~1.
    let w1 = 1.0 / (0.001f64 / 1.001).max(1e-3).powi(2);
    let w2 = 1.0 / (1.0f64 / 1.001).powi(2);
    assert!((w - (w1 * r * r / (w1 + w2)).sqrt()).abs() < 1e-12);
    assert!((u - (r * r / 2.0).sqrt()).abs() < 1e-12);
}
