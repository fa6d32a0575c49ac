//! The lit face's multiply scattered reflection summed to more Fourier
//! orders than the rest of the sheet (`SlabOptions::walk_orders`,
//! src/interface.rs module doc): at grazing incidence on a smooth face the
//! microsurface walk sends a forward peak narrower in azimuth than the
//! sheet's 48 orders resolve. The hardest points are in the plane of
//! incidence at 75 degrees, seen at 80 and 85 degrees on the far side
//! (luster's Beckmann 0.15 front; matte's front), and the back face lit at
//! grazing incidence.

use paperbsdf_core::geometry::in_plane_directions;
use paperbsdf_core::presets::preset;
use paperbsdf_core::{Bsdf, DVec3, Distribution, PaperParams};
use paperbsdf_slab::{SlabBsdf, SlabOptions};

mod support;

/// In-plane reflection at the walk's forward peak, lit from the front and
/// (the same directions mirrored through the sheet) from the back.
fn peak_values(b: &SlabBsdf) -> Vec<(String, f64)> {
    let mut v = Vec::new();
    for (ti, to) in [
        (75.0, -80.0),
        (75.0, -85.0),
        (75.0, -75.0),
        (85.0, -85.0),
        (60.0, -70.0),
    ] {
        let (wi, wo) = in_plane_directions(ti, to, false);
        v.push((format!("front {ti} R {to}"), b.eval(wi, wo).mean()));
        let flip = |w: DVec3| DVec3::new(w.x, w.y, -w.z);
        v.push((format!("back {ti} R {to}"), b.eval(flip(wi), flip(wo)).mean()));
    }
    v
}

/// Doubling the orders (48 -> 96) and the walk's orders (256 -> 512)
/// moves the peak by less than 0.2% (the bound), and the default is
/// closer to the doubled solve than with the walk summed to the sheet's 48
/// orders with Fejer's weights (before 2026-12-05: luster 4.6-6.2% under it
/// lit from the front, 1.1-1.2% from the back). Measured: at most 0.001%
/// at 60 and 75 degrees. At 85 R -85 the walk's peak is narrower than 256
/// orders resolve at the node pairs beyond 82 degrees, which take part of
/// Fejer's weights (src/bsdf.rs, `FEJER_SHARE_STEPS`): 1.2% under (2.2%
/// with Fejer's whole, until 2026-12-06; 4.9% before the walk's orders).
/// Luster with smoother fronts, Beckmann 0.1 and 0.08 (devB's), and GGX
/// 0.06, whose walks take more orders than asked
/// (`interface::walk_orders_for`: 384, 512 and 640): with 256 for every
/// face the first two were 3.9% and 2.8% off at 80 R -80 on devB's sheet,
/// now within 0.001% everywhere but 85 R -85 lit from the front, 2.0%,
/// 2.0% and 0.4% under (3.4%, 3.5% and 2.4% with Fejer's whole): the same
/// pairs, whose share of Fejer's kernel (about `2 pi / M` wide) takes more
/// off a narrower peak. 85 R -85 is asserted within 2.5%, outside the
/// issue's range (examples/convergence.rs stops at 80 degrees). Lit from the back
/// (luster's Beckmann 0.3 back face, 256 orders) the light meets the
/// smoother front's walk only after the sheet.
#[test]
fn the_walks_forward_peak_converges_in_the_orders() {
    let smoother = |m_f: f64, dist_f: Distribution| PaperParams {
        m_f,
        dist_f,
        ..preset("luster").unwrap()
    };
    let sheets = [
        ("luster", preset("luster").unwrap()),
        ("matte", preset("matte").unwrap()),
        ("luster, Beckmann 0.1 front", smoother(0.1, Distribution::Beckmann)),
        ("luster, Beckmann 0.08 front", smoother(0.08, Distribution::Beckmann)),
        ("luster, GGX 0.06 front", smoother(0.06, Distribution::Ggx)),
    ];
    for (name, p) in sheets {
        let base = SlabOptions::default();
        let with = |orders: usize, walk_orders: usize| {
            let o = SlabOptions {
                orders,
                walk_orders,
                ..base
            };
            peak_values(&SlabBsdf::with_options(&p, &o).unwrap())
        };
        let (now, fine, old) = (
            with(base.orders, base.walk_orders),
            with(2 * base.orders, 2 * base.walk_orders),
            with(base.orders, base.orders),
        );
        for (((at, v), (_, f)), (_, o)) in now.iter().zip(&fine).zip(&old) {
            let (rel, rel_old) = (v / f - 1.0, o / f - 1.0);
            eprintln!(
                "{name} {at}: {v:.5} / {f:.5} {:+.3}% (48 orders {:+.3}%)",
                100.0 * rel,
                100.0 * rel_old
            );
            let bound = if at.contains(" 85 R ") { 2.5e-2 } else { 2e-3 };
            assert!(rel.abs() < bound, "{name} {at}: {v} against {f} with twice the orders");
            assert!(
                rel.abs() <= rel_old.abs() + 1e-4,
                "{name} {at}: {v} is farther from {f} than the walk to 48 orders, {o}"
            );
        }
    }
}

/// The orders above the sheet's come from the walk's chain restricted to
/// the outside states (`face_walk::outside_reflection`), those below from
/// the full chain. Solving the sheet to 96 orders instead of 48 takes the
/// orders 48..96 from the full chain instead: the two agree within 1e-4
/// (measured 7.7e-6, lit from the back): the light that refracts into the face on its way is
/// broad in azimuth and has almost no part in the orders above 48. A chain
/// that dropped a block, scaled differently or had the orders' signs wrong
/// would be off by percent.
#[test]
fn the_outside_chain_gives_the_full_chains_high_orders() {
    let p = preset("luster").unwrap();
    let base = SlabOptions::default();
    let b = SlabBsdf::new(&p).unwrap();
    let full = SlabBsdf::with_options(
        &p,
        &SlabOptions {
            orders: 2 * base.orders,
            ..base
        },
    )
    .unwrap();
    for ((at, v), (_, f)) in peak_values(&b).iter().zip(peak_values(&full)) {
        let rel = v / f - 1.0;
        eprintln!("{at}: {v:.6} / {f:.6} {:+.2e}", rel);
        assert!(rel.abs() < 1e-4, "{at}: {v} against the full chain's {f}");
    }
}

/// Faces of which only one has the walk's orders past the sheet's: a
/// smooth front (no walk) over matte's rough back with the walk. The sheet
/// builds; lit from the back its walk's peak converges as the presets' do
/// (< 0.2% against twice the orders; measured at most 0.003%), lit from the
/// front (nothing of a walk to add) likewise (measured 0.000%). 85 degrees
/// is left out: its node pairs keep Fejer's weights, as the presets'. Until
/// the fix of 2026-12-05 the face without walk orders sliced past its empty
/// walk and the build panicked.
#[test]
fn a_face_without_the_walk_beside_one_with_it() {
    let mut p = preset("matte").unwrap();
    p.m_f = 0.0;
    let base = SlabOptions::default();
    let b = SlabBsdf::new(&p).unwrap();
    let fine = SlabBsdf::with_options(
        &p,
        &SlabOptions {
            orders: 2 * base.orders,
            walk_orders: 2 * base.walk_orders,
            ..base
        },
    )
    .unwrap();
    for ((at, v), (_, f)) in peak_values(&b).iter().zip(peak_values(&fine)) {
        if at.contains(" 85 R ") || f <= 0.0 {
            continue;
        }
        let rel = v / f - 1.0;
        eprintln!("smooth front, rough back {at}: {v:.5} / {f:.5} {:+.3}%", 100.0 * rel);
        assert!(rel.abs() < 2e-3, "{at}: {v} against {f} with twice the orders");
    }
}

/// The rule that gives each face its walk's orders
/// (`interface::walk_orders_for`): the orders asked for at and above the
/// reference roughness, in proportion to `1 / alpha` below it rounded up to
/// a multiple of 64, at most 2.5 times, and never past the most orders; 0
/// stays 0 (no walk orders asked). Doubling the orders asked doubles a
/// face's (up to rounding to 64), which the convergence checks rely on.
#[test]
fn each_face_takes_orders_as_its_roughness_needs() {
    use paperbsdf_slab::bsdf::MAX_ORDERS;
    use paperbsdf_slab::interface::{walk_orders_for, WALK_MOST_FACTOR, WALK_REFERENCE_ALPHA};
    assert_eq!(walk_orders_for(256, 0.3, MAX_ORDERS), 256);
    assert_eq!(walk_orders_for(256, WALK_REFERENCE_ALPHA, MAX_ORDERS), 256);
    // 256 * 0.15 / 0.1 = 384; 256 * 0.15 / 0.08 = 480 -> 512; 0.06: 640.
    assert_eq!(walk_orders_for(256, 0.1, MAX_ORDERS), 384);
    assert_eq!(walk_orders_for(256, 0.08, MAX_ORDERS), 512);
    assert_eq!(walk_orders_for(256, 0.06, MAX_ORDERS), 640);
    // Smoother: capped at 2.5 times.
    for alpha in [0.05, 0.01, 1e-4] {
        assert_eq!(
            walk_orders_for(256, alpha, MAX_ORDERS),
            (256.0 * WALK_MOST_FACTOR) as usize
        );
    }
    assert_eq!(walk_orders_for(0, 0.05, MAX_ORDERS), 0);
    assert_eq!(walk_orders_for(1024, 0.05, MAX_ORDERS), MAX_ORDERS);
    assert_eq!(walk_orders_for(512, 0.3, 300), 300);
    for alpha in [0.3, 0.15, 0.12, 0.1, 0.08, 0.07, 0.06, 0.04] {
        let (a, b) = (
            walk_orders_for(256, alpha, MAX_ORDERS),
            walk_orders_for(512, alpha, MAX_ORDERS),
        );
        assert!(b >= 2 * a - 64 && b <= 2 * a, "alpha {alpha}: {a} then {b}");
        assert!(a % 64 == 0 && a >= 256, "alpha {alpha}: {a}");
    }
}

/// Along the walk's mirror ridge at grazing incidence (luster, in the plane
/// from 79.5 to 84 degrees, where its node pairs begin to ring), 32 and 64
/// nodes agree within 0.5% (measured 0.29%). The pairs that ring take the
/// least share of Fejer's weights that keeps them within tolerance
/// (src/bsdf.rs, `FEJER_SHARE_STEPS`); until 2026-12-06 they took Fejer's
/// whole, so the ridge stepped down where the first pair rang (82 degrees
/// on 32 nodes, 80.8 on 64, whose ridge dipped by 8% there) and the two
/// grids were 1.71% apart at 80.75 degrees.
#[test]
fn the_walks_ridge_converges_in_the_nodes() {
    let (coarse, fine) = support::default_and_doubled_nodes(&preset("luster").unwrap());
    let mut worst = 0.0f64;
    for k in 0..=18 {
        let t = 79.5 + 0.25 * k as f64;
        let (wi, wo) = in_plane_directions(t, -t, false);
        let (a, b) = (coarse.eval(wi, wo).mean(), fine.eval(wi, wo).mean());
        let e = (a / b - 1.0).abs();
        worst = worst.max(e);
        assert!(e < 5e-3, "{t} R -{t}: {a} with 32 nodes, {b} with 64");
    }
    eprintln!(
        "luster's ridge 79.5-84 degrees: 32 against 64 nodes within {:.2}%",
        100.0 * worst
    );
}
