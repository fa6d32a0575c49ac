//! One random walk of light through the slab, and the estimators it feeds.
//!
//! # The walk (light tracing in depth only)
//! Light arrives from direction `wi` (pointing toward the light) at the face
//! it faces, carrying unit flux. Every event is sampled exactly from the
//! physical system: surface events from the face's BSDF in importance
//! transport ([`crate::faces`]: Walter's [`paperbsdf_core::RoughDielectric::sample_mode`], the
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
//!
//! # Modules
//! The walk itself is here; its surface events are in `walk/surface.rs`, the
//! next-event estimator in `walk/nee.rs`, the sums in [`Tally`].

mod nee;
mod surface;
mod tally;

pub use tally::Tally;

use crate::slab::{Medium, Side, Slab};
use nee::{draw_exits, Target, Vertex};
use paperbsdf_core::phase::{sample_hg_cos, HgLobes};
use paperbsdf_core::DVec3;
use rand::Rng;

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
/// Survival probability of Russian roulette.
const RR_SURVIVAL: f64 = 0.1;

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
        let p = slab.phase();
        let mut t = Tracer {
            slab,
            med: slab.medium(channel),
            targets: wos.iter().map(|&wo| Target::new(slab, wo)).collect(),
            lobes: p.lobes(),
            smooth: p.smooth_part(),
            any_mis_volume: false,
            max_collisions: MAX_COLLISIONS_PER_WALK,
        };
        t.calibrate_targets();
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
        let lit = Side::of(wi);
        let wi_l = lit.local(wi);
        self.lit_face_reflection(lit, wi_l, rng, tally);
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
            let x = Side::of(dir);
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
    use rand::SeedableRng;
    use std::f64::consts::PI;

    #[test]
    fn face_frames() {
        let v = DVec3::new(0.3, -0.2, 0.9);
        assert_eq!(Side::Front.local(v), v);
        assert_eq!(Side::Back.local(Side::Back.local(v)), v);
        assert!(Side::Back.local(v).z < 0.0);
        assert_eq!(Side::of(DVec3::new(0.0, 0.0, -1.0)), Side::Back);
        assert_eq!(Side::Back.z(0.2), -0.2);
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
