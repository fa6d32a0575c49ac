//! The light a coated sheet's smooth coating/base boundary mirrors back
//! through its rough front in one round trip, kept analytic in the model
//! `slab` (issue 13: sharp paths are not left to the grid).
//!
//! **The term.** The coated front of docs/design.md 4.1 (`crate::slab`'s
//! module doc): a rough air/coating interface (Walter et al. 2007, core's
//! [`RoughDielectric`] of index `eta_f`), a coating of zero thickness, and a
//! smooth boundary to the base (relative index `eta_b / eta_f`, Fresnel
//! reflectance `R_b`, total reflection beyond its critical angle when the
//! base is less dense). Light from outside that crosses the front, is
//! mirrored by the boundary and crosses the front again leaves with
//! `f_c(wi, wo) = int f_in(wi, v) |v_z| R_b(|v_z|) f_out(u(v), wo) dv`
//! over the coating's downward propagation directions `v`, where `f_in`
//! and `f_out` are Walter's transmission into and out of the coating
//! (radiance transport; their `eta^2` factors cancel) and `u(v) = (-v_x,
//! -v_y, v_z)` is the direction towards the light after the mirror. For a
//! front smoother than the grid this is a lobe around the mirror direction
//! about `(eta_f - 1) m_f sqrt 2` wide in the outgoing direction (devB's
//! Beckmann 0.08: 3.5 degrees; glossy's 0.04: 1.8), narrower than the
//! grid's 4.85-degree last interval: on 32 nodes it moved devB's
//! reflection near the normal by 10.4% against 64 nodes (README,
//! "Convergence"). Later round trips (the front's reflection from inside
//! between two mirrors, `R_b^2` times smaller) and the walk's
//! (`face_scattering = "multiple"`) scattering in either crossing are broad
//! and stay in the grid.
//!
//! **Evaluation.** The integral ([`CoatReturn::exact`]) samples the
//! front's visible normals from `wi` on a Gauss-Legendre product rule in the
//! sampler's unit square (checked against a brute-force integral over the
//! coating's directions, tests/coat_return.rs). `eval` reads a table of
//! `f_c` (finite at grazing angles: the Fresnel factors and the shadowing
//! take what the cosines would give) in Rusinkiewicz's coordinates of the
//! half vector `h = (wi + wo) / |wi + wo|`: `x = t / (t + sigma)` with `t =
//! tan theta_h` (`sigma` twice the lobe's width in half-vector slope, so the
//! lobe and its flanks take the first half of the axis and the tails the
//! rest, to `theta_h = 90` degrees), `sqrt(cos theta_d)` with `cos theta_d
//! = wi . h` (finer towards grazing), and `cos^2 phi_d` (`phi_d` the azimuth
//! of `wi` about `h` from the plane of `h` and the normal: `phi_d`, `pi -
//! phi_d` and `-phi_d` give the same value on an isotropic face, and
//! exchanging `wi` and `wo` turns `phi_d` by `pi`, so the table is
//! reciprocal by construction), trilinear on [`TABLE_SIZE`] points whose
//! values are the integral on [`TABLE_POINTS`]` x `[`TABLE_POINTS`] points
//! (within 3e-3 of the lobe's peak there; the table within 1% of the
//! peak at any point below 70 degrees, tests/coat_return.rs). Beyond the
//! last `x` where the table holds more than [`CUT`] of its largest value,
//! `eval` is 0. The table's energy follows the lobe's to about 1% (its
//! flanks between the points: +0.6 to +1.6% for Beckmann fronts of 0.005
//! to 0.08, up to +4.3% for a GGX 0.3 front's heavy tails) and the model
//! `slab` makes it the projection's exactly ([`CoatReturn::balance`]:
//! factors `r(mu_i) r(mu_o)`, reciprocal). Costs: the table 96-109 ms (41
//! for GGX 0.3) and the balance 15-18 ms on two cores, 120 kB, `eval` 34
//! ns (examples/coat_return.rs prints these; glossy's criterion
//! `eval_grazing` 138 -> 181 ns, `eval_reflection` 66 -> 112 ns, benches
//! back to back on 2026-12-06). A table of logarithms, tried,
//! undercut the narrow lobes' energy by up to 3.9% instead and its
//! `exp` cost 8 ns more.

use paperbsdf_core::bsdf::TransportMode;
use paperbsdf_core::dielectric::Interface;
use paperbsdf_core::fresnel::fresnel_dielectric;
use paperbsdf_core::geometry::refract;
use paperbsdf_core::quadrature::gauss_legendre_01;
use paperbsdf_core::{DVec3, RoughDielectric};
use rayon::prelude::*;

/// Points of the table along `x` (the half vector's slope), `sqrt(cos
/// theta_d)` and `cos^2 phi_d`.
pub const TABLE_SIZE: [usize; 3] = [48, 24, 13];

/// Gauss-Legendre points per axis of the sampler's unit square in the
/// table's integrals.
pub const TABLE_POINTS: usize = 8;

/// Gauss-Legendre points per axis of [`CoatReturn::albedo_of`].
pub const ALBEDO_POINTS: usize = 48;

/// Where the half vector's slope is so large that every point of the table
/// from there on is below this fraction of its largest value, `eval` is 0
/// without reading it (a jump of at most this much of the lobe's peak).
pub const CUT: f64 = 1e-9;

/// Cells of the energy factors' guide ([`CoatReturn::balance`]).
const GUIDE: usize = 64;

/// Passes of [`CoatReturn::balance`].
const BALANCE_PASSES: usize = 6;

/// The coating's single round trip (module doc): the exact integral and its table.
#[derive(Clone, Debug)]
pub struct CoatReturn {
    /// The rough air/coating interface (index `eta_f`, Walter's single scattering).
    front: RoughDielectric,
    /// Relative index of the coating/base boundary, `eta_b / eta_f`.
    eta_boundary: f64,
    /// Width of the lobe in half-vector slope (the table's `x` scale).
    sigma: f64,
    /// `f_c` at the table's points, `x` fastest then `sqrt(cos theta_d)`,
    /// then `cos^2 phi_d`.
    values: Vec<f64>,
    /// `x` beyond which `eval` is 0 ([`CUT`]).
    x_cut: f64,
    /// Per cell `[k, k + 1) / GUIDE` of cosines: the interval of
    /// `scale_mu` where it starts (no binary search in `eval`).
    guide: Vec<u16>,
    /// The energy factors `r` ([`CoatReturn::balance`]) at the cosines
    /// `scale_mu` (ascending), linear between them; empty: 1.
    scale_mu: Vec<f64>,
    scale: Vec<f64>,
}

impl CoatReturn {
    /// The round trip of a rough front `front` (air over a coating of index
    /// `front.eta`) over a smooth boundary to a base of relative index
    /// `eta_boundary` (`eta_b / eta_f`), tabulated; `None` if the front is
    /// not rough or there is no boundary (`eta_boundary = 1`).
    pub fn new(front: RoughDielectric, eta_boundary: f64) -> Option<CoatReturn> {
        if !matches!(front.interface, Interface::Rough(_)) || eta_boundary == 1.0 {
            return None;
        }
        // The outgoing direction turns by about (eta - 1) times each
        // micro-normal's tilt, the half vector by half of that, two
        // crossings: (eta - 1) m / sqrt 2 is about 1.4 times the lobe's
        // standard deviation in half-vector slope. Twice that keeps the
        // lobe's flanks off the end of the axis, where its points thin out
        // (the narrowest lobe's energy through the table, Beckmann 0.005:
        // +1.7% at mu 0.5 and +3.5% at 0.25 with `sigma` itself, +0.9% and
        // +1.6% with twice it; examples/coat_return.rs, the factor changed).
        let sigma = 2.0 * ((front.eta - 1.0) * front.m * std::f64::consts::FRAC_1_SQRT_2).max(1e-4);
        let mut me = CoatReturn {
            front,
            eta_boundary,
            sigma,
            values: Vec::new(),
            x_cut: 1.0,
            guide: Vec::new(),
            scale_mu: Vec::new(),
            scale: Vec::new(),
        };
        let [nx, nd, np] = TABLE_SIZE;
        let rule = gauss_legendre_01(TABLE_POINTS);
        let raw: Vec<f64> = (0..nx * nd * np)
            .into_par_iter()
            .map(|k| {
                let (a, b, c) = (k % nx, (k / nx) % nd, k / (nx * nd));
                let x = a as f64 / (nx - 1) as f64;
                let yd = b as f64 / (nd - 1) as f64;
                let cd = yd * yd;
                let c2 = c as f64 / (np - 1) as f64;
                match me.directions(x, cd, c2) {
                    Some((wi, wo)) => me.integral(wi, wo, &rule),
                    None => 0.0,
                }
            })
            .collect();
        let largest = raw.iter().cloned().fold(0.0, f64::max);
        // Beyond the last point of x with a value above CUT of the
        // largest, the table is below it: 0 there (module doc).
        let last = (0..nx)
            .rev()
            .find(|&a| (0..nd * np).any(|k| raw[a + nx * k] > CUT * largest))
            .unwrap_or(0);
        me.x_cut = ((last + 1) as f64 / (nx - 1) as f64).min(1.0);
        me.values = raw;
        Some(me)
    }

    /// The pair of directions at table coordinates `(x, cos theta_d, cos^2
    /// phi_d)`, `None` where either is at or below the horizon.
    fn directions(&self, x: f64, cd: f64, c2: f64) -> Option<(DVec3, DVec3)> {
        if x >= 1.0 {
            return None;
        }
        let th = (self.sigma * x / (1.0 - x)).atan();
        let (sh, ch) = th.sin_cos();
        let h = DVec3::new(sh, 0.0, ch);
        let sd = (1.0 - cd * cd).max(0.0).sqrt();
        let (cp, sp) = (c2.sqrt(), (1.0 - c2).max(0.0).sqrt());
        // The frame about h: b1 in the plane of h and the normal, b2 across it.
        let b1 = DVec3::new(ch, 0.0, -sh);
        let b2 = DVec3::Y;
        let wi = b1 * (sd * cp) + b2 * (sd * sp) + h * cd;
        let wo = h * (2.0 * wi.dot(h)) - wi;
        (wi.z > 1e-9 && wo.z > 1e-9).then_some((wi, wo))
    }

    /// The table's coordinates of `(wi, wo)` (both above the face): `x`,
    /// `sqrt(cos theta_d)`, `cos^2 phi_d` (module doc), from `s = wi + wo`
    /// (`h = s / |s|`) without normalising it first.
    #[inline]
    fn coordinates(&self, wi: DVec3, wo: DVec3) -> Option<(f64, f64, f64)> {
        let s = wi + wo;
        let sxy2 = s.x * s.x + s.y * s.y;
        let len2 = sxy2 + s.z * s.z;
        if len2 <= 0.0 || s.z <= 0.0 {
            return None;
        }
        let sxy = sxy2.sqrt();
        let inv_len = 1.0 / len2.sqrt();
        // tan theta_h = |s_xy| / s_z.
        let t = sxy / s.z;
        let x = t / (t + self.sigma);
        let yd = (wi.dot(s) * inv_len).clamp(0.0, 1.0).sqrt();
        // wi's components across h: along b1 = (h_z e, -sin theta_h) (in
        // the plane of h and the normal, `e` the unit azimuth of h) and b2
        // = z x e (across it); with h on the normal any frame does.
        let (p1, p2) = if sxy > 1e-12 * s.z {
            let (ex, ey) = (s.x / sxy, s.y / sxy);
            (
                (s.z * (wi.x * ex + wi.y * ey) - sxy * wi.z) * inv_len,
                wi.y * ex - wi.x * ey,
            )
        } else {
            (wi.x, wi.y)
        };
        let q = p1 * p1 + p2 * p2;
        let c2 = if q > 0.0 { p1 * p1 / q } else { 1.0 };
        Some((x, yd, c2))
    }

    /// `f_c(wi, wo)` (module doc) from the table, times the energy factors
    /// `r(mu_i) r(mu_o)` ([`CoatReturn::balance`]); 0 unless both
    /// directions are above the face (the term exists for light on the
    /// coated side only).
    #[inline]
    pub fn eval(&self, wi: DVec3, wo: DVec3) -> f64 {
        let v = self.eval_table(wi, wo);
        if self.scale.is_empty() || v == 0.0 {
            return v;
        }
        v * self.scale_at(wi.z) * self.scale_at(wo.z)
    }

    /// The energy factor `r` at cosine `mu` (linear between the balance's
    /// cosines).
    #[inline]
    fn scale_at(&self, mu: f64) -> f64 {
        let (m, s) = (&self.scale_mu, &self.scale);
        let n = m.len();
        if mu <= m[0] {
            return s[0];
        }
        if mu >= m[n - 1] {
            return s[n - 1];
        }
        // The guide's interval for mu's cell, then on to mu's own (Radau's
        // nodes gather near 1: a few steps at most).
        let mut i = self.guide[((mu * GUIDE as f64) as usize).min(GUIDE - 1)] as usize;
        while m[i + 1] <= mu {
            i += 1;
        }
        let t = (mu - m[i]) / (m[i + 1] - m[i]);
        s[i] * (1.0 - t) + s[i + 1] * t
    }

    /// Makes the albedo of [`CoatReturn::eval`] (over `wo`, by
    /// [`CoatReturn::albedo_of`]) the `target` at each cosine of `mu`
    /// (ascending): the factors `r(mu_i) r(mu_o)` (`r` at the cosines,
    /// linear between them), a few symmetric fixed-point passes (each
    /// multiplies `r` by the square root of target over albedo) (the lobe is near the mirror direction,
    /// where `mu_o` is about `mu_i`). The model `slab` gives the albedo
    /// its projection on the grid has, so that exchanging the two moves no
    /// energy; the factors correct the table's interpolation (module doc).
    pub fn balance(&mut self, mu: &[f64], target: &[f64]) {
        self.scale_mu = mu.to_vec();
        self.scale = vec![1.0; mu.len()];
        // The interval of mu's nodes where each guide cell starts.
        self.guide = (0..GUIDE)
            .map(|k| {
                let at = k as f64 / GUIDE as f64;
                mu.partition_point(|&x| x <= at).saturating_sub(1).min(mu.len() - 2) as u16
            })
            .collect();
        for _ in 0..BALANCE_PASSES {
            let now: Vec<f64> = mu
                .par_iter()
                .map(|&m| self.albedo_of(m, |wi, wo| self.eval(wi, wo)))
                .collect();
            for ((s, a), t) in self.scale.iter_mut().zip(&now).zip(target) {
                if *a > 0.0 && *t > 0.0 {
                    *s *= (t / a).sqrt();
                }
            }
        }
    }

    /// `int f(wi, wo) mu_o dwo` for `wi` at cosine `mu` (azimuth 0) over
    /// the outgoing hemisphere, by the half vector `h` (`wo = 2 (wi.h) h -
    /// wi`, `dwo = 4 (wi.h) dh`) in the table's coordinate `x` (so the rule
    /// gathers where the lobe is) and its azimuth, Gauss-Legendre
    /// ([`ALBEDO_POINTS`] per axis; the lobe is even in the azimuth).
    pub fn albedo_of(&self, mu: f64, f: impl Fn(DVec3, DVec3) -> f64) -> f64 {
        let wi = DVec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
        let (u, w) = gauss_legendre_01(ALBEDO_POINTS);
        let mut sum = 0.0;
        for (x, wx) in u.iter().zip(&w) {
            // tan theta_h = sigma x / (1 - x).
            let t = self.sigma * x / (1.0 - x);
            let th = t.atan();
            let dth = self.sigma / ((1.0 - x) * (1.0 - x) * (1.0 + t * t));
            let (sh, ch) = th.sin_cos();
            for (y, wy) in u.iter().zip(&w) {
                let ph = std::f64::consts::PI * y;
                let h = DVec3::new(sh * ph.cos(), sh * ph.sin(), ch);
                let wh = wi.dot(h);
                if wh <= 0.0 {
                    continue;
                }
                let wo = h * (2.0 * wh) - wi;
                if wo.z <= 0.0 {
                    continue;
                }
                // Both signs of the azimuth: 2 pi in all.
                sum += wx * wy * 2.0 * std::f64::consts::PI * dth * sh * 4.0 * wh * wo.z * f(wi, wo);
            }
        }
        sum
    }

    /// [`CoatReturn::eval`] before the energy factors.
    fn eval_table(&self, wi: DVec3, wo: DVec3) -> f64 {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        let Some((x, yd, c2)) = self.coordinates(wi, wo) else {
            return 0.0;
        };
        if x > self.x_cut {
            return 0.0;
        }
        let [nx, nd, np] = TABLE_SIZE;
        #[inline(always)]
        fn place(v: f64, n: usize) -> (usize, f64) {
            let s = v * (n - 1) as f64;
            let i = (s as usize).min(n - 2);
            (i, (s - i as f64).clamp(0.0, 1.0))
        }
        let ((a, ta), (b, tb), (c, tc)) = (place(x, nx), place(yd, nd), place(c2, np));
        // The eight corners, x fastest: a row of two at each (b, c).
        let k = a + nx * (b + nd * c);
        let v = &self.values[k..k + nx * (nd + 1) + 2];
        let row = |o: usize| v[o] + ta * (v[o + 1] - v[o]);
        let (r00, r10) = (row(0), row(nx));
        let (r01, r11) = (row(nx * nd), row(nx * (nd + 1)));
        let lo = r00 + tb * (r10 - r00);
        let hi = r01 + tb * (r11 - r01);
        lo + tc * (hi - lo)
    }

    /// `f_c(wi, wo)` by the integral over the front's visible normals `h`
    /// from `wi` (Heitz and d'Eon 2014, core's sampler, on a Gauss-Legendre
    /// product rule in its unit square, `points` per axis), for directions
    /// above the face. The coating's direction is `v = refract(wi, h)`;
    /// `f_in |v_z|` over `v`'s density among the refracted directions (the
    /// visible normals' `G1(wi) (wi.h) D(h) / mu_i` times the refraction's
    /// Jacobian) leaves `(1 - F(wi.h)) G(wi, v) / G1_exact(wi)` of Walter's
    /// transmission (`G` is the face's Smith term, Walter's rational
    /// approximation for Beckmann; the sampler's `G1` is exact). Accurate
    /// where the lobe is (1e-6 of the brute-force integral on its peak);
    /// on its far flanks, where `f_out` peaks away from the points, the
    /// rule thins out (tests/coat_return.rs).
    pub fn exact(&self, wi: DVec3, wo: DVec3, points: usize) -> f64 {
        self.integral(wi, wo, &gauss_legendre_01(points))
    }

    /// [`CoatReturn::exact`] on the Gauss-Legendre rule `(u, w)` on `[0, 1]`
    /// (the table's entries share one).
    fn integral(&self, wi: DVec3, wo: DVec3, (u, w): &(Vec<f64>, Vec<f64>)) -> f64 {
        let Interface::Rough(mf) = self.front.interface else {
            return 0.0;
        };
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        let eta = self.front.eta;
        let mut sum = 0.0;
        for (ua, wa) in u.iter().zip(w) {
            for (ub, wb) in u.iter().zip(w) {
                let h = mf.sample_visible(wi, [*ua, *ub]);
                let wh = wi.dot(h);
                if wh <= 0.0 {
                    continue;
                }
                let Some(v) = refract(wi, h, 1.0 / eta) else {
                    continue;
                };
                if v.z >= 0.0 {
                    continue;
                }
                let g1 = mf.g1_exact(wi, h);
                if g1 <= 0.0 {
                    continue;
                }
                let weight = (1.0 - fresnel_dielectric(wh, eta)) * mf.g(wi, v, h) / g1;
                let mirror = fresnel_dielectric(-v.z, self.eta_boundary);
                let back = DVec3::new(-v.x, -v.y, v.z);
                let f_out = self.front.eval_mode(back, wo, TransportMode::Radiance);
                sum += wa * wb * weight * mirror * f_out;
            }
        }
        sum
    }

    /// Bytes held by the table.
    pub fn memory_bytes(&self) -> usize {
        (self.values.len() + self.scale.len() + self.scale_mu.len()) * std::mem::size_of::<f64>() + self.guide.len() * 2
    }
}
