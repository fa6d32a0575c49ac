//! Construction of the models by their parameters: errors name the parameter,
//! and the model table of `models.rs` is consistent.

use paperbsdf_core::models::{ComponentModel, LambertGlass, LambertGlassParams, ModelKind};
use paperbsdf_core::paper::{Component, PaperBsdf};
use paperbsdf_core::presets::preset;
use paperbsdf_core::{Colour, DVec3, Distribution, ParamError, RoughDielectricParams};

#[test]
fn paper_errors_name_the_parameter() {
    let mut p = preset("matte").unwrap();
    p.eta_b = 6.0;
    let e = PaperBsdf::new(&p).unwrap_err();
    assert_eq!(e.name(), "eta_b", "{e}");
    let mut p = preset("matte").unwrap();
    p.sigma_s = Colour::Rgb([1.0, -2.0, 3.0]);
    assert_eq!(PaperBsdf::new(&p).unwrap_err().name(), "sigma_s[1]");
    let mut p = preset("matte").unwrap();
    p.g_f = f64::NAN;
    assert!(matches!(
        PaperBsdf::reduced_multilayer(&p).unwrap_err(),
        ParamError::NotFinite { .. }
    ));
}

#[test]
fn lambert_glass_validation() {
    let ok = LambertGlassParams {
        name: None,
        k_d: Colour::Scalar(0.6),
        k_t: Colour::Scalar(0.3),
        eta: 1.5,
        m: 0.2,
        dist: Distribution::Ggx,
    };
    assert!(LambertGlass::new(&ok).is_ok());
    let bad = LambertGlassParams {
        k_t: Colour::Rgb([0.3, 0.5, 0.1]),
        ..ok.clone()
    };
    assert_eq!(LambertGlass::new(&bad).unwrap_err().name(), "k_t");
    let bad = LambertGlassParams { m: 2.0, ..ok.clone() };
    assert_eq!(LambertGlass::new(&bad).unwrap_err().name(), "m");
    let bad = LambertGlassParams {
        k_d: Colour::Scalar(-0.1),
        ..ok.clone()
    };
    assert_eq!(LambertGlass::new(&bad).unwrap_err().name(), "k_d");
    let json = r#"{"k_d": [0.5, 0.4, 0.3], "k_t": 0.1, "eta": 1.5, "m": 0.1, "dist": "beckmann"}"#;
    let p: LambertGlassParams = serde_json::from_str(json).unwrap();
    assert!(LambertGlass::new(&p).unwrap().is_rgb());
    assert!(serde_json::from_str::<LambertGlassParams>(
        r#"{"k_d": 0.5, "k_t": 0.1, "eta": 1.5, "m": 0.1, "dist": "ggx", "x": 1}"#
    )
    .is_err());
    let rd: RoughDielectricParams = serde_json::from_str(r#"{"eta": 7.0, "m": 0.1, "dist": "ggx"}"#).unwrap();
    assert_eq!(rd.validate().unwrap_err().name(), "eta");
}

/// Every model's components sum to its `eval`, and the components it lacks are zero.
#[test]
fn components_sum_to_eval() {
    let p = preset("luster").unwrap();
    let lg = LambertGlassParams {
        name: None,
        k_d: Colour::Rgb([0.5, 0.4, 0.3]),
        k_t: Colour::Scalar(0.2),
        eta: 1.5,
        m: 0.3,
        dist: Distribution::Ggx,
    };
    let models: Vec<Box<dyn ComponentModel>> = vec![
        Box::new(PaperBsdf::new(&p).unwrap()),
        Box::new(PaperBsdf::reduced_multilayer(&p).unwrap()),
        Box::new(LambertGlass::new(&lg).unwrap()),
        Box::new(paperbsdf_core::RoughDielectric::new(Distribution::Beckmann, 1.5, 0.3).unwrap()),
    ];
    assert_eq!(
        models.len(),
        // `measured` (paperbsdf-io) and `slab` (paperbsdf-slab, with its own
        // tests of the same property) are built outside core.
        ModelKind::ALL
            .iter()
            .filter(|k| !matches!(**k, ModelKind::Measured | ModelKind::Slab))
            .count()
    );
    let dirs = [
        DVec3::new(0.3, 0.1, 0.9),
        DVec3::new(-0.5, 0.2, 0.6),
        DVec3::new(0.1, -0.4, -0.8),
        DVec3::new(-0.2, -0.3, -0.5),
    ];
    for m in &models {
        for wi in dirs {
            for wo in dirs {
                let (wi, wo) = (wi.normalize(), wo.normalize());
                let sum = Component::ALL
                    .iter()
                    .fold(paperbsdf_core::Rgb::ZERO, |a, c| a + m.eval_component(wi, wo, *c));
                let f = m.eval(wi, wo);
                for c in 0..3 {
                    assert!((sum.0[c] - f.0[c]).abs() <= 1e-12 * f.0[c].abs().max(1e-300));
                }
                for c in Component::ALL {
                    if !m.components().contains(&c) {
                        assert!(m.eval_component(wi, wo, c).is_black());
                    }
                }
            }
        }
    }
}
