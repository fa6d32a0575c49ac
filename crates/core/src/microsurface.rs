//! The multiple-scattering rough dielectric face: a random walk on the Smith
//! microsurface (docs/design.md 4.1, `face_scattering = "multiple"`).
//!
//! Source: Heitz, Hanika, d'Eon, Dachsbacher, "Multiple-scattering microfacet
//! BSDFs with the Smith model", SIGGRAPH 2016, dielectric case. Light meets the
//! microsurface, scatters off one microfacet (reflection with probability
//! Fresnel `F`, refraction otherwise, the facet drawn from the normals visible
//! from the direction of arrival), and then either leaves (unmasked, with
//! probability `G1` of its new direction) or meets the microsurface again, from
//! the same side or, after a refraction, from the other side. Nothing is
//! absorbed, so every walk ends reflected or transmitted: `R + T = 1` for every
//! direction from both sides, by construction.
//!
//! **Which walk.** Heitz et al. track the height of each scattering point, which
//! makes the first order the *height-correlated* Smith BSDF. The project's
//! single-scattering face is Walter et al.'s BSDF with the *separable* masking
//! `G = G1(wi) G1(wo)` ([`crate::dielectric`], checked against Mitsuba 3's
//! `roughdielectric`), and the issue requires the walk's first order to be
//! exactly that. The separable form is what the same walk gives when the
//! height of each scattering point is drawn afresh from the height
//! distribution (masking and shadowing independent, the assumption behind
//! `G1 G1`): the probability that a ray leaving a point in direction `w`
//! escapes is then `G1(w) = 1 / (1 + Lambda(w))` whatever happened before, and a
//! ray that does not escape meets a facet drawn from the normals visible from
//! `-w` (above the horizon or, for a ray going up that is intercepted, below
//! it). That is the walk implemented here. It is energy conserving (nothing is
//! lost), reciprocal with the `eta^2` of generalised reciprocity (each step's
//! kernel is symmetric, tested), and its order 1 is `D F G1 G1 / (4 |ci co|)`
//! (and Walter's refraction term) with the exact Smith `G1`. For GGX that is
//! [`RoughDielectric::eval_mode`] to rounding. For Beckmann,
//! [`RoughDielectric::eval_mode`] uses Walter's rational approximation of `G1`
//! (as Mitsuba does, relative error below 0.35%), which no normalised walk can
//! reproduce (the visible-normal density is normalised by the exact `Lambda`):
//! order 1 here is Walter's form with the exact `G1`, i.e.
//! `eval_mode * G1_exact(wi) G1_exact(wo) / (G1_rational(wi) G1_rational(wo))`.
//!
//! **Conventions** are those of [`RoughDielectric::sample_mode`] and
//! [`RoughDielectric::eval_mode`]: directions in the face's local frame
//! (outside `+z`, index 1; inside `-z`, index `eta`), both pointing away from
//! the face. The walk starts from `wo`; in [`TransportMode::Importance`] that is
//! the direction the light came from, the returned direction the one it leaves
//! in, and the weight is exactly 1. In [`TransportMode::Radiance`], `wo` is the
//! viewer; the walk run from the viewer has the distribution of the light's
//! path reversed (reciprocity), and the weight carries the radiance factor
//! `1 / eta_rel(wo)^2` of a transmission (`eta_rel(wo)` = index beyond `wo`'s
//! side over `wo`'s side), 1 for a reflection, as for a smooth interface.
//!
//! **Random numbers** come from a caller's closure returning uniform numbers in
//! `[0, 1)` (the core crate has no `rand`); a walk uses a variable number.
//!
//! **Order cap.** A walk that scatters [`MAX_ORDER`] times without leaving is
//! cut: [`sample_multiple`] returns `None` and the estimators stop adding. The
//! tests count the cut fraction: none of 9.6e6 walks at the hardest faces
//! (m up to 1.5, eta up to 3, both sides, up to 89.9 degrees) was cut, and the
//! longest had 13 scattering events.

use crate::bsdf::TransportMode;
use crate::dielectric::{Interface, RoughDielectric};
use crate::fresnel::fresnel_dielectric;
use crate::geometry::{reflect, refract};
use crate::microfacet::{beckmann_slope_y, upper_unit, Distribution, Microfacet};
use glam::DVec3;

/// Scattering events after which a walk is cut (see the module doc).
pub const MAX_ORDER: u32 = 10_000;

/// One draw of the multiple-scattering walk, in the conventions of `RoughDielectric::sample_mode`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MsSample {
    /// The exit direction (unit, local frame, pointing away from the face):
    /// where the light leaves in [`TransportMode::Importance`], toward the light
    /// in [`TransportMode::Radiance`].
    pub wi: DVec3,
    /// `f |cos| / pdf`: 1 in [`TransportMode::Importance`]; in
    /// [`TransportMode::Radiance`] 1 for a reflection and `1 / eta_rel(wo)^2` for
    /// a transmission.
    pub weight: f64,
    /// Number of scattering events on the microsurface (1 = Walter's single
    /// scattering; 0 for an index-matched face, which the light crosses untouched).
    pub order: u32,
}

/// Same conventions as `RoughDielectric::sample_mode(wo, uc, u, mode)` (directions in the face frame, `wo` the
/// direction the walk starts from, `weight` = f |cos| / pdf: exactly 1 in `TransportMode::Importance` for an
/// energy-conserving walk, the eta^2 radiance factor in `Radiance` mode).
///
/// A smooth face draws its delta reflection with probability `F` and its delta
/// refraction otherwise (order 1, the weights of
/// [`RoughDielectric::specular_lobes`] divided by the lobe probability); an
/// index-matched face returns `-wo` with weight 1 and order 0. `None` when `wo`
/// lies in the plane of the face or the walk was cut at [`MAX_ORDER`].
pub fn sample_multiple(
    b: &RoughDielectric,
    wo: DVec3,
    mode: TransportMode,
    rnd: &mut impl FnMut() -> f64,
) -> Option<MsSample> {
    if wo.z == 0.0 || !wo.is_finite() {
        return None;
    }
    let t_weight = match mode {
        TransportMode::Importance => 1.0,
        TransportMode::Radiance => {
            let e = if wo.z > 0.0 { b.eta } else { 1.0 / b.eta };
            1.0 / (e * e)
        }
    };
    let (wi, order) = match b.interface {
        Interface::IndexMatched => {
            return Some(MsSample {
                wi: -wo,
                weight: 1.0,
                order: 0,
            })
        }
        Interface::Smooth => {
            let f = fresnel_dielectric(wo.z, b.eta);
            let wi = if rnd() < f {
                DVec3::new(-wo.x, -wo.y, wo.z)
            } else {
                let eta_ti = if wo.z > 0.0 { 1.0 / b.eta } else { b.eta };
                refract(wo, DVec3::Z, eta_ti)?
            };
            (wi, 1)
        }
        Interface::Rough(mf) => Microsurface::new(mf, b.eta).walk(wo, rnd)?,
    };
    let weight = if wi.z * wo.z > 0.0 { 1.0 } else { t_weight };
    Some(MsSample { wi, weight, order })
}

/// Unbiased estimate of the multiple-scattering BSDF value in the conventions of `RoughDielectric::eval_mode`
/// (no cosine): Walter's closed form (order 1) plus a stochastic estimate of orders >= 2.
///
/// Order 1 is deterministic (see the module doc for Beckmann's exact `G1`);
/// orders >= 2 are one walk with next-event estimation at every scattering
/// point and the escapes replaced by their expected value, so the estimate is
/// never negative and its variance is small. Zero for smooth and index-matched
/// faces (their lobes are deltas, which `eval` excludes) and for directions in
/// the plane of the face.
pub fn eval_multiple_estimate(
    b: &RoughDielectric,
    wi: DVec3,
    wo: DVec3,
    mode: TransportMode,
    rnd: &mut impl FnMut() -> f64,
) -> f64 {
    let mf = match b.interface {
        Interface::Rough(mf) => mf,
        _ => return 0.0,
    };
    if wi.z == 0.0 || wo.z == 0.0 {
        return 0.0;
    }
    let s = Microsurface::new(mf, b.eta);
    match mode {
        // f(wi, wo) |cos wo| is the flux density from the light at wi into wo.
        TransportMode::Radiance => s.density_estimate(wi, wo, rnd) / wo.z.abs(),
        // In importance transport wo is where the light comes from.
        TransportMode::Importance => s.density_estimate(wo, wi, rnd) / wi.z.abs(),
    }
}

/// The first order of the walk, in the conventions of
/// `RoughDielectric::eval_mode` (no cosine): Walter's BSDF with the exact
/// Smith `G1` (identical to [`RoughDielectric::eval_mode`] for GGX). Zero for
/// smooth and index-matched faces.
pub fn eval_single(b: &RoughDielectric, wi: DVec3, wo: DVec3, mode: TransportMode) -> f64 {
    let mf = match b.interface {
        Interface::Rough(mf) => mf,
        _ => return 0.0,
    };
    if wi.z == 0.0 || wo.z == 0.0 {
        return 0.0;
    }
    let s = Microsurface::new(mf, b.eta);
    match mode {
        TransportMode::Radiance => s.vertex_density(local(wi, wi.z > 0.0), wi.z > 0.0, wo) / wo.z.abs(),
        TransportMode::Importance => s.vertex_density(local(wo, wo.z > 0.0), wo.z > 0.0, wi) / wi.z.abs(),
    }
}

/// A vector in the frame of the side a ray is on: unchanged outside, negated
/// inside, so that the current medium is always above the microsurface (the
/// isotropic distribution is symmetric under this point reflection).
#[inline]
fn local(v: DVec3, outside: bool) -> DVec3 {
    if outside {
        v
    } else {
        -v
    }
}

/// The microsurface of one face: a microfacet distribution and the relative
/// index `eta` (inside over outside). Unlike [`RoughDielectric`] it does not
/// resolve `eta = 1` to "no interface", so that tables can take the limit
/// `eta -> 1+` of a rough face.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Microsurface {
    /// The microfacet distribution (family and roughness).
    pub mf: Microfacet,
    /// Relative index of refraction, inside over outside (>= 1).
    pub eta: f64,
}

impl Microsurface {
    /// The microsurface of distribution `mf` and relative index `eta`.
    pub fn new(mf: Microfacet, eta: f64) -> Self {
        Microsurface { mf, eta }
    }

    /// Smith's `Lambda` of a direction with `|cos theta| = c` (unsigned: the
    /// value for the direction flipped above the surface). For GGX in a form
    /// without cancellation near the normal.
    #[inline]
    fn lambda(&self, c: f64) -> f64 {
        match self.mf.dist {
            Distribution::Ggx => {
                let c2 = c * c;
                if c2 == 0.0 {
                    return f64::INFINITY;
                }
                let x = self.mf.alpha * self.mf.alpha * (1.0 - c2).max(0.0) / c2;
                0.5 * x / ((1.0 + x).sqrt() + 1.0)
            }
            Distribution::Beckmann => {
                // (exp(-a^2) / (a sqrt(pi)) - erfc(a)) / 2, a = cot(theta) / alpha:
                // the same value as `Microfacet::lambda_cos`, computed from erfc
                // so that it keeps its relative precision where it is tiny (the
                // normalisation of the normals seen from below the horizon is
                // Lambda itself).
                let s = (1.0 - c * c).max(0.0).sqrt();
                if s == 0.0 {
                    return 0.0;
                }
                if c == 0.0 {
                    return f64::INFINITY;
                }
                let a = c / (self.mf.alpha * s);
                if a > 26.0 {
                    // Both terms underflow (erfc(26) = 5e-296).
                    return 0.0;
                }
                0.5 * ((-a * a).exp() / (a * std::f64::consts::PI.sqrt()) - libm::erfc(a))
            }
        }
    }

    /// Escape probability `G1 = 1 / (1 + Lambda)` of a ray leaving the
    /// microsurface at `|cos theta| = c` away from it.
    #[inline]
    pub fn g1(&self, c: f64) -> f64 {
        1.0 / (1.0 + self.lambda(c))
    }

    /// Normalisation of the visible normals seen from `w` (any direction, in the
    /// frame where the medium is above): `int max(0, w.m) D(m) dm`, which is
    /// `(1 + Lambda) w.z` above the horizon and `Lambda |w.z|` below it.
    #[inline]
    fn visible_norm(&self, w: DVec3) -> f64 {
        let c = w.z.abs();
        let l = self.lambda(c);
        if w.z > 0.0 {
            (1.0 + l) * c
        } else {
            l * c
        }
    }

    /// Density per steradian of `m` of the normals visible from `w`:
    /// `max(0, w.m) D(m) / int max(0, w.m') D(m') dm'`, for `w` above or below
    /// the horizon (in the frame where the medium is above; `m.z > 0`).
    pub fn visible_density(&self, w: DVec3, m: DVec3) -> f64 {
        let wm = w.dot(m);
        if wm <= 0.0 || m.z <= 0.0 {
            return 0.0;
        }
        let n = self.visible_norm(w);
        if n.is_nan() || n <= 0.0 || !n.is_finite() {
            return 0.0;
        }
        wm * self.mf.d(m) / n
    }

    /// Draws a micro-normal (`m.z > 0`) from [`Microsurface::visible_density`]
    /// for `w` above or below the horizon. GGX: Heitz 2018's construction, which
    /// holds for directions below the horizon too (the visible part of the
    /// stretched hemisphere then projects to a half-disk minus a half-ellipse).
    /// Beckmann: the visible-normal sampler of [`Microfacet::sample_visible`]
    /// above the horizon; below it the slope along the incidence plane has the
    /// density `(x - A) exp(-x^2)` on `x > A` (`A = |cot theta| / alpha`),
    /// drawn exactly by rejection, and the slope across it is Gaussian.
    pub fn sample_visible(&self, w: DVec3, rnd: &mut impl FnMut() -> f64) -> DVec3 {
        let a = self.mf.alpha;
        match self.mf.dist {
            Distribution::Ggx => {
                let (u0, u1) = (rnd(), rnd());
                self.mf.sample_visible_ggx(w, [u0, u1])
            }
            Distribution::Beckmann => {
                if w.z >= 0.0 {
                    let (u0, u1) = (rnd(), rnd());
                    return self.mf.sample_visible(w, [u0, u1]);
                }
                let sin_s = (a * w.x).hypot(a * w.y);
                if sin_s == 0.0 {
                    // Straight up from below: nothing is visible (the walk never
                    // asks, as such a ray escapes surely).
                    return DVec3::Z;
                }
                let big_a = -w.z / sin_s;
                let y = loop {
                    if big_a < 0.75 {
                        let y = (-(1.0 - rnd()).ln()).sqrt();
                        if rnd() < (-2.0 * big_a * y).exp() {
                            break y;
                        }
                    } else {
                        let y = -((1.0 - rnd()) * (1.0 - rnd())).ln() / (2.0 * big_a);
                        if rnd() < (-y * y).exp() {
                            break y;
                        }
                    }
                };
                let x = big_a + y;
                let ys = beckmann_slope_y(rnd().max(1e-300));
                // The frame of -w (azimuth turned by pi): its slopes (-x, -ys)
                // are the slopes (x, ys) in w's own azimuth.
                let frame = self.mf.beckmann_visible_frame(w);
                frame.normal(-x, -ys)
            }
        }
    }

    /// A visible facet for `w` with `w.m > 0` (a draw that rounding put on the
    /// facet's back is drawn again; `None` after 16 such draws).
    #[inline]
    fn facet(&self, w: DVec3, rnd: &mut impl FnMut() -> f64) -> Option<(DVec3, f64)> {
        for _ in 0..16 {
            let m = self.sample_visible(w, rnd);
            let c = w.dot(m);
            if c > 0.0 && m.is_finite() {
                return Some((m, c));
            }
        }
        None
    }

    /// Scatters off a facet visible from `i` (local frame of side `outside`,
    /// pointing away from the facet): returns the new propagation direction in
    /// the global frame and the side it is on.
    #[inline]
    fn scatter(&self, i: DVec3, outside: bool, rnd: &mut impl FnMut() -> f64) -> Option<(DVec3, bool)> {
        let (m, c) = self.facet(i, rnd)?;
        let eta_l = if outside { self.eta } else { 1.0 / self.eta };
        let f = fresnel_dielectric(c, eta_l);
        if rnd() >= f {
            if let Some(t) = refract(i, m, 1.0 / eta_l) {
                return Some((local(t, outside), !outside));
            }
        }
        Some((local(reflect(i, m), outside), outside))
    }

    /// One walk started by light arriving from `wo` (pointing away from the
    /// face, either side): the exit direction and the number of scattering
    /// events, `None` if cut at [`MAX_ORDER`].
    pub fn walk(&self, wo: DVec3, rnd: &mut impl FnMut() -> f64) -> Option<(DVec3, u32)> {
        let mut outside = wo.z > 0.0;
        let mut i = local(wo, outside);
        for order in 1..=MAX_ORDER {
            let (wr, side) = self.scatter(i, outside, rnd)?;
            outside = side;
            let wl = local(wr, outside);
            if wl.z > 0.0 && rnd() < self.g1(wl.z) {
                return Some((wr, order));
            }
            i = -wl;
        }
        None
    }

    /// The density per steradian of `b` of leaving in direction `b` (global
    /// frame) right after scattering at a point reached from `i` (local frame of
    /// side `outside`, pointing back along the ray): the microfacet phase
    /// function of the facets visible from `i` times the escape probability
    /// `G1(b)`. For the first scattering point this is order 1 of the walk.
    pub fn vertex_density(&self, i: DVec3, outside: bool, b: DVec3) -> f64 {
        if b.z == 0.0 || i.z == 0.0 {
            return 0.0;
        }
        let esc = self.g1(b.z.abs());
        // Reflection back into the current medium when `b` is on its side.
        let reflected = (b.z > 0.0) == outside;
        self.scatter_density(i, outside, local(b, outside), reflected) * esc
    }

    /// The microfacet phase function of the facets visible from `i` (local
    /// frame of side `outside`, pointing back along the arriving ray, above
    /// or below the horizon): the density per steradian of the new
    /// propagation direction `o`, given in the same local frame, with
    /// `reflected` saying which event makes it: a reflection (`o` in the
    /// current medium, above or below the horizon) or a refraction (`o` the
    /// transmitted direction, beyond the facet). Before any masking of `o`:
    /// integrated over the sphere, reflection and refraction together, it is
    /// 1 (tested). [`Microsurface::vertex_density`] is this times the escape
    /// probability `G1`; a discrete solver of the walk (the `slab` model's
    /// faces) chains it.
    pub fn scatter_density(&self, i: DVec3, outside: bool, o: DVec3, reflected: bool) -> f64 {
        self.scatter_from(i, outside).density(o, reflected)
    }

    /// [`Microsurface::scatter_density`] for one arriving ray and many new
    /// directions: the normalisation of the visible normals (Smith's
    /// `Lambda` of `i`) computed once.
    pub fn scatter_from(&self, i: DVec3, outside: bool) -> Scatterer {
        let norm = if i.z == 0.0 { 0.0 } else { self.visible_norm(i) };
        let inv_norm = if norm > 0.0 && norm.is_finite() {
            1.0 / norm
        } else {
            0.0
        };
        Scatterer {
            mf: self.mf,
            i,
            eta_l: if outside { self.eta } else { 1.0 / self.eta },
            inv_norm,
        }
    }

    /// Unbiased estimate of the flux density per steradian of `b` with which
    /// light arriving from `a` leaves in direction `b` (both pointing away from
    /// the face): order 1 exactly, orders >= 2 by one walk with next-event
    /// estimation and expected escapes (see [`eval_multiple_estimate`]).
    pub fn density_estimate(&self, a: DVec3, b: DVec3, rnd: &mut impl FnMut() -> f64) -> f64 {
        let mut outside = a.z > 0.0;
        let mut i = local(a, outside);
        let mut sum = self.vertex_density(i, outside, b);
        let mut w = 1.0;
        for _ in 2..=MAX_ORDER {
            let Some((wr, side)) = self.scatter(i, outside, rnd) else {
                break;
            };
            outside = side;
            let wl = local(wr, outside);
            if wl.z > 0.0 {
                w *= 1.0 - self.g1(wl.z);
            }
            if !roulette(&mut w, rnd) {
                break;
            }
            i = -wl;
            sum += w * self.vertex_density(i, outside, b);
        }
        sum
    }

    /// Unbiased estimate of the fractions of the flux arriving from `a` that
    /// leave by orders >= 2, `(reflected, transmitted)` (reflected = back to
    /// `a`'s side), with the escapes replaced by their expected value (the
    /// estimator of the tables of [`crate::microsurface_tables`]).
    pub fn higher_order_albedo_estimate(&self, a: DVec3, rnd: &mut impl FnMut() -> f64) -> (f64, f64) {
        let start = a.z > 0.0;
        let mut outside = start;
        let mut i = local(a, outside);
        let (mut r, mut t) = (0.0, 0.0);
        let mut w = 1.0;
        for order in 1..=MAX_ORDER {
            let Some((wr, side)) = self.scatter(i, outside, rnd) else {
                break;
            };
            outside = side;
            let wl = local(wr, outside);
            if wl.z > 0.0 {
                let g = self.g1(wl.z);
                if order >= 2 {
                    if outside == start {
                        r += w * g;
                    } else {
                        t += w * g;
                    }
                }
                w *= 1.0 - g;
            }
            if !roulette(&mut w, rnd) {
                break;
            }
            i = -wl;
        }
        (r, t)
    }
}

/// The microfacet phase function of one arriving ray
/// ([`Microsurface::scatter_from`]).
#[derive(Clone, Copy, Debug)]
pub struct Scatterer {
    mf: Microfacet,
    /// The arriving ray's reverse direction, in the local frame of its side.
    i: DVec3,
    /// Index beyond the microsurface over the index of the ray's side.
    eta_l: f64,
    /// `1 / int max(0, i.m) D(m) dm` (0 when nothing is visible).
    inv_norm: f64,
}

impl Scatterer {
    /// The normalisation of the arriving ray's visible normals, `int max(0,
    /// i.m) D(m) dm` (0 when nothing is visible): `density(o) * norm` is
    /// `D F / 4` in reflection, symmetric in the two directions, which is
    /// how a discrete solver of the walk gets the reverse paths' kernel by
    /// reciprocity.
    pub fn norm(&self) -> f64 {
        if self.inv_norm > 0.0 {
            1.0 / self.inv_norm
        } else {
            0.0
        }
    }

    /// [`Microsurface::scatter_density`] of the new direction `o` (same
    /// local frame), by reflection or by refraction as `reflected` says.
    /// Always inlined: `paperbsdf_slab::face_walk` calls it from two loops
    /// over the azimuths, and outlined it cost 7% of a sheet's build
    /// (perf on the glossy preset while writing this).
    #[inline(always)]
    pub fn density(&self, o: DVec3, reflected: bool) -> f64 {
        if self.inv_norm == 0.0 {
            return 0.0;
        }
        let (i, eta_l) = (self.i, self.eta_l);
        let visible = |h: DVec3, ih: f64| ih * self.mf.d(h) * self.inv_norm;
        if reflected {
            let h = i + o;
            let hl = h.length();
            if hl == 0.0 {
                return 0.0;
            }
            let h = h / hl;
            let ih = i.dot(h);
            if h.z <= 0.0 || ih <= 0.0 {
                return 0.0;
            }
            visible(h, ih) * fresnel_dielectric(ih, eta_l) / (4.0 * ih)
        } else {
            // Refraction into the other medium (relative index eta_l).
            let Some(h) = upper_unit(-(i + eta_l * o)) else {
                return 0.0;
            };
            let (ih, oh) = (i.dot(h), o.dot(h));
            if ih <= 0.0 || oh >= 0.0 {
                return 0.0;
            }
            let f = fresnel_dielectric(ih, eta_l);
            if f >= 1.0 {
                return 0.0;
            }
            let den = ih + eta_l * oh;
            visible(h, ih) * (1.0 - f) * eta_l * eta_l * (-oh) / (den * den)
        }
    }
}

/// Russian roulette on a path weight below 1e-3: kept with probability 1/2 and
/// doubled, or ended (unbiased). Returns whether the path goes on.
#[inline]
fn roulette(w: &mut f64, rnd: &mut impl FnMut() -> f64) -> bool {
    if *w <= 0.0 {
        return false;
    }
    if *w < 1e-3 {
        if rnd() < 0.5 {
            *w *= 2.0;
        } else {
            return false;
        }
    }
    true
}
