//! Chi-square goodness-of-fit of the sampling of every model of `models.rs`
//! (pdf(wi, wo) must be the density of sample(wo)) over a grid of Table 2's
//! corners: thin and thick slabs, smooth, rough and index-matched faces,
//! forward and backward phase lobes, eta up to 5, viewer above and below.
//! Delta draws are mapped to the harness's "no direction" cell.

#[path = "support/chi2.rs"]
mod chi2;

use paperbsdf_core::geometry::spherical_direction;
use paperbsdf_core::models::{LambertGlass, LambertGlassParams};
use paperbsdf_core::paper::PaperBsdf;
use paperbsdf_core::{Bsdf, Colour, DVec3, Distribution, PaperParams, RoughDielectric};

fn paper(d: f64, sa: Colour, ss: Colour, faces: Faces, phase: (f64, f64, f64)) -> PaperParams {
    PaperParams {
        name: None,
        d,
        sigma_a: sa,
        sigma_s: ss,
        g_f: phase.0,
        g_b: phase.1,
        w_b: phase.2,
        eta_f: faces[0].0,
        m_f: faces[0].1,
        dist_f: faces[0].2,
        eta_b: faces[1].0,
        m_b: faces[1].1,
        dist_b: faces[1].2,
        face_scattering: Default::default(),
    }
}

struct Outcome {
    failures: Vec<String>,
    p_min: f64,
    n: usize,
}

fn run(out: &mut Outcome, name: &str, b: &dyn Bsdf, wo: DVec3, seed: u64) {
    let r = chi2::chi2_test(
        name,
        |u| {
            b.sample(wo, u[0], [u[1], u[2]])
                .filter(|s| !s.flags.is_specular())
                .map(|s| s.wi)
        },
        |wi| b.pdf(wi, wo),
        50_000,
        seed,
    );
    out.n += 1;
    match r {
        Ok(p) => out.p_min = out.p_min.min(p),
        Err(e) => out.failures.push(e),
    }
}

fn viewers() -> Vec<(String, DVec3)> {
    let mut v = Vec::new();
    for side in [1.0, -1.0] {
        for theta in [25.0f64, 72.0] {
            let w = spherical_direction(theta.to_radians(), 0.4);
            v.push((format!("theta_o={theta} side={side}"), DVec3::new(w.x, w.y, side * w.z)));
        }
    }
    v
}

fn finish(out: Outcome) {
    eprintln!("{} chi-square tests, smallest p = {:.3e}", out.n, out.p_min);
    assert!(
        out.failures.is_empty(),
        "{} of {} failed:\n{}",
        out.failures.len(),
        out.n,
        out.failures.join("\n")
    );
}

const GGX: Distribution = Distribution::Ggx;
const BECK: Distribution = Distribution::Beckmann;

/// `(eta, m, dist)` of the front and back faces.
type Faces = [(f64, f64, Distribution); 2];

fn face_sets() -> Vec<(&'static str, Faces)> {
    vec![
        ("rough-rough", [(1.5, 0.3, GGX), (5.0, 0.6, BECK)]),
        ("smooth-smooth", [(1.5, 0.0, GGX), (1.5, 0.0, GGX)]),
        ("smooth-rough", [(2.4, 0.0, GGX), (1.3, 0.15, GGX)]),
        ("matched-rough", [(1.0, 0.4, GGX), (1.5, 1.2, BECK)]),
    ]
}

fn slabs() -> Vec<(&'static str, f64, Colour, Colour)> {
    vec![
        ("thick", 0.1, Colour::Rgb([1.0, 0.5, 2.0]), Colour::Scalar(300.0)),
        ("thin", 0.02, Colour::Scalar(0.5), Colour::Rgb([5.0, 20.0, 2.0])),
    ]
}

fn paper_grid(phase: (f64, f64, f64), tag: &str, seed0: u64) {
    let mut out = Outcome {
        failures: vec![],
        p_min: 1.0,
        n: 0,
    };
    let mut seed = seed0;
    for (sn, d, sa, ss) in slabs() {
        for (fname, faces) in face_sets() {
            let p = paper(d, sa, ss, faces, phase);
            let b = PaperBsdf::new(&p).unwrap();
            for (vn, wo) in viewers() {
                seed += 1;
                run(&mut out, &format!("paper {tag} {sn} {fname} {vn}"), &b, wo, seed);
            }
        }
    }
    finish(out);
}

#[test]
fn chi2_paper_forward_lobes() {
    paper_grid((0.9, -0.3, 0.1), "forward", 100);
}

#[test]
fn chi2_paper_backward_lobes() {
    paper_grid((0.2, -0.9, 0.8), "backward", 200);
}

#[test]
fn chi2_reduced_multilayer_and_no_direct() {
    let mut out = Outcome {
        failures: vec![],
        p_min: 1.0,
        n: 0,
    };
    let mut seed = 300;
    for (fname, faces) in face_sets() {
        let p = paper(0.03, Colour::Scalar(1.0), Colour::Scalar(40.0), faces, (0.7, -0.5, 0.3));
        let b = PaperBsdf::reduced_multilayer(&p).unwrap();
        for (vn, wo) in viewers() {
            seed += 1;
            run(&mut out, &format!("reduced {fname} {vn}"), &b, wo, seed);
        }
    }
    finish(out);
}

#[test]
fn chi2_lambert_glass() {
    let mut out = Outcome {
        failures: vec![],
        p_min: 1.0,
        n: 0,
    };
    let mut seed = 400;
    for (eta, m, dist) in [(1.5, 0.2, GGX), (1.5, 0.0, GGX), (5.0, 0.7, BECK), (1.0, 0.3, GGX)] {
        for (kd, kt) in [(Colour::Rgb([0.5, 0.1, 0.3]), Colour::Scalar(0.2))] {
            let p = LambertGlassParams {
                name: None,
                k_d: kd,
                k_t: kt,
                eta,
                m,
                dist,
            };
            let b = LambertGlass::new(&p).unwrap();
            for (vn, wo) in viewers() {
                seed += 1;
                run(&mut out, &format!("lambert-glass eta={eta} m={m} {vn}"), &b, wo, seed);
            }
        }
    }
    finish(out);
}

#[test]
fn chi2_rough_dielectric_model() {
    let mut out = Outcome {
        failures: vec![],
        p_min: 1.0,
        n: 0,
    };
    let mut seed = 500;
    for (eta, m, dist) in [(1.5, 0.2, GGX), (5.0, 0.05, BECK)] {
        let b = RoughDielectric::new(dist, eta, m).unwrap();
        for (vn, wo) in viewers() {
            seed += 1;
            run(
                &mut out,
                &format!("rough-dielectric eta={eta} m={m} {vn}"),
                &b,
                wo,
                seed,
            );
        }
    }
    finish(out);
}

/// `sample` returns `f = eval(wi, wo)` and `pdf = pdf(wi, wo)` for non-delta
/// draws, and finite weights.
#[test]
fn sample_consistent_with_eval_and_pdf() {
    let p = paper(
        0.05,
        Colour::Rgb([0.2, 1.0, 3.0]),
        Colour::Scalar(80.0),
        [(1.5, 0.3, GGX), (1.4, 0.5, BECK)],
        (0.8, -0.4, 0.3),
    );
    let b = PaperBsdf::new(&p).unwrap();
    for (_, wo) in viewers() {
        for k in 0..2000 {
            let u = [
                (k as f64 * 0.618_034).fract(),
                (k as f64 * 0.754_878).fract(),
                (k as f64 * 0.569_840).fract(),
            ];
            if let Some(s) = b.sample(wo, u[0], [u[1], u[2]]) {
                assert!(s.weight().is_finite() && s.pdf > 0.0);
                if !s.flags.is_specular() {
                    let f = b.eval(s.wi, wo);
                    let pdf = b.pdf(s.wi, wo);
                    assert!((pdf - s.pdf).abs() <= 1e-9 * pdf, "{pdf} vs {}", s.pdf);
                    for c in 0..3 {
                        assert!((f.0[c] - s.f.0[c]).abs() <= 1e-9 * f.0[c].abs().max(1e-300));
                    }
                }
            }
        }
    }
}

/// `face_interface_reflection_and_pdf` is `face_interface_reflection` and
/// `face_reflection_pdf` at once (the slab model's sampler uses it): the same
/// values, for rough, coated (glossy: a Beckmann 0.04 coating over a base of
/// another index) and smooth faces, both sides, in reflection and in
/// transmission (both zero there), grazing directions included.
#[test]
fn face_reflection_and_pdf_at_once() {
    use paperbsdf_core::paper::Side;
    use paperbsdf_core::presets::preset;
    let mut sheets: Vec<PaperParams> = ["matte", "luster", "glossy"]
        .iter()
        .map(|n| preset(n).unwrap())
        .collect();
    sheets.push(paper(
        0.1,
        Colour::Scalar(0.5),
        Colour::Scalar(50.0),
        [(1.5, 0.0, Distribution::Ggx), (1.6, 0.5, Distribution::Beckmann)],
        (0.8, -0.3, 0.2),
    ));
    let mut n = 0;
    for p in &sheets {
        let b = PaperBsdf::new(p).unwrap();
        for k in 0..400 {
            let u = |a: f64| (0.5 + k as f64 * a).fract();
            let half_pi = 0.9999 * std::f64::consts::FRAC_PI_2;
            let (ti, to) = (u(0.618_033_988_7) * half_pi, u(0.754_877_666) * half_pi);
            let si = if k % 2 == 0 { 1.0 } else { -1.0 };
            let so = if k % 3 == 0 { -si } else { si };
            let a = spherical_direction(ti, u(0.569_840_29) * std::f64::consts::TAU);
            let c = spherical_direction(to, u(0.412_454_03) * std::f64::consts::TAU);
            let (wi, wo) = (DVec3::new(a.x, a.y, si * a.z), DVec3::new(c.x, c.y, so * c.z));
            let side = if wo.z > 0.0 { Side::Front } else { Side::Back };
            let (f, pdf) = b.face_interface_reflection_and_pdf(side, wi, wo);
            let (f0, pdf0) = (b.face_interface_reflection(side, wi, wo), b.face_reflection_pdf(wi, wo));
            assert!((f - f0).abs() <= 1e-12 * f0.abs(), "f {f} vs {f0}");
            assert!((pdf - pdf0).abs() <= 1e-12 * pdf0.abs(), "pdf {pdf} vs {pdf0}");
            n += usize::from(f0 > 0.0);
        }
    }
    assert!(n > 400, "too few directions with a face reflection: {n}");
}

/// The interface's reflection of a coated front (glossy: Beckmann 0.04 at
/// 1.55 over a base of 1.5) is the reflection of the same interface on an
/// uncoated sheet (`eta_b = eta_f`): Walter's lobe, and for `face_scattering
/// = "multiple"` the compensation lobe, which depends on the interface
/// alone; none of the coating's lobe. Both face modes, directions down to
/// 0.01 degrees above the horizon, with and without the coating's lobe
/// dominating (near the normal, away from the mirror direction).
#[test]
fn coated_interface_reflection_is_the_uncoated_face() {
    use paperbsdf_core::paper::Side;
    use paperbsdf_core::presets::preset;
    use paperbsdf_core::FaceScattering;
    let mut n = 0;
    for fs in [FaceScattering::Single, FaceScattering::Multiple] {
        let coated = PaperParams {
            face_scattering: fs,
            ..preset("glossy").unwrap()
        };
        let uncoated = PaperParams {
            eta_b: coated.eta_f,
            ..coated.clone()
        };
        let (c, u) = (PaperBsdf::new(&coated).unwrap(), PaperBsdf::new(&uncoated).unwrap());
        for k in 0..2000 {
            let f = |a: f64| (0.5 + k as f64 * a).fract();
            let max = (90.0f64 - 0.01).to_radians();
            let (ti, to) = (f(0.618_033_988_7) * max, f(0.754_877_666) * max);
            let wi = spherical_direction(ti, f(0.569_840_29) * std::f64::consts::TAU);
            let wo = spherical_direction(to, f(0.412_454_03) * std::f64::consts::TAU);
            let (a, b) = (
                c.face_interface_reflection(Side::Front, wi, wo),
                u.face_interface_reflection(Side::Front, wi, wo),
            );
            assert!(
                (a - b).abs() <= 1e-13 * b.abs(),
                "{fs:?} at {wi:?} -> {wo:?}: coated {a}, uncoated {b}"
            );
            // The coated face's whole reflection holds the coating's lobe too.
            let whole = c.face_reflection(Side::Front, wi, wo);
            assert!(whole >= a, "{fs:?}: whole {whole} below the interface's {a}");
            n += usize::from(b > 0.0 && whole > 1.001 * b);
        }
    }
    assert!(n > 1000, "too few directions where the coating's lobe shows: {n}");
}
