//! Would keeping single scattering analytic (the issue's "exact single
//! scattering") take out the node change of a thin sheet with two smooth
//! faces and a forward-peaked medium? The thin tissue of the accuracy
//! cases (d 0.03 mm, `sigma_s` 40 /mm, `sigma_a` 0.3 /mm: optical
//! thickness 1.2) with smooth faces (`m` 0, `eta` 1.5) and forward lobe
//! `g_f` (default 0.8 and 0.9), transmission in the plane of incidence,
//! 32 nodes against 64 (`theta_i` 0 to 40, `theta_o` -40 to 40 every half
//! degree, values above 1e-2 of the largest).
//!
//! The single-scattering part is what the same sheet with the medium's
//! albedo made `eps` = 1e-5 (the same extinction) gives, divided by `eps`
//! and times the albedo: with smooth faces the unscattered light is in the
//! delta lobes, not in `eval`, and the second order is `eps` smaller, so
//! it is the solution's own single scattering, interpolated between the
//! nodes as the table is. Printed: the largest change of the whole value,
//! there the change of the rest (the whole less its single scattering, as
//! a share of the whole value), and the rest's largest change anywhere.
//! docs/slab.md gives the numbers of 2026-12-07.
//!
//! `cargo run --release -p paperbsdf-slab --example smooth_forward_lobe [G_F...]`

#[path = "../tests/support/mod.rs"]
mod support;

use paperbsdf_core::geometry::in_plane_directions;
use paperbsdf_core::{Bsdf, Colour, PaperParams};
use support::with_nodes_times;

/// An in-plane point and its values: `theta_i`, `theta_o` (transmission),
/// the whole value on 32 and 64 nodes, the single scattering on 32 and 64.
type Row = (f64, f64, f64, f64, f64, f64);

fn main() {
    let gs: Vec<f64> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("G_F: a number in (-1, 1)"))
        .collect();
    let gs = if gs.is_empty() { vec![0.8, 0.9] } else { gs };
    let (sigma_s, sigma_a) = (40.0, 0.3);
    let sigma_t = sigma_s + sigma_a;
    let eps = 1e-5;
    for g_f in gs {
        let sheet = PaperParams {
            d: 0.03,
            sigma_a: Colour::Scalar(sigma_a),
            sigma_s: Colour::Scalar(sigma_s),
            g_f,
            g_b: -0.3,
            w_b: 0.2,
            eta_f: 1.5,
            eta_b: 1.5,
            m_f: 0.0,
            m_b: 0.0,
            ..paperbsdf_core::presets::matte_office()
        };
        let first = PaperParams {
            sigma_a: Colour::Scalar(sigma_t * (1.0 - eps)),
            sigma_s: Colour::Scalar(sigma_t * eps),
            ..sheet.clone()
        };
        let (whole32, whole64) = (with_nodes_times(&sheet, 1), with_nodes_times(&sheet, 2));
        let (first32, first64) = (with_nodes_times(&first, 1), with_nodes_times(&first, 2));
        let per_eps = sigma_s / sigma_t / eps;
        let mut rows: Vec<Row> = Vec::new();
        for ti in (0..=80).map(|k| 0.5 * k as f64) {
            for to in (-80..=80).map(|k| 0.5 * k as f64) {
                let (wi, wo) = in_plane_directions(ti, to, true);
                rows.push((
                    ti,
                    to,
                    whole32.eval(wi, wo).mean(),
                    whole64.eval(wi, wo).mean(),
                    first32.eval(wi, wo).mean() * per_eps,
                    first64.eval(wi, wo).mean() * per_eps,
                ));
            }
        }
        let floor = 1e-2 * rows.iter().map(|r| r.3).fold(0.0, f64::max);
        let rows: Vec<_> = rows.into_iter().filter(|r| r.3 > floor).collect();
        let whole = |r: &Row| (r.2 / r.3 - 1.0).abs();
        let rest = |r: &Row| ((r.2 - r.4) - (r.3 - r.5)).abs() / r.3;
        let by = |f: &dyn Fn(&Row) -> f64| {
            *rows
                .iter()
                .max_by(|a, b| f(a).total_cmp(&f(b)))
                .expect("in-plane values")
        };
        let w = by(&whole);
        let r = by(&rest);
        println!(
            "g_f {g_f}: largest change of the whole {:.2}% at ({} T {}), single scattering there {:.4} -> {:.4} of {:.4}, the rest's change {:.2}%; the rest's largest change {:.2}% at ({} T {})",
            100.0 * whole(&w),
            w.0,
            w.1,
            w.4,
            w.5,
            w.3,
            100.0 * rest(&w),
            100.0 * rest(&r),
            r.0,
            r.1
        );
    }
}
