//! Next-event estimation of `f(wi, wo)` for the walk (the estimator of
//! [`crate::walk`]'s module doc, sections "The BSDF value by next-event
//! estimation" and "Cost, without bias"): the requested viewing directions
//! and how light reaches each through its exit face, the two strategies at a
//! vertex (the exit face's BSDF sampled from `wo` and the direction the walk
//! drew), their combination by the balance heuristic (Veach 1997, section
//! 9.2), the closed-form series of internal mirror reflections before a delta
//! exit, and Russian roulette on small contributions.

use super::{Tally, Tracer};
use crate::faces::{FaceOptics, StochFace};
use crate::slab::{Side, Slab};
use paperbsdf_core::{DVec3, RoughDielectric, TransportMode};
use rand::Rng;
use std::f64::consts::PI;

/// Next-event contributions whose bound is below this are subject to Russian
/// roulette (played with survival probability bound / NEE_RR_SCALE): deep
/// vertices seen through many mean free paths cost almost nothing.
const NEE_RR_SCALE: f64 = 2e-3;
/// Volume vertices use MIS for a rough exit only when the phase function's
/// peak density exceeds this fraction of the exit lobe's typical density.
const MIS_PHASE_RATIO: f64 = 1.0;

/// How light leaves the slab toward one requested viewing direction.
#[derive(Clone, Copy, Debug)]
pub(super) enum Exit {
    /// A rough single-scattering exit face: both NEE strategies.
    Rough(RoughDielectric),
    /// A face that is sampled exactly but only estimated (multiple scattering
    /// or a coating): one NEE strategy at a time.
    Stoch(StochFace),
    /// A smooth or index-matched exit face (or film): the only inside direction
    /// that reaches `wo` is `-w_s` (propagation), with radiance factor `t_rad`;
    /// `r_x`, `r_y` are the delta reflectances inside the exit face and the
    /// other face for light along that direction and its mirror image (chains
    /// of internal mirror reflections before the exit).
    Delta { w_s: DVec3, t_rad: f64, r_x: f64, r_y: f64 },
    /// No light reaches `wo` through this face (cannot happen from air).
    Blocked,
}

/// One draw of the exit face's BSDF sampled from `wo` (radiance transport):
/// the propagation direction inside that reaches `wo` (slab frame), the BSDF
/// value and the density. `p2 = 0` marks a draw that produced no inside
/// direction (a reflection sample or a failed draw): it contributes zero.
#[derive(Clone, Copy, Debug)]
pub(super) struct ExitDraw {
    w: DVec3,
    f: f64,
    p2: f64,
}

/// One requested viewing direction `wo`.
#[derive(Clone, Debug)]
pub(super) struct Target {
    /// The face through which the slab is seen from `wo`.
    pub(super) face: Side,
    /// `wo` in that face's local frame (`z > 0`).
    pub(super) wo_l: DVec3,
    exit: Exit,
    /// Pre-drawn exit samples (empty: draw afresh at every vertex).
    pub(super) pool: Vec<ExitDraw>,
    /// A typical exit BSDF value (mean over transmitted draws), the scale of
    /// next-event contributions for Russian roulette.
    f_scale: f64,
    /// Whether volume vertices combine both strategies by MIS for this target
    /// (see [`Tracer::calibrate_targets`]); otherwise only the exit-face strategy is used there.
    mis_volume: bool,
}

/// A vertex of the walk that sends light into the slab.
#[derive(Clone, Copy, Debug)]
pub(super) enum Vertex {
    /// A scattering event at depth `z` of light propagating along `prev`.
    Volume { z: f64, prev: DVec3 },
    /// A surface event at `face` for light arriving from `w_from_l` (face-local,
    /// pointing away from the surface toward where the light came from).
    Surface { face: Side, w_from_l: DVec3 },
}

impl Target {
    /// The target for viewing direction `wo` (unit, slab frame, `wo.z != 0`):
    /// the face it sees and how light leaves through it (before calibration,
    /// see [`Tracer::calibrate_targets`]).
    pub(super) fn new(slab: &Slab, wo: DVec3) -> Self {
        let face = Side::of(wo);
        let wo_l = face.local(wo);
        let exit = match *slab.face(face) {
            FaceOptics::Walter(b) => Exit::Rough(b),
            FaceOptics::Stochastic(s) => Exit::Stoch(s),
            FaceOptics::Delta(df) => match df.lobes(wo_l, TransportMode::Radiance) {
                (_, t_rad, Some(dir_l)) if t_rad > 0.0 => {
                    let w_s = face.local(dir_l);
                    let w = -w_s;
                    let wm = DVec3::new(w.x, w.y, -w.z);
                    let y = face.other();
                    Exit::Delta {
                        w_s,
                        t_rad,
                        r_x: slab.face(face).delta_reflectance_inside(face.local(-w)),
                        r_y: slab.face(y).delta_reflectance_inside(y.local(-wm)),
                    }
                }
                _ => Exit::Blocked,
            },
        };
        Target {
            face,
            wo_l,
            exit,
            pool: Vec::new(),
            f_scale: 0.0,
            mis_volume: true,
        }
    }
}

impl Tracer<'_> {
    /// Sets each target's scale for Russian roulette and whether volume
    /// vertices use MIS for it, from a fixed set of 256 exit draws (a
    /// generator of its own, so that the walks' random numbers do not depend
    /// on it).
    pub(super) fn calibrate_targets(&mut self) {
        // Whether the phase function's peak is comparable to the exit lobe's
        // typical density (E[p2] under its own sampling): only then can
        // phase sampling beat exit sampling at a volume vertex, and only then is
        // its evaluation (a BSDF eval and pdf per target) worth its cost.
        // The peak of `w HG(g)` is at `cos = sign(g)`: `w (1 + |g|) / (4 pi (1 - |g|)^2)`.
        let phase_peak: f64 = self
            .smooth
            .lobes()
            .iter()
            .map(|&(g, w)| w * (1.0 + g.abs()) / (4.0 * PI * (1.0 - g.abs()).powi(2)))
            .sum();
        let mut rng = rand_pcg::Pcg64Mcg::new(0x5eed);
        for tg in &mut self.targets {
            let draws = draw_exits(tg, 256, &mut rng);
            // No transmitted draw among 256: never play roulette on this target.
            tg.f_scale = match f_scale(&draws) {
                f if f > 0.0 => f,
                _ => f64::INFINITY,
            };
            let (sp, n) = draws
                .iter()
                .filter(|e| e.p2 > 0.0)
                .fold((0.0, 0usize), |(s, n), e| (s + e.p2, n + 1));
            tg.mis_volume = n == 0 || phase_peak > MIS_PHASE_RATIO * sp / n as f64;
            self.any_mis_volume |= tg.mis_volume && matches!(tg.exit, Exit::Rough(_));
        }
    }

    /// The vertex's flux density `q_v(w)` into propagation direction `w`
    /// (non-delta part; an unbiased estimate at a stochastic face) and the
    /// density with which the walk draws `w` (0 where it is not known: then
    /// only the exit strategy is used).
    #[inline]
    pub(super) fn q_p<R: Rng>(&self, v: Vertex, w: DVec3, rng: &mut R) -> (f64, f64) {
        match v {
            Vertex::Volume { prev, .. } => {
                let q = self.smooth.eval(prev.dot(w));
                (q, q)
            }
            Vertex::Surface { face, w_from_l } => {
                let wl = face.local(w);
                match self.slab.face(face) {
                    FaceOptics::Walter(b) => {
                        let q = b.eval_mode(wl, w_from_l, TransportMode::Importance) * w.z.abs();
                        if q == 0.0 {
                            return (0.0, 0.0);
                        }
                        (q, b.pdf_dir(wl, w_from_l))
                    }
                    FaceOptics::Stochastic(s) => {
                        let mut rnd = || rng.gen::<f64>();
                        let q = s.eval(wl, w_from_l, TransportMode::Importance, &mut rnd) * w.z.abs();
                        (q, 0.0)
                    }
                    FaceOptics::Delta(_) => (0.0, 0.0),
                }
            }
        }
    }

    /// Next-event estimation by sampling the exit face from `wo` (and the only
    /// strategy for a delta exit face), for every target reachable from `v`.
    pub(super) fn nee_exit<R: Rng>(&self, v: Vertex, weight: f64, rng: &mut R, tally: &mut Tally) {
        let z = self.depth(v);
        let d = self.slab.d;
        let at_face = match v {
            Vertex::Surface { face, .. } => Some(face),
            Vertex::Volume { .. } => None,
        };
        for (j, t) in self.targets.iter().enumerate() {
            let own_face = at_face == Some(t.face);
            if own_face && !matches!(t.exit, Exit::Delta { r_y, .. } if r_y > 0.0) {
                continue;
            }
            let dz = (z - t.face.z(d)).abs();
            match t.exit {
                Exit::Rough(_) | Exit::Stoch(_) => {
                    let e = if t.pool.is_empty() {
                        draw_exit(t, rng)
                    } else {
                        t.pool[rng.gen_range(0..t.pool.len())]
                    };
                    if e.p2 == 0.0 {
                        continue;
                    }
                    let tr = self.transmittance(dz, e.w);
                    // Contribution <= weight * tr * f (the MIS factor q / (q + p2) <= 1).
                    let Some(rr) = nee_roulette(weight * tr * e.f, rng) else {
                        continue;
                    };
                    let (q, p1) = self.q_p(v, e.w, rng);
                    if q <= 0.0 {
                        continue;
                    }
                    // (f / p2) * p2 / (p1 + p2) with MIS, f / p2 without (a
                    // stochastic exit stores f / p2 as `f` with `p2 = 1`).
                    let p1 =
                        if matches!(t.exit, Exit::Rough(_)) && (t.mis_volume || matches!(v, Vertex::Surface { .. })) {
                            p1
                        } else {
                            0.0
                        };
                    let c = rr * weight * q * tr * e.f / (p1 + e.p2);
                    if c.is_finite() {
                        tally.add_f(j, c);
                    }
                }
                Exit::Delta { w_s, t_rad, r_x, r_y } => {
                    let w = -w_s;
                    let a = w.z.abs();
                    // Light along w reaches the exit directly (n = 0) or after n
                    // round trips of mirror reflections inside (factor r_x r_y
                    // and 2 d of depth each); light along the mirror image first
                    // meets the other face (factor r_y, depth |z - z_y| + d).
                    let round = r_x * r_y;
                    let series = if round > 0.0 {
                        1.0 / (1.0 - round * self.transmittance(2.0 * d, w))
                    } else {
                        1.0
                    };
                    if !own_face {
                        let (q, _) = self.q_p(v, w, rng);
                        if q > 0.0 {
                            let c = weight * q * self.transmittance(dz, w) * t_rad / a;
                            tally.add_f(j, c * series);
                        }
                    }
                    let from_other_face = at_face == Some(t.face.other());
                    if r_y > 0.0 && !from_other_face {
                        let wm = DVec3::new(w.x, w.y, -w.z);
                        let (q, _) = self.q_p(v, wm, rng);
                        if q > 0.0 {
                            let dy = (z - t.face.other().z(d)).abs() + d;
                            let c = weight * q * r_y * self.transmittance(dy, w) * t_rad / a;
                            tally.add_f(j, c * series);
                        }
                    }
                }
                Exit::Blocked => {}
            }
        }
    }

    /// Next-event estimation along the direction `w` the walk drew at `v` (or a
    /// delta lobe's direction, `p1 = None`, weighted by the lobe's expected
    /// value), for the rough targets on the face `w` heads for.
    pub(super) fn nee_dir<R: Rng>(
        &self,
        v: Vertex,
        weight: f64,
        w: DVec3,
        p1: Option<f64>,
        rng: &mut R,
        tally: &mut Tally,
    ) {
        if w.z == 0.0 || weight == 0.0 {
            return;
        }
        let x = Side::of(w);
        let dz = (self.depth(v) - x.z(self.slab.d)).abs();
        let mut tr = f64::NAN;
        for (j, t) in self.targets.iter().enumerate() {
            if t.face != x {
                continue;
            }
            let stoch = match t.exit {
                Exit::Rough(_) => None,
                // A stochastic exit has no density for MIS: exit sampling covers
                // it at every vertex that has a density, this strategy at delta ones.
                Exit::Stoch(s) if p1.is_none() => Some(s),
                _ => continue,
            };
            if p1.is_some() && !t.mis_volume && matches!(v, Vertex::Volume { .. }) {
                continue; // exit sampling alone covers this target at volume vertices
            }
            if tr.is_nan() {
                tr = self.transmittance(dz, w);
            }
            let Some(rr) = nee_roulette(weight * tr * t.f_scale, rng) else {
                continue;
            };
            let ws_l = x.local(-w);
            let f = match (stoch, t.exit) {
                (Some(s), _) => {
                    let mut rnd = || rng.gen::<f64>();
                    s.eval(ws_l, t.wo_l, TransportMode::Radiance, &mut rnd)
                }
                (None, Exit::Rough(b)) => b.eval_mode(ws_l, t.wo_l, TransportMode::Radiance),
                _ => 0.0,
            };
            if f == 0.0 {
                continue;
            }
            let mis = match (p1, t.exit) {
                (Some(p1), Exit::Rough(b)) => p1 / (p1 + b.pdf_dir(ws_l, t.wo_l)),
                _ => 1.0,
            };
            let c = rr * weight * tr * f * mis;
            if c.is_finite() {
                tally.add_f(j, c);
            }
        }
    }
}

/// Russian roulette on a next-event contribution bounded by about `bound`:
/// `Some(1 / survival)` when it is to be evaluated, `None` when it is skipped.
#[inline]
fn nee_roulette<R: Rng>(bound: f64, rng: &mut R) -> Option<f64> {
    if bound.is_nan() || bound >= NEE_RR_SCALE {
        return Some(1.0);
    }
    if bound <= 0.0 {
        return None; // the contribution is zero
    }
    let survive = bound / NEE_RR_SCALE;
    if rng.gen::<f64>() < survive {
        Some(1.0 / survive)
    } else {
        None
    }
}

/// One draw of a rough exit face sampled from the target's `wo`. For a
/// stochastic face (no density known) the draw stores `f / p2 = weight / |cos|`
/// as `f` with `p2 = 1`.
fn draw_exit<R: Rng>(t: &Target, rng: &mut R) -> ExitDraw {
    let none = ExitDraw {
        w: DVec3::ZERO,
        f: 0.0,
        p2: 0.0,
    };
    match t.exit {
        Exit::Rough(b) => {
            let (uc, u0, u1) = (rng.gen(), rng.gen(), rng.gen());
            match b.sample_mode(t.wo_l, uc, [u0, u1], TransportMode::Radiance) {
                Some(s) if s.wi.z < 0.0 && s.pdf > 0.0 && s.f.0[0] > 0.0 && s.f.0[0].is_finite() => ExitDraw {
                    w: -t.face.local(s.wi),
                    f: s.f.0[0],
                    p2: s.pdf,
                },
                _ => none,
            }
        }
        Exit::Stoch(sf) => {
            let mut rnd = || rng.gen::<f64>();
            match sf.sample(t.wo_l, TransportMode::Radiance, &mut rnd) {
                Some(s) if s.dir.z < 0.0 && s.weight > 0.0 && s.weight.is_finite() => ExitDraw {
                    w: -t.face.local(s.dir),
                    f: s.weight / s.dir.z.abs(),
                    p2: 1.0,
                },
                _ => none,
            }
        }
        _ => none,
    }
}

/// `n` independent draws of a target's exit face (empty for a delta exit).
pub(super) fn draw_exits<R: Rng>(t: &Target, n: usize, rng: &mut R) -> Vec<ExitDraw> {
    if !matches!(t.exit, Exit::Rough(_) | Exit::Stoch(_)) {
        return Vec::new();
    }
    (0..n).map(|_| draw_exit(t, rng)).collect()
}

/// Mean BSDF value of the transmitted draws (0 when there are none).
fn f_scale(d: &[ExitDraw]) -> f64 {
    let (s, n) = d
        .iter()
        .filter(|e| e.p2 > 0.0)
        .fold((0.0, 0usize), |(s, n), e| (s + e.f, n + 1));
    if n == 0 {
        0.0
    } else {
        s / n as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use paperbsdf_core::Distribution;
    use rand::SeedableRng;

    /// The estimator uses `eval_mode(a, b, Importance) = eval_mode(b, a, Radiance)`
    /// (the adjoint BSDF, Veach 1997 section 5.2) to turn the exit face's
    /// radiance BSDF sampled from `wo` into the flux it lets out toward `wo`.
    #[test]
    fn importance_eval_is_the_adjoint_of_radiance_eval() {
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(1);
        for (dist, eta, m) in [
            (Distribution::Ggx, 1.45, 0.35),
            (Distribution::Beckmann, 1.6, 0.1),
            (Distribution::Ggx, 2.5, 0.9),
        ] {
            let b = RoughDielectric::new(dist, eta, m).unwrap();
            let mut nonzero = 0;
            for _ in 0..2000 {
                let a = paperbsdf_core::geometry::sample_uniform_sphere([rng.gen(), rng.gen()]);
                let c = paperbsdf_core::geometry::sample_uniform_sphere([rng.gen(), rng.gen()]);
                let x = b.eval_mode(a, c, TransportMode::Importance);
                let y = b.eval_mode(c, a, TransportMode::Radiance);
                assert!((x - y).abs() <= 1e-12 * x.abs().max(1.0), "{a} {c}: {x} vs {y}");
                nonzero += (x > 0.0) as usize;
            }
            assert!(nonzero > 100);
        }
    }

    #[test]
    fn nee_roulette_is_unbiased() {
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(2);
        for bound in [1e-5, 3e-4, 1.5e-3, 0.1] {
            let n = 400_000;
            let s: f64 = (0..n).map(|_| nee_roulette(bound, &mut rng).unwrap_or(0.0)).sum();
            let mean = s / n as f64;
            // Bernoulli(p) / p: relative standard error sqrt((1 - p) / (p n)).
            let p = (bound / NEE_RR_SCALE).min(1.0);
            let se = ((1.0 - p) / (p * n as f64)).sqrt();
            assert!(
                (mean - 1.0).abs() <= 4.0 * se + 1e-12,
                "bound {bound}: {mean} (se {se})"
            );
        }
        assert_eq!(nee_roulette(0.0, &mut rng), None);
    }
}
