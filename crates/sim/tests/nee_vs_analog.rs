//! The next-event estimator of `f` against the analog estimator of the same walks.
//!
//! The flux leaving into a cone around an axis is counted directly from the
//! walks' exits (no next-event estimation, no MIS, no BSDF evaluation: only
//! the sampled events), and compared with the integral of the next-event
//! estimate `integral_cap f(wi, wo) |cos wo| dwo` by a product quadrature over
//! the cone (Gauss-Legendre in `sin^2 theta`, trapezoid in azimuth). The two
//! come from the same walks, so their difference is tested against its own
//! standard error over 32 independent batches: |difference| < 4 sigma plus
//! 0.5% of the value for the quadrature error over the cone.

mod support;

use paperbsdf_core::geometry::in_plane_directions;
use paperbsdf_core::quadrature::gauss_legendre_01;
use paperbsdf_core::{Colour, DVec3, Distribution, PaperParams};
use paperbsdf_sim::walk::{Tally, Tracer};
use paperbsdf_sim::Slab;
use rand::SeedableRng;

/// Returns (analog, nee, stderr of the difference).
#[allow(clippy::too_many_arguments)]
fn cap(
    p: &PaperParams,
    theta_i: f64,
    transmission: bool,
    cap_deg: f64,
    quad: (usize, usize),
    walks: usize,
    seed: u64,
) -> (f64, f64, f64) {
    let slab = Slab::from_params(p).unwrap();
    let (wi, _) = in_plane_directions(theta_i, 0.0, false);
    let axis = if transmission { -DVec3::Z } else { DVec3::Z };
    let s2c = cap_deg.to_radians().sin().powi(2);
    let (xu, wu) = gauss_legendre_01(quad.0);
    let nphi = quad.1;
    let mut wos = Vec::new();
    let mut wts = Vec::new();
    for (u, w) in xu.iter().zip(&wu) {
        let st = (u * s2c).sqrt();
        let ct = (1.0 - st * st).sqrt();
        for k in 0..nphi {
            let phi = 2.0 * std::f64::consts::PI * (k as f64 + 0.5) / nphi as f64;
            wos.push(DVec3::new(st * phi.cos(), st * phi.sin(), ct * axis.z));
            // 1/2 * s2c * w * (2 pi / nphi)
            wts.push(0.5 * s2c * w * 2.0 * std::f64::consts::PI / nphi as f64);
        }
    }
    let tracer = Tracer::new(&slab, 0, &wos);
    let nb = 32;
    let per = walks / nb;
    let mut diffs = Vec::new();
    let (mut sa, mut sn) = (0.0, 0.0);
    for b in 0..nb {
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed * 1000 + b as u64);
        let mut tally = Tally::new(wos.len());
        let mut analog = 0.0;
        let cos_c = cap_deg.to_radians().cos();
        for _ in 0..per {
            tracer.walk_with_exits(wi, &mut rng, &mut tally, &mut |d: DVec3, w: f64| {
                if d.dot(axis) >= cos_c {
                    analog += w;
                }
            });
        }
        let nee: f64 = tally.f.iter().zip(&wts).map(|(f, w)| f * w).sum();
        let (a, n) = (analog / per as f64, nee / per as f64);
        sa += a;
        sn += n;
        diffs.push(a - n);
    }
    let m = diffs.iter().sum::<f64>() / nb as f64;
    let var = diffs.iter().map(|d| (d - m).powi(2)).sum::<f64>() / (nb as f64 - 1.0);
    (sa / nb as f64, sn / nb as f64, (var / nb as f64).sqrt())
}

fn paper(d: f64, sigma_s: f64, m_f: f64, m_b: f64, eta_f: f64, eta_b: f64) -> PaperParams {
    PaperParams {
        name: None,
        d,
        sigma_a: Colour::Scalar(0.5),
        sigma_s: Colour::Scalar(sigma_s),
        g_f: 0.8,
        g_b: -0.3,
        w_b: 0.2,
        eta_f,
        eta_b,
        m_f,
        m_b,
        dist_f: Distribution::Ggx,
        dist_b: Distribution::Beckmann,
        face_scattering: paperbsdf_core::FaceScattering::Single,
    }
}

/// Quadrature over the cone: (Gauss-Legendre points in sin^2 theta, azimuths).
/// At normal incidence the integrand does not depend on azimuth.
fn quad_for(theta_i: f64) -> (usize, usize) {
    if theta_i == 0.0 {
        (8, 2)
    } else {
        (4, 6)
    }
}

fn check(name: &str, p: &PaperParams, theta_i: f64, transmission: bool, cap_deg: f64, walks: usize) {
    check_quad(name, p, theta_i, transmission, cap_deg, quad_for(theta_i), walks);
}

/// [`check`] with a given quadrature over the cone (narrow lobes need more points).
fn check_quad(
    name: &str,
    p: &PaperParams,
    theta_i: f64,
    transmission: bool,
    cap_deg: f64,
    quad: (usize, usize),
    walks: usize,
) {
    let (a, n, se) = cap(p, theta_i, transmission, cap_deg, quad, walks, 11);
    let tol = 4.0 * se + 0.005 * a.abs();
    eprintln!("{name}: analog {a:.6} nee {n:.6} diff {:.2e} stderr {se:.2e}", a - n);
    assert!(
        (a - n).abs() <= tol,
        "{name}: analog {a} vs next-event {n} (stderr of difference {se})"
    );
}

#[test]
fn rough_faces_reflection_and_transmission_at_grazing_light() {
    // devA-like slab, light at 75 degrees: the configuration where Mitsuba's
    // reference looks non-reciprocal.
    let p = paper(0.05, 120.0, 0.35, 0.35, 1.45, 1.45);
    check("rough R 75", &p, 75.0, false, 20.0, 16_000);
    check("rough T 75", &p, 75.0, true, 20.0, 16_000);
}

#[test]
fn thin_sheet_unscattered_light_and_mixed_faces() {
    // Optically thin (tau = 0.5): unscattered light and surface-only paths
    // dominate. eta_f != eta_b: a rough front over a coating (sub-walk in the
    // coating, path estimates of its BSDF, exit sampling only).
    let p = paper(0.01, 50.0, 0.3, 0.5, 1.5, 1.3);
    // The unscattered lobe is centred in the cone at normal incidence (a cone
    // edge across it would need a finer quadrature).
    check("thin T 0", &p, 0.0, true, 30.0, 32_000);
    check("thin R 30", &p, 30.0, false, 25.0, 16_000);
    // Smooth front (delta vertex and delta exit), rough back.
    let q = paper(0.02, 100.0, 0.0, 0.4, 1.5, 1.5);
    check("smooth-front T 0", &q, 0.0, true, 30.0, 16_000);
    check("smooth-front R 40 (cone off the mirror)", &q, 40.0, false, 20.0, 16_000);
}

#[test]
fn smooth_faces_and_coatings_chains_of_mirror_reflections() {
    // Both faces smooth: every exit is a delta and light reaches it after any
    // number of internal mirror reflections (the geometric series of the delta
    // exits); a thin sheet makes the reflections matter.
    let p = paper(0.02, 30.0, 0.0, 0.0, 1.8, 1.8);
    check("smooth-both R 30", &p, 30.0, false, 25.0, 16_000);
    // Unscattered light leaves in the delta direction at 40 degrees, outside the
    // 20-degree cone (f excludes pure delta paths, the analog count would not).
    check("smooth-both T 40", &p, 40.0, true, 20.0, 16_000);
    // A smooth coating of index 2.4 over a base of 1.4 (a film: delta with
    // internal reflections of the film), rough back.
    let q = paper(0.02, 60.0, 0.0, 0.4, 2.4, 1.4);
    check(
        "smooth-coating R 40 (cone off the mirror)",
        &q,
        40.0,
        false,
        20.0,
        16_000,
    );
    check("smooth-coating T 0", &q, 0.0, true, 30.0, 16_000);
    // A rough coating of lower index than the base (total internal reflection
    // from the base at the coating) over a smooth back. The base of index 2
    // narrows the transmitted lobe: the default quadrature over the cone was 9%
    // off at T 0 without a medium (32 points in sin^2 theta agree to 0.1%). Its
    // reflection needs 16 x 24 points over the cone, too slow for CI here: the
    // reciprocity tests cover it.
    let r = paper(0.02, 60.0, 0.25, 0.0, 1.3, 2.0);
    check_quad("low-index rough coating T 0", &r, 0.0, true, 30.0, (32, 2), 16_000);
}

#[test]
fn multiple_scattering_faces() {
    // The microsurface walk's faces: exit sampling by the walk, stochastic
    // estimates of the faces' values at vertices, uncoated and coated fronts.
    let mut p = paper(0.05, 120.0, 0.5, 0.9, 1.45, 1.45);
    p.face_scattering = paperbsdf_core::FaceScattering::Multiple;
    check("multiple R 60", &p, 60.0, false, 25.0, 8_000);
    check("multiple T 0", &p, 0.0, true, 30.0, 8_000);
    let mut q = paper(0.01, 50.0, 0.3, 0.5, 1.5, 1.3);
    q.face_scattering = paperbsdf_core::FaceScattering::Multiple;
    check("multiple coated thin T 0", &q, 0.0, true, 30.0, 16_000);
    check("multiple coated thin R 30", &q, 30.0, false, 25.0, 8_000);
}
