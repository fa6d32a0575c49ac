//! One random walk of light through the slab, and the estimators it feeds.
//!
//! # The walk (light tracing in depth only)
//! Light arrives from direction `wi` (pointing toward the light) at the face
//! it faces, carrying unit flux. Every event is sampled exactly from the
//! physical system: surface events from the face's BSDF in importance
//! transport ([`crate::faces`]: Walter's [`RoughDielectric::sample_mode`], the
//! microsurface walk, or the sub-walk through a front coating, whose weight is
//! the fraction of flux carried; smooth and index-matched faces and smooth
//! coatings are delta events), free paths
//! from `sigma_t` (Beer-Lambert), scattering directions from the phase
//! function. Absorption is implicit (the weight is multiplied by the albedo at
//! each collision) with Russian roulette below a weight of 0.01. Only depth
//! matters: the slab is laterally infinite; the lateral offset is tracked only
//! to report where light leaves ([`Tracer::walk_with_exits_at`], for [`crate::lateral`]).
//!
//! # Totals
//! The flux that leaves through the lit face is the reflectance `R`, through the
//! other face the transmittance `T` (both include everything: surface
//! reflection, unscattered light, all orders of scattering).
//!
//! # The BSDF value by next-event estimation
//! For a laterally infinite slab lit by a collimated beam of unit irradiance
//! (perpendicular to the beam), the flux per unit area entering is
//! `|cos wi|`, and the radiance leaving toward `wo` is `|cos wi| q(wo) / |cos wo|`,
//! where `q(wo)` is the flux density per steradian of the exit direction per unit
//! incident flux. So `f(wi, wo) = q(wo) / |cos wo|`: no angular binning is
//! needed if `q` is estimated by next-event estimation. A vertex (a volume
//! scattering or a surface event) that sends flux into directions `w` inside with
//! density `q_v(w)` (the phase function, or `f_imp(w, w_from) |cos w|` of a face)
//! contributes, through the exit face `x` at depth distance `dz`,
//!
//! `C = W * integral q_v(w) exp(-sigma_t dz / |w_z|) f_x(-w -> wo) dw`,
//!
//! where `f_x(-w -> wo) = eval_mode(-w, wo, Radiance)` of face `x` (the flux
//! density per steradian leaving toward `wo` is that times `|cos wo|`, which
//! cancels against the `1 / |cos wo|` above). The integral is estimated by
//! multiple importance sampling (balance heuristic, Veach 1997) of two
//! strategies: the direction the walk itself draws from `q_v` (no extra cost),
//! and a direction drawn from the exit face's own BSDF sampled from `wo`
//! (the camera-side strategy of a volumetric path tracer). Delta lobes are
//! handled by their only strategy: a smooth or index-matched exit face by the
//! refraction of `wo`, a smooth face vertex or a `|g| = 1` lobe by its
//! expected value. A delta exit is reached directly or after any number of
//! mirror reflections inside (at smooth faces, or at a coating's smooth
//! boundary with the base): their geometric series is summed in closed form.
//! Faces whose value is only estimated ([`crate::faces::FaceOptics::Stochastic`]:
//! multiple scattering, coatings) have no density for MIS and use one strategy:
//! exit sampling (the face sampled from `wo`, weight `f |cos| / pdf`) from every
//! vertex with a known or estimated density, and the vertex's own sampled
//! direction with an unbiased estimate of the exit face's value from delta
//! vertices. Paths whose every event is a delta (the mirror reflection of
//! a smooth face, unscattered light through two smooth faces) are Dirac deltas
//! in `wo` and, as in `Bsdf::eval`, are not part of `f`; they are in the totals.
//! Add to this the direct Walter reflection of the lit face when `wo` is on the
//! lit side. The result is unbiased with no angular binning.
//!
//! The same vertex contributes to every requested `wo`, so one set of walks
//! estimates a whole in-plane curve (reflection and transmission) for one `wi`.
//!
//! # Cost, without bias
//! - The phase-sampling strategy needs a BSDF evaluation per target and vertex;
//!   it is used at volume vertices only when the phase function's peak density
//!   is comparable to the exit lobe's typical density (a strongly forward
//!   phase function behind a rough face). Otherwise the exit-sampling strategy
//!   alone is unbiased with bounded weights: with visible-normal sampling
//!   `f / p2 <= 1 / |cos|`, so a contribution is at most `p_max T / |cos|`.
//! - Exit draws depend only on `wo`, so a batch may pre-draw a pool of them
//!   ([`Tracer::with_exit_pool`]) and pick one at random per vertex.
//! - A contribution whose bound (weight x transmittance x exit BSDF) is below
//!   `NEE_RR_SCALE` is evaluated with probability bound / `NEE_RR_SCALE` and
//!   divided by it (Russian roulette): vertices deep in the slab, seen through
//!   many mean free paths, then cost almost nothing.
//!
//! # Radiance and flux
//! With `f_imp(a, b) = eval_mode(a, b, Importance) = eval_mode(b, a, Radiance)`
//! (the adjoint of Veach 1997, section 5.2), the light-tracing estimator here
//! and a camera-side volumetric path tracer (Mitsuba's `volpath`) estimate the
//! same integral. With `eta_f != eta_b` the sheet has a front coating
//! (`paperbsdf_core::sheet`) and is reciprocal like any other; Mitsuba's
//! references for such parameters (devB) put a medium of index `eta_f` behind
//! the front and `eta_b` before the back instead (a prism-like slab), a
//! different physical system.

use crate::faces::{FaceOptics, StochFace};
use crate::slab::{Face, Medium, Slab};
use paperbsdf_core::phase::{sample_hg_cos, HgLobes};
use paperbsdf_core::{DVec3, RoughDielectric, TransportMode};
use rand::Rng;
use std::f64::consts::PI;

/// Weight below which Russian roulette is played.
const RR_THRESHOLD: f64 = 0.01;

/// Default number of scattering events after which a walk is cut (counted in
/// [`Tally::truncated`]; [`Tracer::with_max_collisions`] and
/// [`crate::SimConfig::max_collisions_per_walk`] set another cap). A walk in a
/// nearly conservative slab of optical thickness `tau` takes about `tau^2`
/// collisions to cross it, so this cuts nothing below `tau` of about 3000, far
/// beyond paper (`tau` of 10 to 100); it bounds the work of absurd inputs
/// (`sigma_s = 1e308`), whose walks have a heavy-tailed length.
pub const MAX_COLLISIONS_PER_WALK: usize = 10_000_000;
/// Next-event contributions whose bound is below this are subject to Russian
/// roulette (played with survival probability bound / NEE_RR_SCALE): deep
/// vertices seen through many mean free paths cost almost nothing.
const NEE_RR_SCALE: f64 = 2e-3;
/// Volume vertices use MIS for a rough exit only when the phase function's
/// peak density exceeds this fraction of the exit lobe's typical density.
const MIS_PHASE_RATIO: f64 = 1.0;
/// Survival probability of Russian roulette.
const RR_SURVIVAL: f64 = 0.1;

/// How light leaves the slab toward one requested viewing direction.
#[derive(Clone, Copy, Debug)]
enum Exit {
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
struct ExitDraw {
    w: DVec3,
    f: f64,
    p2: f64,
}

/// One requested viewing direction `wo`.
#[derive(Clone, Debug)]
struct Target {
    /// The face through which the slab is seen from `wo`.
    face: Face,
    /// `wo` in that face's local frame (`z > 0`).
    wo_l: DVec3,
    exit: Exit,
    /// Pre-drawn exit samples (empty: draw afresh at every vertex).
    pool: Vec<ExitDraw>,
    /// A typical exit BSDF value (mean over transmitted draws), the scale of
    /// next-event contributions for Russian roulette.
    f_scale: f64,
    /// Whether volume vertices combine both strategies by MIS for this target
    /// (see [`Tracer::new`]); otherwise only the exit-face strategy is used there.
    mis_volume: bool,
}

/// A vertex of the walk that sends light into the slab.
#[derive(Clone, Copy, Debug)]
enum Vertex {
    /// A scattering event at depth `z` of light propagating along `prev`.
    Volume { z: f64, prev: DVec3 },
    /// A surface event at `face` for light arriving from `w_from_l` (face-local,
    /// pointing away from the surface toward where the light came from).
    Surface { face: Face, w_from_l: DVec3 },
}

/// Per-walk sums: BSDF contributions per target, reflected and transmitted flux.
#[derive(Clone, Debug, Default)]
pub struct Tally {
    /// Sum of next-event contributions to `f(wi, wo_j)` per requested `wo_j`.
    pub f: Vec<f64>,
    /// Flux that left through the lit face.
    pub r: f64,
    /// Flux that left through the other face.
    pub t: f64,
    /// Number of scattering events (collisions with scattering) in the walk(s).
    pub collisions: u64,
    /// Walks cut at the tracer's collision cap ([`Tracer::max_collisions`],
    /// [`MAX_COLLISIONS_PER_WALK`] by default). A cut walk ends there: its
    /// remaining flux (its weight at the cut, at most 1 each) is added to
    /// neither `r`, `t` nor `f`, so it is missing from every estimate.
    pub truncated: u64,
    /// When `Some`, the contributions to `f` split by the number of volume
    /// scattering events on the path: `[0, 1, 2 or more]` per viewing direction
    /// (0: surface reflection and unscattered light, including internal
    /// reflections; 1: single scattering; the rest: multiple scattering).
    pub by_order: Option<Vec<[f64; 3]>>,
    /// Scattering events so far in the current walk (set by the walk).
    order: usize,
}

impl Tally {
    /// A zero tally for `n` viewing directions.
    pub fn new(n: usize) -> Self {
        Tally {
            f: vec![0.0; n],
            r: 0.0,
            t: 0.0,
            collisions: 0,
            truncated: 0,
            by_order: None,
            order: 0,
        }
    }
    /// Adds `o` into `self`.
    pub fn add(&mut self, o: &Tally) {
        for (a, b) in self.f.iter_mut().zip(&o.f) {
            *a += b;
        }
        self.r += o.r;
        self.t += o.t;
        self.collisions += o.collisions;
        self.truncated += o.truncated;
        if let (Some(a), Some(b)) = (self.by_order.as_mut(), o.by_order.as_ref()) {
            for (x, y) in a.iter_mut().zip(b) {
                for k in 0..3 {
                    x[k] += y[k];
                }
            }
        }
    }

    /// A zero tally for `n` viewing directions that also splits `f` by scattering order.
    pub fn with_orders(n: usize) -> Self {
        Tally {
            by_order: Some(vec![[0.0; 3]; n]),
            ..Tally::new(n)
        }
    }

    /// Resets every sum to zero (keeping the sizes).
    pub fn clear(&mut self) {
        self.f.iter_mut().for_each(|v| *v = 0.0);
        if let Some(b) = self.by_order.as_mut() {
            b.iter_mut().for_each(|v| *v = [0.0; 3]);
        }
        self.r = 0.0;
        self.t = 0.0;
        self.collisions = 0;
        self.truncated = 0;
        self.order = 0;
    }

    #[inline]
    fn add_f(&mut self, j: usize, c: f64) {
        self.f[j] += c;
        if let Some(b) = self.by_order.as_mut() {
            b[j][self.order.min(2)] += c;
        }
    }
}

/// The random walk for one colour channel and a fixed set of viewing directions.
#[derive(Clone, Debug)]
pub struct Tracer<'a> {
    slab: &'a Slab,
    med: Medium,
    targets: Vec<Target>,
    /// The phase function's lobes `(g, weight)`, forward first
    /// ([`paperbsdf_core::phase::TwoLobeHg::lobes`]); those with `|g| = 1` are
    /// Dirac deltas along the propagation direction or against it.
    lobes: [(f64, f64); 2],
    /// The lobes with `|g| < 1`, whose density next-event estimation evaluates.
    smooth: HgLobes,
    /// Whether any rough target uses MIS at volume vertices.
    any_mis_volume: bool,
    /// Scattering events after which a walk is cut (at least 1).
    max_collisions: usize,
}

impl<'a> Tracer<'a> {
    /// A tracer for channel `channel` of `slab` and viewing directions `wos`
    /// (unit vectors, slab frame; `wo.z != 0`).
    pub fn new(slab: &'a Slab, channel: usize, wos: &[DVec3]) -> Self {
        let targets = wos
            .iter()
            .map(|&wo| {
                let face = Face::toward(wo);
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
            })
            .collect();
        let p = slab.phase();
        let mut t = Tracer {
            slab,
            med: slab.medium(channel),
            targets,
            lobes: p.lobes(),
            smooth: p.smooth_part(),
            any_mis_volume: false,
            max_collisions: MAX_COLLISIONS_PER_WALK,
        };
        // The scale of each rough exit for Russian roulette, from a fixed set of draws.
        // Whether the phase function's peak is comparable to the exit lobe's
        // typical density (E[p2] under its own sampling): only then can
        // phase sampling beat exit sampling at a volume vertex, and only then is
        // its evaluation (a BSDF eval and pdf per target) worth its cost.
        let phase_peak: f64 = t
            .smooth
            .lobes()
            .iter()
            .map(|&(g, w)| w * (1.0 + g.abs()) / (4.0 * PI * (1.0 - g.abs()).powi(2)))
            .sum();
        let mut rng = rand_pcg::Pcg64Mcg::new(0x5eed);
        for tg in &mut t.targets {
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
            t.any_mis_volume |= tg.mis_volume && matches!(tg.exit, Exit::Rough(_));
        }
        t
    }

    /// [`Tracer::new`] with a pool of `size` pre-drawn exit samples per rough
    /// exit, drawn from `rng`; every next-event estimate then picks a uniformly
    /// random member of the pool instead of sampling the exit face afresh.
    /// Each pick is still an exact draw, so the estimator stays unbiased; the
    /// pool is shared by all walks of a batch, so batches must each have their
    /// own pool for batch standard errors to be valid.
    pub fn with_exit_pool<R: Rng>(slab: &'a Slab, channel: usize, wos: &[DVec3], size: usize, rng: &mut R) -> Self {
        let mut t = Tracer::new(slab, channel, wos);
        for tg in &mut t.targets {
            tg.pool = draw_exits(tg, size, rng);
        }
        t
    }

    /// The tracer with walks cut after `cap` scattering events instead of
    /// [`MAX_COLLISIONS_PER_WALK`] (a cap of 0 is taken as 1: the first
    /// collision ends the walk). Each cut walk is counted in
    /// [`Tally::truncated`] and its remaining flux is dropped.
    pub fn with_max_collisions(mut self, cap: usize) -> Self {
        self.max_collisions = cap.max(1);
        self
    }

    /// Scattering events after which a walk is cut.
    pub fn max_collisions(&self) -> usize {
        self.max_collisions
    }

    /// Number of viewing directions.
    pub fn n_targets(&self) -> usize {
        self.targets.len()
    }

    /// Transmittance along `w` over a depth difference `dz`.
    #[inline]
    fn transmittance(&self, dz: f64, w: DVec3) -> f64 {
        if self.med.sigma_t == 0.0 {
            1.0
        } else {
            (-self.med.sigma_t * dz / w.z.abs()).exp()
        }
    }

    #[inline]
    fn depth(&self, v: Vertex) -> f64 {
        match v {
            Vertex::Volume { z, .. } => z,
            Vertex::Surface { face, .. } => face.z(self.slab.d),
        }
    }

    /// The vertex's flux density `q_v(w)` into propagation direction `w`
    /// (non-delta part; an unbiased estimate at a stochastic face) and the
    /// density with which the walk draws `w` (0 where it is not known: then
    /// only the exit strategy is used).
    #[inline]
    fn q_p<R: Rng>(&self, v: Vertex, w: DVec3, rng: &mut R) -> (f64, f64) {
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
    fn nee_exit<R: Rng>(&self, v: Vertex, weight: f64, rng: &mut R, tally: &mut Tally) {
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
    fn nee_dir<R: Rng>(&self, v: Vertex, weight: f64, w: DVec3, p1: Option<f64>, rng: &mut R, tally: &mut Tally) {
        if w.z == 0.0 || weight == 0.0 {
            return;
        }
        let x = Face::toward(w);
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

    /// A surface event at `face` for light arriving from `w_from_l` (face-local)
    /// with weight `weight`: next-event estimation, then the sampled event.
    /// Returns the new propagation direction and weight if the light stays in
    /// the slab; exits are added to the totals (`lit` is the lit face).
    #[allow(clippy::too_many_arguments)]
    fn surface_vertex<R: Rng, E: FnMut(DVec3, f64)>(
        &self,
        face: Face,
        w_from_l: DVec3,
        weight: f64,
        lit: Face,
        rng: &mut R,
        tally: &mut Tally,
        on_exit: &mut E,
    ) -> Option<(DVec3, f64)> {
        let v = Vertex::Surface { face, w_from_l };
        let from_outside = w_from_l.z > 0.0;
        let mut exit = |tally: &mut Tally, w: f64, dir_l: DVec3| {
            if face == lit {
                tally.r += w;
            } else {
                tally.t += w;
            }
            on_exit(face.local(dir_l), w);
        };
        match self.slab.face(face) {
            FaceOptics::Walter(b) => {
                self.nee_exit(v, weight, rng, tally);
                let (uc, u0, u1) = (rng.gen::<f64>(), rng.gen::<f64>(), rng.gen::<f64>());
                let s = b.sample_mode(w_from_l, uc, [u0, u1], TransportMode::Importance)?;
                let sw = s.weight().0[0];
                if !(sw.is_finite() && sw > 0.0) {
                    return None;
                }
                if s.wi.z > 0.0 {
                    exit(tally, weight * sw, s.wi);
                    return None;
                }
                let w = face.local(s.wi);
                let nw = weight * sw;
                self.nee_dir(v, nw, w, Some(s.pdf), rng, tally);
                Some((w, nw))
            }
            FaceOptics::Stochastic(sf) => {
                // Exit sampling covers the non-delta part of this face at every
                // target; its delta part (a coating's mirror reflection) is
                // covered along the sampled direction.
                self.nee_exit(v, weight, rng, tally);
                let mut rnd = || rng.gen::<f64>();
                let s = sf.sample(w_from_l, TransportMode::Importance, &mut rnd)?;
                if !(s.weight.is_finite() && s.weight > 0.0) {
                    return None;
                }
                let nw = weight * s.weight;
                if s.dir.z > 0.0 {
                    exit(tally, nw, s.dir);
                    return None;
                }
                let w = face.local(s.dir);
                if s.delta {
                    self.nee_dir(v, nw, w, None, rng, tally);
                }
                Some((w, nw))
            }
            FaceOptics::Delta(df) => {
                let (r, t, t_dir) = df.lobes(w_from_l, TransportMode::Importance);
                // Delta interface: the lobe into the slab and the lobe out of it.
                let mirror = DVec3::new(-w_from_l.x, -w_from_l.y, w_from_l.z);
                let (into, out) = if from_outside {
                    ((t, t_dir.unwrap_or(DVec3::ZERO)), (r, mirror))
                } else {
                    ((r, mirror), (t, t_dir.unwrap_or(DVec3::ZERO)))
                };
                let total = into.0 + out.0;
                if total <= 0.0 {
                    return None;
                }
                let w_into = face.local(into.1);
                if into.0 > 0.0 {
                    self.nee_dir(v, weight * into.0, w_into, None, rng, tally);
                }
                if rng.gen::<f64>() * total < into.0 {
                    Some((w_into, weight * total))
                } else {
                    exit(tally, weight * total, out.1);
                    None
                }
            }
        }
    }

    /// One walk of unit flux arriving from `wi` (unit, slab frame, `wi.z != 0`);
    /// adds its contributions to `tally`.
    pub fn walk<R: Rng>(&self, wi: DVec3, rng: &mut R, tally: &mut Tally) {
        self.walk_with_exits(wi, rng, tally, &mut |_, _| {});
    }

    /// [`Tracer::walk`], also reporting every exit of light from the slab to
    /// `on_exit(direction, flux)` (direction in the slab frame, pointing away
    /// from the slab): the analog estimator, for checks of the next-event one.
    pub fn walk_with_exits<R: Rng, E: FnMut(DVec3, f64)>(
        &self,
        wi: DVec3,
        rng: &mut R,
        tally: &mut Tally,
        on_exit: &mut E,
    ) {
        self.walk_with_exits_at(wi, rng, tally, &mut |w, f, _| on_exit(w, f));
    }

    /// [`Tracer::walk_with_exits`], also reporting where on the face each exit
    /// is: `on_exit(direction, flux, xy)` with `xy` the lateral offset (mm) of
    /// the exit point from the point of entry. Used by [`crate::lateral`].
    pub fn walk_with_exits_at<R: Rng, E: FnMut(DVec3, f64, glam::DVec2)>(
        &self,
        wi: DVec3,
        rng: &mut R,
        tally: &mut Tally,
        on_exit: &mut E,
    ) {
        let mut xy = glam::DVec2::ZERO;
        let d = self.slab.d;
        tally.order = 0;
        let lit = Face::lit_by(wi);
        let wi_l = lit.local(wi);
        // The lit face's own reflection toward viewers on its side.
        for (j, t) in self.targets.iter().enumerate() {
            if t.face == lit {
                let f = match self.slab.face(lit) {
                    FaceOptics::Walter(b) => b.eval_mode(wi_l, t.wo_l, TransportMode::Radiance),
                    FaceOptics::Stochastic(s) => {
                        let mut rnd = || rng.gen::<f64>();
                        s.eval(wi_l, t.wo_l, TransportMode::Radiance, &mut rnd)
                    }
                    FaceOptics::Delta(_) => 0.0,
                };
                tally.add_f(j, f);
            }
        }
        let Some((mut dir, mut weight)) =
            self.surface_vertex(lit, wi_l, 1.0, lit, rng, tally, &mut |w, f| on_exit(w, f, xy))
        else {
            return;
        };
        let mut z = lit.z(d);
        loop {
            if weight < RR_THRESHOLD {
                if rng.gen::<f64>() < RR_SURVIVAL {
                    weight /= RR_SURVIVAL;
                } else {
                    return;
                }
            }
            if dir.z == 0.0 {
                return; // parallel to the faces: measure zero
            }
            let x = Face::toward(dir);
            let dist = (x.z(d) - z) / dir.z;
            let t = if self.med.sigma_t > 0.0 {
                -(1.0 - rng.gen::<f64>()).ln() / self.med.sigma_t
            } else {
                f64::INFINITY
            };
            if t < dist {
                z = (z + t * dir.z).clamp(-d, 0.0);
                xy += t * dir.truncate();
                weight *= self.med.albedo;
                if weight == 0.0 {
                    return;
                }
                tally.collisions += 1;
                tally.order += 1;
                if tally.order >= self.max_collisions {
                    tally.truncated += 1;
                    return;
                }
                let v = Vertex::Volume { z, prev: dir };
                self.nee_exit(v, weight, rng, tally);
                let along = |g: f64| if g > 0.0 { dir } else { -dir };
                for (g, wl) in self.lobes {
                    if wl > 0.0 && g.abs() >= 1.0 {
                        self.nee_dir(v, weight * wl, along(g), None, rng, tally);
                    }
                }
                // Draw a lobe by its weight, delta lobes included (the forward
                // one for u < w_f / (w_f + w_b)), then a direction from it.
                let [(g0, w0), (g1, w1)] = self.lobes;
                let g = if rng.gen::<f64>() * (w0 + w1) < w0 { g0 } else { g1 };
                let is_delta = g.abs() >= 1.0;
                let new_dir = if is_delta {
                    along(g)
                } else {
                    let c = sample_hg_cos(g, rng.gen());
                    direction_at(dir, c, rng)
                };
                if !is_delta && self.any_mis_volume {
                    let p1 = self.smooth.eval(dir.dot(new_dir));
                    self.nee_dir(v, weight, new_dir, Some(p1), rng, tally);
                }
                dir = new_dir;
            } else {
                z = x.z(d);
                xy += dist * dir.truncate();
                let at = xy;
                match self.surface_vertex(x, x.local(-dir), weight, lit, rng, tally, &mut |w, f| on_exit(w, f, at)) {
                    Some((nd, nw)) => {
                        dir = nd;
                        weight = nw;
                    }
                    None => return,
                }
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
fn draw_exits<R: Rng>(t: &Target, n: usize, rng: &mut R) -> Vec<ExitDraw> {
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

/// The direction at cosine `cos` from unit `dir`, with a uniformly random
/// azimuth. The azimuth's cosine and sine come from a point drawn uniformly in
/// the unit disk by rejection, doubled in angle (`(x^2 - y^2, 2 x y) / r^2`),
/// which avoids trigonometric functions; the distribution is exactly uniform.
#[inline]
fn direction_at<R: Rng>(dir: DVec3, cos: f64, rng: &mut R) -> DVec3 {
    let (cp, sp) = loop {
        let x = 2.0 * rng.gen::<f64>() - 1.0;
        let y = 2.0 * rng.gen::<f64>() - 1.0;
        let r2 = x * x + y * y;
        if r2 <= 1.0 && r2 > 1e-12 {
            break ((x * x - y * y) / r2, 2.0 * x * y / r2);
        }
    };
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    let (t, b) = paperbsdf_core::geometry::coordinate_system(dir);
    // Unit up to rounding (t, b, dir orthonormal); renormalise only if it drifts.
    let w = sin * cp * t + sin * sp * b + cos * dir;
    let l2 = w.length_squared();
    if (l2 - 1.0).abs() > 1e-12 {
        w / l2.sqrt()
    } else {
        w
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

    #[test]
    fn face_frames() {
        let v = DVec3::new(0.3, -0.2, 0.9);
        assert_eq!(Face::Front.local(v), v);
        assert_eq!(Face::Back.local(Face::Back.local(v)), v);
        assert!(Face::Back.local(v).z < 0.0);
        assert_eq!(Face::toward(DVec3::new(0.0, 0.0, -1.0)), Face::Back);
        assert_eq!(Face::Back.z(0.2), -0.2);
    }

    #[test]
    fn direction_sampling_is_uniform_in_azimuth() {
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(3);
        let dir = DVec3::new(0.48, 0.6, 0.64);
        let (t, b) = paperbsdf_core::geometry::coordinate_system(dir);
        let n = 200_000;
        let mut bins = [0usize; 8];
        for _ in 0..n {
            let w = direction_at(dir, 0.3, &mut rng);
            assert!((w.length() - 1.0).abs() < 1e-12 && (w.dot(dir) - 0.3).abs() < 1e-12);
            let phi = w.dot(b).atan2(w.dot(t)) + PI;
            bins[((phi / (2.0 * PI) * 8.0) as usize).min(7)] += 1;
        }
        // Each bin: n/8 +- sqrt(n/8 * 7/8); allow 4 sigma.
        let e = n as f64 / 8.0;
        for c in bins {
            assert!((c as f64 - e).abs() < 4.0 * (e * 7.0 / 8.0).sqrt(), "{bins:?}");
        }
    }
}
