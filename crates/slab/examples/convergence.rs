//! Convergence of the model `slab` in its discretisation, measured where the
//! renderer sees it: `SlabBsdf::eval` in the plane of incidence on a dense
//! grid (`theta_i` 0 to 80 degrees and `theta_o` -80 to 80, every half
//! degree: the nodes of 32, 64 and 128, the points between them and the
//! points of docs/accuracy.md; reflection and transmission, light on the
//! front), and the directional albedo, for the default options against
//! doubled nodes (64 outside, 32 in the cone of total reflection) and
//! against doubled Fourier orders (96, and 512 for the lit face's walk), for
//! every case of docs/accuracy.md (the presets, devA, devB and the spread of
//! sheets), in both face modes. Until 2026-12-06 the points were `theta_i`
//! 0, 2.5, 30, 45, 60, 75 only, which missed the largest changes (between
//! 5 and 15 degrees from the normal, where no `theta_i` was).
//!
//! Printed per sheet: the largest relative change of a value (with the
//! in-plane point where it happens), the largest within 5 degrees of the
//! normal (either direction), from 5 to 15 degrees, and further out, the RMS
//! relative change, and the largest change of the albedo; and at the point
//! of the largest change, how much each component (`surface`, `single`,
//! `multiple`, `direct`) moves, so that the component to improve is named
//! (since 2026-12-07, when `slab` got its `single`). Values below
//! `1e-3` of the sheet's largest in-plane value are left out of the relative
//! change (the far tails of a narrow lobe, where a relative change says
//! nothing a renderer sees).
//!
//! `cargo run --release -p paperbsdf-slab --example convergence [--nodes N] [CASE...]`
//! (optional case names, e.g. `thin-tissue devB`: only those cases;
//! `--nodes N`: `N` nodes and `N / 2` in the cone instead of the default's
//! 32 and 16, against twice as many, for how the change falls with the
//! nodes; `--g-f G`: the forward lobe's asymmetry `g_f` of every case set
//! to `G`; `--m M`: both faces' roughness set to `M`, 0 for smooth faces;
//! `--eta-f E` and `--eta-b E`: the front's and the base's index set to
//! `E` (a coated front where they differ, docs/design.md 4.1);
//! the base build's time is printed).

use paperbsdf_core::bsdf::albedo_from;
use paperbsdf_core::geometry::in_plane_directions;
use paperbsdf_core::models::ComponentModel;
use paperbsdf_core::{Bsdf, FaceScattering, PaperParams};
use paperbsdf_slab::{SlabBsdf, SlabOptions};

// The cases of docs/accuracy.md, as the accuracy example has them.
#[path = "../../sim/examples/support/cases.rs"]
mod cases;

/// An in-plane point: `theta_i`, transmission, `theta_o` (degrees).
type Point = (f64, bool, f64);

/// In-plane values (mean over channels) and the points they belong to.
fn in_plane(b: &SlabBsdf) -> (Vec<f64>, Vec<Point>) {
    let mut v = Vec::new();
    let mut at = Vec::new();
    for ti in (0..=160).map(|k| 0.5 * k as f64) {
        for tr in [false, true] {
            for to in (-160..=160).map(|k| 0.5 * k as f64) {
                let (wi, wo) = in_plane_directions(ti, to, tr);
                v.push(b.eval(wi, wo).mean());
                at.push((ti, tr, to));
            }
        }
    }
    (v, at)
}

/// How an in-plane point is printed.
fn show((ti, tr, to): Point) -> String {
    format!("{ti} {} {to}", if tr { "T" } else { "R" })
}

/// The band of a point: within 5 degrees of the normal (either direction),
/// 5 to 15, further out.
fn band((ti, _, to): Point) -> usize {
    let near = ti.min(to.abs());
    if near < 5.0 {
        0
    } else if near < 15.0 {
        1
    } else {
        2
    }
}

fn albedos(b: &SlabBsdf) -> Vec<f64> {
    [0.0f64, 30.0, 60.0, 75.0]
        .iter()
        .flat_map(|t| {
            let t = t.to_radians();
            let (r, tr) = albedo_from(b, paperbsdf_core::DVec3::new(t.sin(), 0.0, t.cos()), 256);
            [r.mean(), tr.mean()]
        })
        .collect()
}

fn main() {
    let mut only: Vec<String> = std::env::args().skip(1).collect();
    let mut base = SlabOptions::default();
    if let Some(k) = only.iter().position(|a| a == "--nodes") {
        let n: usize = match only.get(k + 1).map(|v| v.parse()) {
            Some(Ok(n)) if n >= 4 => n,
            _ => {
                eprintln!("--nodes needs a whole number of nodes, at least 4");
                std::process::exit(2);
            }
        };
        base.nodes = n;
        base.tir_nodes = n / 2;
        only.drain(k..k + 2);
    }
    // `--g-f G` and `--m M`: a value taken from the arguments.
    let mut value_of = |flag: &str, range: std::ops::RangeInclusive<f64>| -> Option<f64> {
        let k = only.iter().position(|a| a == flag)?;
        match only.get(k + 1).map(|v| v.parse::<f64>()) {
            Some(Ok(v)) if range.contains(&v) => {
                only.drain(k..k + 2);
                Some(v)
            }
            _ => {
                eprintln!("{flag} needs a number in [{}, {}]", range.start(), range.end());
                std::process::exit(2);
            }
        }
    };
    let g_f = value_of("--g-f", -0.98..=0.98);
    let m = value_of("--m", 0.0..=1.5);
    let eta_f = value_of("--eta-f", 1.0..=5.0);
    let eta_b = value_of("--eta-b", 1.0..=5.0);
    let cases: Vec<_> = cases::cases()
        .into_iter()
        .filter(|(n, _)| only.is_empty() || only.contains(n))
        .map(|(n, p)| {
            let p = PaperParams {
                g_f: g_f.unwrap_or(p.g_f),
                m_f: m.unwrap_or(p.m_f),
                m_b: m.unwrap_or(p.m_b),
                eta_f: eta_f.unwrap_or(p.eta_f),
                eta_b: eta_b.unwrap_or(p.eta_b),
                ..p
            };
            (n, p)
        })
        .collect();
    let variants = [
        (
            "nodes x2",
            SlabOptions {
                nodes: 2 * base.nodes,
                tir_nodes: 2 * base.tir_nodes,
                ..base
            },
        ),
        (
            "orders x2",
            SlabOptions {
                orders: 2 * base.orders,
                walk_orders: 2 * base.walk_orders,
                ..base
            },
        ),
    ];
    for faces in [FaceScattering::Multiple, FaceScattering::Single] {
        for (name, p) in &cases {
            let p = PaperParams {
                face_scattering: faces,
                ..p.clone()
            };
            let t0 = std::time::Instant::now();
            let b0 = SlabBsdf::with_options(&p, &base).expect("build");
            println!(
                "{:8} {name:14} {} nodes: build {:.2} s",
                faces.name(),
                base.nodes,
                t0.elapsed().as_secs_f64()
            );
            let (v0, at) = in_plane(&b0);
            let a0 = albedos(&b0);
            let floor = 1e-3 * v0.iter().cloned().fold(0.0, f64::max);
            for (vname, opts) in &variants {
                let b1 = SlabBsdf::with_options(&p, opts).expect("build");
                let (v1, _) = in_plane(&b1);
                let a1 = albedos(&b1);
                let (mut worst, mut where_, mut sum, mut n) = (0.0f64, (0.0, false, 0.0), 0.0, 0);
                let mut bands = [0.0f64; 3];
                for ((x, y), &w) in v0.iter().zip(&v1).zip(&at) {
                    if x.max(*y) < floor {
                        continue;
                    }
                    let r = (y / x - 1.0).abs();
                    sum += r * r;
                    n += 1;
                    let b = &mut bands[band(w)];
                    *b = b.max(r);
                    if r > worst {
                        worst = r;
                        where_ = w;
                    }
                }
                let da = a0.iter().zip(&a1).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
                println!(
                    "{:8} {name:14} {vname:9}: largest {:.2}% at ({}); <5 deg {:.2}%, 5-15 {:.2}%, beyond {:.2}%; RMS {:.3}%, albedo {:.1e}",
                    faces.name(),
                    100.0 * worst,
                    show(where_),
                    100.0 * bands[0],
                    100.0 * bands[1],
                    100.0 * bands[2],
                    100.0 * (sum / n as f64).sqrt(),
                    da
                );
                // What each component moves at that point.
                let (ti, tr, to) = where_;
                let (wi, wo) = in_plane_directions(ti, to, tr);
                let moves: Vec<String> = b0
                    .components()
                    .iter()
                    .map(|&c| {
                        let d = b1.eval_component(wi, wo, c).mean() - b0.eval_component(wi, wo, c).mean();
                        format!("{} {d:+.2e}", c.name())
                    })
                    .collect();
                println!(
                    "{:8} {name:14} {vname:9}: there the value moves by {:+.2e}: {}",
                    faces.name(),
                    b1.eval(wi, wo).mean() - b0.eval(wi, wo).mean(),
                    moves.join(", ")
                );
            }
        }
    }
}
