//! Light that crosses a rough face, meets something sharp, and crosses a
//! rough face out, kept analytic in the model `slab` (issue 13: sharp paths
//! are not left to the grid). Two such terms:
//!
//! - **a coated front's round trip** ([`TwoCrossings::coat_return`]). The
//!   coated front of docs/design.md 4.1 (`crate::slab`'s module doc): a
//!   rough air/coating interface (Walter et al. 2007, core's
//!   [`RoughDielectric`] of index `eta_f`), a coating of zero thickness,
//!   and a smooth boundary to the base (relative index `eta_b / eta_f`,
//!   Fresnel reflectance `R_b`, total reflection beyond its critical angle
//!   when the base is less dense). Light from outside that crosses the
//!   front, is mirrored by the boundary and crosses the front again leaves
//!   with `f_c(wi, wo) = int f_in(wi, v) |v_z| R_b(|v_z|) f_out(u(v), wo)
//!   dv`. For a front smoother than the grid this is a lobe about the
//!   mirror direction about `(eta_f - 1) m_f sqrt 2` wide (devB's Beckmann
//!   0.08: 3.5 degrees; glossy's 0.04: 1.8), narrower than the grid's
//!   4.85-degree last interval: on 32 nodes it moved devB's reflection near
//!   the normal by 10.4% against 64 nodes. Later round trips (`R_b^2`
//!   times smaller) and the walk's (`face_scattering = "multiple"`)
//!   scattering in either crossing are broad and stay in the grid.
//! - **the unscattered transmission of a sheet with two rough faces**
//!   ([`TwoCrossings::unscattered`]; a coated sheet's through its
//!   coating/base boundary too, [`TwoCrossings::unscattered_coated_each`],
//!   since 2026-12-07: on a thin coated sheet the grid was 7-11% off twice
//!   the nodes near straight through): through the lit face, straight
//!   through the medium with `exp(-tau / |v_z|)`, out through the other
//!   face: `f_u(wi, wo) = int f_in(wi, v) |v_z| exp(-tau / |v_z|)
//!   f_out(u(v), wo) dv` with the exit face in its own frame (outside up,
//!   so that `u(v) = (-v_x, -v_y, v_z)` again and `wo` is above it). A lobe
//!   about the straight-through direction as wide as the faces make it:
//!   on the grid it moved thin tissue's transmission 5-15 degrees from the
//!   normal by 9.6% against twice the nodes (weak scatter 4.5%; 1.5% and
//!   0.9% with the term, `examples/convergence`).
//!
//! In both, `v` runs over the downward propagation directions inside,
//! `f_in` and `f_out` are Walter's transmission into and out of the face
//! (radiance transport; their `eta^2` factors cancel), and `u(v)` is the
//! direction towards the light at the second crossing.
//!
//! **Evaluation.** The integral ([`TwoCrossings::exact`]) draws `v` two
//! ways on a Gauss-Legendre product rule in each sampler's unit square:
//! refracting `wi` through the first face's normals visible from `wi`
//! (Heitz and d'Eon 2014, core's samplers; for Beckmann the separable
//! visible slopes with the exact inverse error function), and refracting
//! `wo` through the second face's normals visible from `wo`; the two are
//! combined by the balance heuristic (Veach 1997), each point weighted by
//! the integrand over the sum of the two densities (the visible normals'
//! `G1_exact (w.h) D / w_z` times the refraction's Jacobian). One sampler
//! alone follows only its own lobe: where the other lobe is off its centre
//! (the flanks), the lit face's sampler on 8 x 8 points was 17% and 49%
//! high 20 and 40 degrees from a GGX 0.3 lobe's centre (the rule before
//! 2026-12-06); with both, 1.5% at most for round trips and equal faces,
//! 5% for unequal faces six times apart in width (tests/two_crossings.rs,
//! against 64 points, which agree with a brute-force integral over `v`
//! within 1.8e-3). `eval` reads a table of the integral (finite at grazing
//! angles: the Fresnel factors and the shadowing take what the cosines
//! would give) in Rusinkiewicz's coordinates of the half vector `h = (wi +
//! wo) / |wi + wo|` (for the unscattered term `wo` in the exit face's
//! frame, so that `h` is the normal at the straight-through direction):
//! `x = t / (t + sigma)` with `t = tan theta_h` (`sigma` twice the wider
//! lobe's width in half-vector slope, so the lobe and its flanks take the
//! first half of the axis and the tails the rest, to `theta_h = 90`
//! degrees), `sqrt(cos theta_d)` with `cos theta_d = wi . h` (finer towards
//! grazing), and the azimuth `phi_d` of `wi` about `h` from the plane of
//! `h` and the normal: `cos^2 phi_d` where the term is the same with the
//! two directions exchanged (a round trip, equal faces: `phi_d`, `pi -
//! phi_d` and `-phi_d` give the same value, and exchanging `wi` and `wo`
//! turns `phi_d` by `pi`, so the table is reciprocal by construction), else
//! `(1 + cos phi_d) / 2` on twice the points. Trilinear on [`TABLE_SIZE`]
//! points whose values are the integral on [`TABLE_POINTS`] per axis of
//! each sampler (the table within 1% of the peak of those values at the
//! tested points, measured 7.7e-3). Beyond the last `x` where the table
//! holds more than [`CUT`] of its largest value, `eval` is 0.
//!
//! **Energy.** The model `slab` takes the term's projection on its grid out
//! of its table and gives the term the projection's albedo
//! ([`TwoCrossings::balance`]): factors `r_1(mu_i) r_2(mu_o)` of the two
//! faces (reciprocal), a matrix scaling (Sinkhorn) on the albedo's hat
//! functions at the nodes, and for the unscattered term also at
//! [`STEPS`] points between them, where the target is the albedo the
//! table's interpolation gives its own light there (the lit face's
//! crossing shape times the linear interpolation of the nodes'; crate::bsdf,
//! "Energy"); what the term still misses at a node goes to the table's
//! balance. Non-absorbing sheets close to 9e-6 (tests/slab_bsdf.rs) and
//! faces smoother than the grid to 2.5e-6 (tests/smooth_faces.rs); with
//! the factors linear between the nodes a sheet with unequal faces and tau
//! 0.2 was 1.4e-4 off between them, GGX 0.001 faces 2.6e-4.
//!
//! **Costs** (examples/two_crossings.rs prints them, 2026-12-06): a coated
//! front's table 106-111 ms (GGX 0.3: 66) and its balance 2-5 ms of a
//! build on two cores; the unscattered term's table 62 ms for equal GGX
//! faces (thin tissue) and 147 ms for unequal ones, its balance 41-45 ms
//! (82; 35-36 and 60 with the coarser rule before 2026-12-06,
//! [`ALBEDO_POINTS_PER_CELL`]); 143 kB (254 for unequal faces); `eval` about
//! 35 ns. A coloured sheet's distinct optical thicknesses share one pass
//! over the entries ([`TwoCrossings::unscattered_each`]) and one over the
//! balance's rule ([`TwoCrossings::balance_each`]): a thin RGB sheet with
//! GGX 0.1 and Beckmann 0.25 faces builds in 0.92 s (1.07 s with a balance
//! per channel and the coarser rule, 0.68 s before the term; with a pass
//! per channel over the entries about 1.4 s, from a run beside CI: 2.8 s
//! against 2.1; examples/slab_build, `rgb-thin-unequal`). A table of
//! logarithms, tried for the round trip, undercut the narrow lobes' energy
//! by up to 3.9% and its `exp` cost 8 ns more.

use paperbsdf_core::dielectric::Interface;
use paperbsdf_core::fresnel::fresnel_dielectric;
use paperbsdf_core::geometry::refract;
use paperbsdf_core::quadrature::gauss_legendre_01;
use paperbsdf_core::{DVec3, Microfacet, RoughDielectric};
use rayon::prelude::*;

/// Points of the table along `x` (the half vector's slope), `sqrt(cos
/// theta_d)` and `cos^2 phi_d`.
pub const TABLE_SIZE: [usize; 3] = [48, 24, 13];

/// Gauss-Legendre points per axis of the sampler's unit square in the
/// table's integrals.
pub const TABLE_POINTS: usize = 8;

/// Gauss-Legendre points of [`TwoCrossings::albedo_of`] on each of the
/// table's intervals in `x`. The balance makes the albedo by this rule the
/// target, so `eval`'s energy is off by the rule's error: until 2026-12-06
/// the rule had 48 points over all of `x` (one per interval of the
/// trilinear table, whose kinks it does not see), and a thin sheet's
/// unscattered term (optical thickness 0.3, GGX 0.01 faces) integrated
/// 0.2-0.4% below it at 80 degrees, 1-2% at 88 (against 400 points, and
/// against this rule with 8 points per interval and 512 in azimuth): the
/// sheet's `R + T` was 1 - 3.6e-3 (thin tissue, GGX 0.3: 2.8e-4), which
/// the energy tests, integrating the term by the same rule, did not see.
/// With 2 points per interval the rule is within 1e-4 of the term's albedo
/// (tests/slab_bsdf.rs, `energy_closes_without_absorption`, by 6 x 256;
/// examples/two_crossings.rs); 2 x 64 halved the largest error and cost
/// the RGB thin sheet 0.14 s of build, 3 x 64 was no better.
pub const ALBEDO_POINTS_PER_CELL: usize = 2;

/// Gauss-Legendre points of [`TwoCrossings::albedo_of`] in the half
/// vector's azimuth.
pub const ALBEDO_AZIMUTH_POINTS: usize = 48;

/// Where the half vector's slope is so large that every point of the table
/// from there on is below this fraction of its largest value, `eval` is 0
/// without reading it (a jump of at most this much of the lobe's peak).
pub const CUT: f64 = 1e-9;

/// Cells of the energy factors' guide ([`TwoCrossings::balance`]): finer
/// than the points near `mu = 1` (32 Radau nodes: the last interval 3.6e-3
/// wide, its points 3e-4 apart).
const GUIDE: usize = 4096;

/// Most iterations of [`TwoCrossings::balance`]'s matrix scaling.
const BALANCE_ITERATIONS: usize = 500;

/// Points of the energy factors per interval between the balance's cosines
/// (and below the first), where [`TwoCrossings::balance`] shapes the
/// albedo between them (with 12 the energy tests close to 9e-6; 4 and 8
/// points, tried with shaping passes instead of the matrix scaling, left
/// 6.4e-5 and 1.7e-5 on the thin sheet with unequal faces).
pub const STEPS: usize = 12;

/// The crossing shapes `g(mu)` of the first and the second face that
/// [`TwoCrossings::balance`] gives the albedo between its cosines.
pub type Shapes<'a> = [&'a (dyn Fn(f64) -> f64 + Sync); 2];

/// What the light meets between its two crossings (module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Between {
    /// A coated front's smooth coating/base boundary, relative index
    /// `eta_b / eta_f`, mirrors it (Fresnel) back to the same front.
    Mirror {
        /// `eta_b / eta_f`.
        eta_boundary: f64,
    },
    /// The medium lets it through unscattered, `exp(-tau / |v_z|)`, to the
    /// other face.
    Straight {
        /// The medium's optical thickness.
        tau: f64,
    },
}

/// Light that crosses a rough face, meets [`Between`], and crosses a rough
/// face out (module doc): the exact integral and its table.
#[derive(Clone, Debug)]
pub struct TwoCrossings {
    /// The face crossed first, from outside (Walter's single scattering; in
    /// the frame of the face the light arrives at, outside up).
    front: RoughDielectric,
    /// The face crossed second, from inside, in its own frame (outside up):
    /// the same front after a mirror, the other face through the medium.
    second: RoughDielectric,
    /// What is between the crossings.
    between: Between,
    /// For the unscattered term of a coated sheet: the relative index
    /// `eta_b / eta_f` of the smooth coating/base boundary the light crosses
    /// between the front (into the coating) and the medium; 1: none
    /// ([`TwoCrossings::unscattered_coated_each`]).
    boundary: f64,
    /// Whether the value is the same with the two directions exchanged
    /// (the mirror's round trip, or equal faces): the table's azimuth
    /// coordinate is then `cos^2 phi_d` on `[0, 1]`, else `(1 + cos phi_d)
    /// / 2` with twice the points.
    folded: bool,
    /// Points of the table's azimuth coordinate.
    np: usize,
    /// Width of the lobe in half-vector slope (the table's `x` scale).
    sigma: f64,
    /// `f_c` at the table's points, `x` fastest then `sqrt(cos theta_d)`,
    /// then `cos^2 phi_d`.
    values: Vec<f64>,
    /// `x` beyond which `eval` is 0 ([`CUT`]).
    x_cut: f64,
    /// Per cell `[k, k + 1) / GUIDE` of cosines: the last of
    /// `points_mu` at or below its start (no binary search in `eval`).
    guide: Vec<u16>,
    /// The cosines of [`TwoCrossings::balance`] (ascending).
    scale_mu: Vec<f64>,
    /// The points of the energy factors: [`STEPS`] uniform in `mu` on
    /// `[0, scale_mu[0])` and on each interval between the cosines, then
    /// the last cosine.
    points_mu: Vec<f64>,
    /// The energy factors of the first and the second face
    /// ([`TwoCrossings::balance`]), linear between `points_mu` (constant
    /// beyond the last): per segment from point `p`, `a + b mu`; empty: 1.
    line: [Vec<[f64; 2]>; 2],
}

impl TwoCrossings {
    /// The round trip of a rough front `front` (air over a coating of index
    /// `front.eta`) over a smooth boundary to a base of relative index
    /// `eta_boundary` (`eta_b / eta_f`), tabulated; `None` if the front is
    /// not rough or there is no boundary (`eta_boundary = 1`).
    pub fn coat_return(front: RoughDielectric, eta_boundary: f64) -> Option<TwoCrossings> {
        if eta_boundary == 1.0 {
            return None;
        }
        Self::new_each(front, front, &[Between::Mirror { eta_boundary }], 1.0, true).map(|mut v| v.remove(0))
    }

    /// The unscattered transmission of a sheet of optical thickness `tau`
    /// between the rough faces `front` (crossed first) and `back` (crossed
    /// second, in its own frame: outside up), tabulated; `None` unless both
    /// faces are rough.
    pub fn unscattered(front: RoughDielectric, back: RoughDielectric, tau: f64) -> Option<TwoCrossings> {
        Self::unscattered_each(front, back, &[tau]).map(|mut v| v.remove(0))
    }

    /// [`TwoCrossings::unscattered`] for each optical thickness of `taus`
    /// (a coloured sheet's channels), in one pass over the tables' entries:
    /// only the attenuation differs between them, so each point of the
    /// integral is found once (a third of the time for three).
    pub fn unscattered_each(front: RoughDielectric, back: RoughDielectric, taus: &[f64]) -> Option<Vec<TwoCrossings>> {
        Self::unscattered_coated_each(front, back, 1.0, taus)
    }

    /// [`TwoCrossings::unscattered_each`] of a coated sheet: `front` is the
    /// rough air/coating interface (index `eta_f`), `back` the rough
    /// base/air face (`eta_b`), and between the front and the medium the
    /// light crosses the smooth coating/base boundary of relative index
    /// `boundary = eta_b / eta_f` (1: none, the uncoated sheet): refracted
    /// from the coating's direction `v_c` to the base's `v_b` (Snell), with
    /// the boundary's Fresnel transmittance `1 - F(|v_c,z|)` (0 where the
    /// coating's light is totally reflected), then `exp(-tau / |v_b,z|)` and
    /// the back face at `v_b`. Over the coating's directions the radiance's
    /// `n^2` scaling and the solid angles' change cancel (`eta_f^2 |v_c,z|
    /// dv_c = eta_b^2 |v_b,z| dv_b`), so `f_u(wi, wo) = int f_in(wi, v_c)
    /// |v_c,z| (1 - F) exp(-tau / |v_b,z|) f_out(u(v_b), wo) dv_c`. The
    /// light the boundary or the faces send back inside the coating
    /// (`F` and later terms) is broad and stays in the grid.
    pub fn unscattered_coated_each(
        front: RoughDielectric,
        back: RoughDielectric,
        boundary: f64,
        taus: &[f64],
    ) -> Option<Vec<TwoCrossings>> {
        let between: Vec<Between> = taus.iter().map(|&tau| Between::Straight { tau }).collect();
        Self::new_each(front, back, &between, boundary, front == back && boundary == 1.0)
    }

    /// The tables of the same two crossings with each of `between` (and a
    /// smooth `boundary` before the medium, [`TwoCrossings::unscattered_coated_each`]).
    fn new_each(
        front: RoughDielectric,
        second: RoughDielectric,
        between: &[Between],
        boundary: f64,
        folded: bool,
    ) -> Option<Vec<TwoCrossings>> {
        if !matches!(front.interface, Interface::Rough(_)) || !matches!(second.interface, Interface::Rough(_)) {
            return None;
        }
        if between.is_empty() {
            return Some(Vec::new());
        }
        // The outgoing direction turns by about (eta - 1) times each
        // micro-normal's tilt, the half vector by half of that, two
        // crossings: (eta - 1) m / sqrt 2 is about 1.4 times the lobe's
        // standard deviation in half-vector slope (the larger of the two
        // faces' for unequal faces). Twice that keeps the lobe's flanks off
        // the end of the axis, where its points thin out (the narrowest
        // lobe's energy through the table: 2.6% low at 60 degrees with
        // `sigma` itself, 1.6% with twice it).
        let sigma = 2.0 * face_width(&front).max(face_width(&second)).max(1e-4);
        let np = if folded { TABLE_SIZE[2] } else { 2 * TABLE_SIZE[2] - 1 };
        let me = TwoCrossings {
            front,
            second,
            between: between[0],
            boundary,
            folded,
            np,
            sigma,
            values: Vec::new(),
            x_cut: 1.0,
            guide: Vec::new(),
            scale_mu: Vec::new(),
            points_mu: Vec::new(),
            line: [Vec::new(), Vec::new()],
        };
        let [nx, nd, _] = TABLE_SIZE;
        let rule = gauss_legendre_01(TABLE_POINTS);
        let nb = between.len();
        let raw: Vec<f64> = (0..nx * nd * np)
            .into_par_iter()
            .flat_map_iter(|k| {
                let (a, b, c) = (k % nx, (k / nx) % nd, k / (nx * nd));
                let x = a as f64 / (nx - 1) as f64;
                let yd = b as f64 / (nd - 1) as f64;
                let cd = yd * yd;
                let c2 = c as f64 / (np - 1) as f64;
                let mut v = vec![0.0; nb];
                if let Some((wi, wo)) = me.directions(x, cd, c2) {
                    me.integral_each(wi, wo, &rule, between, &mut v);
                }
                v
            })
            .collect();
        Some(
            between
                .iter()
                .enumerate()
                .map(|(i, &b)| {
                    let values: Vec<f64> = raw.iter().skip(i).step_by(nb).copied().collect();
                    let largest = values.iter().cloned().fold(0.0, f64::max);
                    // Beyond the last point of x with a value above CUT of
                    // the largest, the table is below it: 0 there (module doc).
                    let last = (0..nx)
                        .rev()
                        .find(|&a| (0..nd * np).any(|k| values[a + nx * k] > CUT * largest))
                        .unwrap_or(0);
                    TwoCrossings {
                        between: b,
                        x_cut: ((last + 1) as f64 / (nx - 1) as f64).min(1.0),
                        values,
                        ..me.clone()
                    }
                })
                .collect(),
        )
    }

    /// What is between the crossings.
    pub fn between(&self) -> Between {
        self.between
    }

    /// The lobe's width in half-vector slope: the two crossings' turns of
    /// the direction, `(eta - 1) m / sqrt 2` each, added in quadrature.
    pub fn lobe_width(&self) -> f64 {
        face_width(&self.front).hypot(face_width(&self.second))
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
        let cp = if self.folded { c2.sqrt() } else { 2.0 * c2 - 1.0 };
        let sp = (1.0 - cp * cp).max(0.0).sqrt();
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
        let c2 = match (q > 0.0, self.folded) {
            (false, _) => 1.0,
            (true, true) => p1 * p1 / q,
            (true, false) => 0.5 * (1.0 + p1 / q.sqrt()),
        };
        Some((x, yd, c2))
    }

    /// `f_c(wi, wo)` (module doc) from the table, times the energy factors
    /// `r_1(mu_i) r_2(mu_o)` ([`TwoCrossings::balance`]); 0 unless both
    /// directions are above the face (the term exists for light on the
    /// coated side only).
    #[inline]
    pub fn eval(&self, wi: DVec3, wo: DVec3) -> f64 {
        let v = self.eval_table(wi, wo);
        if self.scale_mu.is_empty() || v == 0.0 {
            return v;
        }
        v * self.scale_at(0, wi.z) * self.scale_at(1, wo.z)
    }

    /// The energy factor of `face` at cosine `mu` (module doc; linear
    /// between its points, constant beyond the last): the guide's point
    /// for mu's cell, on to mu's own segment (a step at most), its line.
    #[inline]
    fn scale_at(&self, face: usize, mu: f64) -> f64 {
        let pm = &self.points_mu;
        let mut p = self.guide[((mu * GUIDE as f64) as usize).min(GUIDE - 1)] as usize;
        while p + 1 < pm.len() && pm[p + 1] <= mu {
            p += 1;
        }
        let [a, b] = self.line[face][p];
        a + b * mu
    }

    /// The cosine of the factors' point `p`.
    fn step_mu(&self, p: usize) -> f64 {
        let (m, k) = (&self.scale_mu, STEPS);
        if p < k {
            return (p as f64 / k as f64 * m[0]).max(1e-9);
        }
        let (i, s) = ((p - k) / k, (p - k) % k);
        if i + 1 >= m.len() {
            return m[m.len() - 1];
        }
        m[i] + (m[i + 1] - m[i]) * s as f64 / k as f64
    }

    /// Makes the albedo of [`TwoCrossings::eval`] (by
    /// [`TwoCrossings::albedo_of`]) the targets at each cosine of `mu`
    /// (ascending, at least two): `first[j]` for light arriving at the
    /// first face at `mu[j]`, `second[j]` for light arriving the other way
    /// (at the second face; by reciprocity `eval` with the directions
    /// exchanged). With `shapes`, also between the cosines: there the
    /// targets are the face's crossing shape `g(mu)` times the linear
    /// interpolation of the cosines' targets (below the first cosine, its
    /// target), the albedo the model's table gives its own light between
    /// its nodes (module doc). The factors `r_1(mu_i) r_2(mu_o)`, at the
    /// cosines (without `shapes`) or at [`STEPS`] points per interval
    /// (with), linear between them; one factor where the term is
    /// symmetric in its two directions (a mirror's round trip, equal
    /// faces), whose targets are then `first` both. At those points the
    /// albedo is `r_1[p] (A r_2)[p]` and `r_2[p] (B r_1)[p]`, with `A` and
    /// `B` the table's albedo on each factor's hat function (by the rule of
    /// `albedo_of`, so exact for it): a matrix scaling problem, solved by
    /// Sinkhorn's alternating iteration (for a symmetric term its
    /// symmetric form, the geometric mean of `r` and `t / (A r)`) to 1e-12
    /// or `BALANCE_ITERATIONS`. The two faces' targets must carry the
    /// same flux; where they do not (the projection's quadrature against
    /// the table's rule, about 1e-5 of it), the iteration stops once only
    /// the factors' common scale moves, and the caller takes up what the
    /// albedo misses (the model `slab` gives it to its table). Returns the
    /// albedo reached at each cosine of `mu`, for light at the first face
    /// and at the second (by the rule of `albedo_of`: equal to it to
    /// rounding, as `A` and `B` are).
    pub fn balance(&mut self, mu: &[f64], first: &[f64], second: &[f64], shapes: Option<Shapes>) -> [Vec<f64>; 2] {
        let mut reached = Self::balance_each(std::slice::from_mut(self), mu, &[(first, second)], shapes);
        reached.pop().expect("one term")
    }

    /// [`TwoCrossings::balance`] of several terms of one geometry (those of
    /// [`TwoCrossings::unscattered_each`]: the same faces, so the same
    /// table coordinates and rule, tables that differ by the attenuation),
    /// `targets[k]` term `k`'s `(first, second)`: the tables' albedo on the
    /// hat functions in one pass over the rule (each point's directions,
    /// coordinates and hat placed once, then read from every table),
    /// then each term's scaling. Returns each term's reached albedo.
    /// Terms of different geometries are balanced one by one.
    pub fn balance_each(
        terms: &mut [TwoCrossings],
        mu: &[f64],
        targets: &[(&[f64], &[f64])],
        shapes: Option<Shapes>,
    ) -> Vec<[Vec<f64>; 2]> {
        assert_eq!(terms.len(), targets.len(), "a target pair per term");
        let Some(first) = terms.first() else {
            return Vec::new();
        };
        let shared = terms.iter().all(|t| {
            t.sigma == first.sigma
                && t.folded == first.folded
                && t.np == first.np
                && t.values.len() == first.values.len()
        });
        if !shared {
            return terms
                .iter_mut()
                .zip(targets)
                .map(|(t, (a, b))| t.balance(mu, a, b, shapes))
                .collect();
        }
        let n = mu.len();
        let points = STEPS * n + 1;
        for t in terms.iter_mut() {
            t.scale_mu = mu.to_vec();
        }
        let fine: Vec<f64> = (0..points).map(|p| terms[0].step_mu(p)).collect();
        // Values at the cosines, linear at the points between them.
        let lerp = |t: &[f64], p: usize| -> f64 {
            let k = STEPS;
            if p < k {
                return t[0];
            }
            let (i, s) = ((p - k) / k, (p - k) % k);
            if i + 1 >= n {
                return t[n - 1];
            }
            let f = s as f64 / k as f64;
            t[i] * (1.0 - f) + t[i + 1] * f
        };
        // The cosines where the factors are balanced.
        let at: Vec<f64> = match shapes {
            Some(_) => fine.clone(),
            None => mu.to_vec(),
        };
        let m = at.len();
        // Where a cosine falls among `at`: hat functions `i` and `i + 1`
        // with weights `1 - t` and `t`; beyond either end, that end's.
        let place = |c: f64| -> (usize, f64) {
            if c <= at[0] {
                return (0, 0.0);
            }
            if c >= at[m - 1] {
                return (m - 1, 0.0);
            }
            let i = at.partition_point(|&x| x <= c).saturating_sub(1).min(m - 2);
            (i, (c - at[i]) / (at[i + 1] - at[i]))
        };
        // Per term, row p: the albedo at at[p] on each hat function of the
        // exit cosine (before any factor). The rule reaches the largest
        // `x_cut` (each table is 0 beyond its own, so a term's rows are
        // those of its own rule).
        let x_cut = terms.iter().map(|t| t.x_cut).fold(0.0, f64::max);
        let geometry = &terms[0];
        let count = terms.len();
        let hats = |reverse: bool| -> Vec<Vec<Vec<f64>>> {
            let rows: Vec<Vec<Vec<f64>>> = at
                .par_iter()
                .map(|&c| {
                    let mut row = vec![vec![0.0; m]; count];
                    geometry.rule_within(
                        x_cut,
                        c,
                        ALBEDO_POINTS_PER_CELL,
                        ALBEDO_AZIMUTH_POINTS,
                        |wi, wo, weight| {
                            let (a, b) = if reverse { (wo, wi) } else { (wi, wo) };
                            let Some(coords) = geometry.coordinates(a, b) else {
                                return;
                            };
                            let (i, t) = place(wo.z);
                            for (term, row) in terms.iter().zip(row.iter_mut()) {
                                let v = term.lookup(coords);
                                if v != 0.0 {
                                    row[i] += weight * v * (1.0 - t);
                                    if t > 0.0 {
                                        row[i + 1] += weight * v * t;
                                    }
                                }
                            }
                        },
                    );
                    row
                })
                .collect();
            // Term-major, each row moved to its term.
            let mut per_term: Vec<Vec<Vec<f64>>> = (0..count).map(|_| Vec::with_capacity(m)).collect();
            for r in rows {
                for (term, row) in per_term.iter_mut().zip(r) {
                    term.push(row);
                }
            }
            per_term
        };
        let a_all = hats(false);
        let b_all = (!geometry.folded).then(|| hats(true));
        // Each term's scaling on its own (a serial iteration of about 9 ms
        // each, so the channels' terms of a coloured sheet side by side).
        terms
            .par_iter_mut()
            .zip(targets.par_iter())
            .enumerate()
            .map(|(k, (term, &(first, second)))| {
                let tg: [Vec<f64>; 2] = match shapes {
                    Some(g) => [(first, g[0]), (second, g[1])]
                        .map(|(t, g)| (0..points).map(|p| g(fine[p]) * lerp(t, p)).collect()),
                    None => [first.to_vec(), second.to_vec()],
                };
                let b = b_all.as_ref().map(|b| &b[k]);
                term.scale_to(&a_all[k], b, &tg, &fine, n, shapes.is_some(), &lerp)
            })
            .collect()
    }

    /// The matrix scaling of [`TwoCrossings::balance`] on the hat albedos
    /// `a` (light at the first face) and `b` (at the second; `None` for a
    /// symmetric term) to `targets` at the points `fine` (`shaped`: the
    /// factors at every point; else at the `n` cosines, `lerp` between),
    /// and the factors' lines and guide. Returns the albedo reached at the
    /// cosines.
    #[allow(clippy::too_many_arguments)]
    fn scale_to(
        &mut self,
        a: &[Vec<f64>],
        b: Option<&Vec<Vec<f64>>>,
        targets: &[Vec<f64>; 2],
        fine: &[f64],
        n: usize,
        shaped: bool,
        lerp: &(dyn Fn(&[f64], usize) -> f64 + Sync),
    ) -> [Vec<f64>; 2] {
        let m = a.len();
        let points = fine.len();
        let times = |k: &[Vec<f64>], r: &[f64]| -> Vec<f64> {
            k.iter()
                .map(|row| row.iter().zip(r).map(|(a, b)| a * b).sum())
                .collect()
        };
        let update = |r: &mut [f64], k: &[f64], t: &[f64], geometric: bool| -> f64 {
            let mut change = 0.0f64;
            for ((r, k), t) in r.iter_mut().zip(k).zip(t) {
                if *k > 0.0 && *t > 0.0 {
                    let new = if geometric { (*r * t / k).sqrt() } else { t / k };
                    change = change.max((new / *r - 1.0).abs());
                    *r = new;
                }
            }
            change
        };
        let (mut r1, mut r2) = (vec![1.0; m], vec![1.0; m]);
        if let Some(b) = b {
            let mut last = f64::INFINITY;
            for _ in 0..BALANCE_ITERATIONS {
                let k = times(a, &r2);
                let c1 = update(&mut r1, &k, &targets[0], false);
                let k = times(b, &r1);
                let c2 = update(&mut r2, &k, &targets[1], false);
                let change = c1.max(c2);
                // Converged, or only the two factors' common scale still
                // moving (targets whose fluxes differ by that much).
                if change < 1e-12 || (change - last).abs() < 1e-3 * change {
                    break;
                }
                last = change;
            }
        } else {
            for _ in 0..BALANCE_ITERATIONS {
                let k = times(a, &r1);
                if update(&mut r1, &k, &targets[0], true) < 1e-12 {
                    break;
                }
            }
            r2.clone_from(&r1);
        }
        // The albedo reached at the cosines (a symmetric term's the same
        // both ways), before the factors go to their points.
        let node = |j: usize| if shaped { STEPS * (j + 1) } else { j };
        let reached_first: Vec<f64> = {
            let k = times(a, &r2);
            (0..n).map(|j| r1[node(j)] * k[node(j)]).collect()
        };
        let reached_second = match b {
            Some(b) => {
                let k = times(b, &r1);
                (0..n).map(|j| r2[node(j)] * k[node(j)]).collect()
            }
            None => reached_first.clone(),
        };
        let values = if shaped {
            [r1, r2]
        } else {
            [r1, r2].map(|r| (0..points).map(|p| lerp(&r, p)).collect())
        };
        // Each segment's line through its two points; the last constant.
        self.line = values.map(|v| {
            (0..points)
                .map(|p| {
                    if p + 1 == points {
                        return [v[p], 0.0];
                    }
                    let b = (v[p + 1] - v[p]) / (fine[p + 1] - fine[p]);
                    [v[p] - b * fine[p], b]
                })
                .collect()
        });
        self.guide = (0..GUIDE)
            .map(|k| {
                let at = k as f64 / GUIDE as f64;
                fine.partition_point(|&x| x <= at).saturating_sub(1) as u16
            })
            .collect();
        self.points_mu = fine.to_vec();
        [reached_first, reached_second]
    }

    /// `int f(wi, wo) mu_o dwo` for `wi` at cosine `mu` (azimuth 0) over
    /// the outgoing hemisphere, by the half vector `h` (`wo = 2 (wi.h) h -
    /// wi`, `dwo = 4 (wi.h) dh`) in the table's coordinate `x` (so the rule
    /// gathers where the lobe is) and its azimuth: Gauss-Legendre on each
    /// of the table's intervals in `x` ([`ALBEDO_POINTS_PER_CELL`]; the
    /// table is linear in `x` there) and in the azimuth
    /// ([`ALBEDO_AZIMUTH_POINTS`]; the lobe is even in it).
    pub fn albedo_of(&self, mu: f64, f: impl Fn(DVec3, DVec3) -> f64) -> f64 {
        self.albedo_with(mu, ALBEDO_POINTS_PER_CELL, ALBEDO_AZIMUTH_POINTS, f)
    }

    /// [`TwoCrossings::albedo_of`] with `per_cell` points on each of the
    /// table's intervals in `x` and `azimuth` points in the half vector's
    /// azimuth: a finer rule to check it by.
    pub fn albedo_with(&self, mu: f64, per_cell: usize, azimuth: usize, f: impl Fn(DVec3, DVec3) -> f64) -> f64 {
        let mut sum = 0.0;
        self.rule_within(self.x_cut, mu, per_cell, azimuth, |wi, wo, weight| {
            sum += weight * f(wi, wo)
        });
        sum
    }

    /// The rule of [`TwoCrossings::albedo_with`]: calls `add(wi, wo,
    /// weight)` at each of its points (`weight` includes `mu_o` and the
    /// rule's Jacobian), with `per_cell` points per interval of the table
    /// in `x` up to `x_cut` (the term's own, beyond which `eval` is 0, or a
    /// larger one shared by terms of one geometry) and `azimuth` points in
    /// the half vector's azimuth.
    fn rule_within(
        &self,
        x_cut: f64,
        mu: f64,
        per_cell: usize,
        azimuth: usize,
        mut add: impl FnMut(DVec3, DVec3, f64),
    ) {
        let wi = DVec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
        let (u, w) = gauss_legendre_01(per_cell);
        let (v, wv) = gauss_legendre_01(azimuth);
        // The half vector's azimuths, the same in every cell.
        let azimuths: Vec<(f64, f64, f64)> = v
            .iter()
            .zip(&wv)
            .map(|(y, wy)| {
                let (s, c) = (std::f64::consts::PI * y).sin_cos();
                (c, s, *wy)
            })
            .collect();
        let nx = TABLE_SIZE[0] - 1;
        let cells = ((x_cut * nx as f64).ceil() as usize).clamp(1, nx);
        for cell in 0..cells {
            for (xu, wxu) in u.iter().zip(&w) {
                let x = (cell as f64 + xu) / nx as f64;
                let wx = wxu / nx as f64;
                // tan theta_h = sigma x / (1 - x).
                let t = self.sigma * x / (1.0 - x);
                let th = t.atan();
                let dth = self.sigma / ((1.0 - x) * (1.0 - x) * (1.0 + t * t));
                let (sh, ch) = th.sin_cos();
                for &(c, s, wy) in &azimuths {
                    let h = DVec3::new(sh * c, sh * s, ch);
                    let wh = wi.dot(h);
                    if wh <= 0.0 {
                        continue;
                    }
                    let wo = h * (2.0 * wh) - wi;
                    if wo.z <= 0.0 {
                        continue;
                    }
                    // Both signs of the azimuth: 2 pi in all.
                    add(
                        wi,
                        wo,
                        wx * wy * 2.0 * std::f64::consts::PI * dth * sh * 4.0 * wh * wo.z,
                    );
                }
            }
        }
    }

    /// [`TwoCrossings::eval`] before the energy factors.
    fn eval_table(&self, wi: DVec3, wo: DVec3) -> f64 {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        match self.coordinates(wi, wo) {
            Some(coords) => self.lookup(coords),
            None => 0.0,
        }
    }

    /// The table at its coordinates `(x, yd, c2)` ([`TwoCrossings::coordinates`]):
    /// trilinear, 0 beyond `x_cut`.
    #[inline]
    fn lookup(&self, (x, yd, c2): (f64, f64, f64)) -> f64 {
        if x > self.x_cut {
            return 0.0;
        }
        let [nx, nd, _] = TABLE_SIZE;
        let np = self.np;
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

    /// The term at `(wi, wo)` (both above their faces) by its integral
    /// (module doc, "Evaluation"): both crossings' visible normals on a
    /// Gauss-Legendre product rule, `points` per axis of each sampler's
    /// unit square, by the balance heuristic. For `v` from the first
    /// sampler alone the weight would be `(1 - F(wi.h)) G(wi, v) /
    /// G1_exact(wi)` (`G` the face's Smith term, Walter's rational
    /// approximation for Beckmann; the samplers' `G1` is exact) times what
    /// is between and `f_out`. Within 1.8e-3 of a brute-force integral
    /// over `v` on 64 points (tests/two_crossings.rs).
    pub fn exact(&self, wi: DVec3, wo: DVec3, points: usize) -> f64 {
        let mut v = [0.0];
        self.integral_each(wi, wo, &gauss_legendre_01(points), &[self.between], &mut v);
        v[0]
    }

    /// [`TwoCrossings::exact`] on the Gauss-Legendre rule `(u, w)` on `[0, 1]`
    /// (the table's entries share one): both crossings' samplers, each on
    /// the rule's product in its unit square, combined by the balance
    /// heuristic (module doc, "Evaluation"), into `out` for each of
    /// `between` (what is between the crossings; the rest is shared).
    fn integral_each(&self, wi: DVec3, wo: DVec3, (u, w): &(Vec<f64>, Vec<f64>), between: &[Between], out: &mut [f64]) {
        let (Interface::Rough(m1), Interface::Rough(m2)) = (self.front.interface, self.second.interface) else {
            return;
        };
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return;
        }
        let (eta1, eta2) = (self.front.eta, self.second.eta);
        // A coated sheet's boundary (`r = eta_b / eta_f`) between the
        // coating's direction `v_c` and the base's `v_b` (Snell's law keeps
        // `n sin theta`); both ways `None` where no direction refracts to it
        // (total reflection at the boundary, or base directions beyond the
        // coating's reach). Without one (`r = 1`) they are the same.
        let r = self.boundary;
        let snell = |v: DVec3, k: f64| -> Option<DVec3> {
            if r == 1.0 {
                return Some(v);
            }
            let (x, y) = (v.x * k, v.y * k);
            let z2 = 1.0 - x * x - y * y;
            (z2 > 0.0).then(|| DVec3::new(x, y, -z2.sqrt()))
        };
        let mut add = |weight: f64, v_c: DVec3, v_b: DVec3| {
            for (o, b) in out.iter_mut().zip(between) {
                *o += weight
                    * match *b {
                        Between::Mirror { eta_boundary } => fresnel_dielectric(-v_c.z, eta_boundary),
                        Between::Straight { tau } => (tau / v_b.z).exp(),
                    };
            }
        };
        let (out_i, out_o) = (Outside::new(&m1, wi), Outside::new(&m2, wo));
        // The integrand over the coating's (the medium's) directions `v_c`
        // and the two samplers' densities there.
        let point = |v_c: DVec3, v_b: DVec3| -> Option<(f64, f64, f64)> {
            // Towards the light from the second crossing (module doc).
            let back = DVec3::new(-v_b.x, -v_b.y, v_b.z);
            let (p1, f_in) = crossing(&m1, eta1, &out_i, v_c)?;
            // Walter's transmission out, radiance transport: `f_out |v_z|
            // eta^2` by reciprocity (the refraction's Jacobian holds
            // `eta^2`).
            let (p2, f_out) = crossing(&m2, eta2, &out_o, back)?;
            if r == 1.0 {
                return Some((f_in * f_out / (eta2 * eta2 * -v_c.z), p1, p2));
            }
            // Through the boundary (`TwoCrossings::unscattered_coated_each`):
            // its transmittance, and the second sampler's density, per solid
            // angle of `v_b`, per solid angle of `v_c` (`dv_b / dv_c =
            // |v_c,z| / (r^2 |v_b,z|)`).
            let t_b = 1.0 - fresnel_dielectric(-v_c.z, r);
            Some((
                f_in * t_b * f_out / (eta2 * eta2 * -v_b.z),
                p1,
                p2 * -v_c.z / (r * r * -v_b.z),
            ))
        };
        // A point of either sampler (the pair of directions it reached, if
        // any) with the rule's weight: the integrand over the sum of the
        // densities (the balance heuristic).
        let mut visit = |weight: f64, dirs: Option<(DVec3, DVec3)>| {
            if let Some((v_c, v_b)) = dirs {
                if let Some((f, p1, p2)) = point(v_c, v_b).filter(|q| q.0 > 0.0) {
                    add(weight * f / (p1 + p2), v_c, v_b);
                }
            }
        };
        // Both samplers' micro-normals on the rule's points.
        let (n1, n2) = (m1.visible_normal_grid(wi, u), m2.visible_normal_grid(wo, u));
        for (a, wa) in w.iter().enumerate() {
            for (b, wb) in w.iter().enumerate() {
                let k = a * u.len() + b;
                // From `wi` through the first face.
                let first = refract(wi, n1[k], 1.0 / eta1)
                    .filter(|v| v.z < 0.0)
                    .and_then(|v_c| snell(v_c, 1.0 / r).map(|v_b| (v_c, v_b)));
                visit(wa * wb, first);
                // From `wo` through the second face (the direction towards
                // the light there, mirrored back to the medium's `v_b`).
                let second = refract(wo, n2[k], 1.0 / eta2)
                    .filter(|t| t.z < 0.0)
                    .map(|t| DVec3::new(-t.x, -t.y, t.z))
                    .and_then(|v_b| snell(v_b, r).map(|v_c| (v_c, v_b)));
                visit(wa * wb, second);
            }
        }
    }

    /// Bytes held by the table.
    pub fn memory_bytes(&self) -> usize {
        (self.values.len() + 2 * (self.line[0].len() + self.line[1].len()) + self.scale_mu.len() + self.points_mu.len())
            * std::mem::size_of::<f64>()
            + self.guide.len() * 2
    }
}

/// The direction outside a crossing (`w`, above the face) with its masking
/// by the face `mf`, computed once for all the directions `v` inside that
/// [`crossing`] pairs it with: `G1_exact` (`1 / (1 + Lambda(w))`) and
/// `G1` as core's BSDF values have it (exact for GGX, Walter's rational
/// approximation for Beckmann), both for a micro-normal `w` sees from the
/// front (`crossing` returns `None` for the others).
#[derive(Clone, Copy, Debug)]
struct Outside {
    w: DVec3,
    g1_exact: f64,
    g1: f64,
}

impl Outside {
    fn new(mf: &Microfacet, w: DVec3) -> Outside {
        // `w` itself is a micro-normal `w` sees from the front (w.z > 0).
        Outside {
            w,
            g1_exact: mf.g1_exact(w, w),
            g1: mf.g1(w, w),
        }
    }
}

/// Light from outside `w` (above the face) refracted to `v` (below) by a
/// rough face `mf` of index `eta`: the density of `v` when the face's
/// visible normals from `w` are drawn and `w` refracted (`G1_exact(w, h)
/// (w.h) D(h) / w_z` times the refraction's Jacobian `eta^2 |v.h| / (w.h +
/// eta v.h)^2`, `h` the generalised half vector), and `f_in |v_z|`
/// (Walter's transmission in radiance transport, as the single sampler's
/// weight `(1 - F) G / G1_exact` times that density: `(1 - F) G (w.h) D
/// Jacobian / w_z`, `G = G1(w, h) G1(v, h)`). `None` where no micro-normal
/// refracts `w` to `v`.
#[inline]
fn crossing(mf: &Microfacet, eta: f64, out: &Outside, v: DVec3) -> Option<(f64, f64)> {
    let w = out.w;
    let s = w + v * eta;
    let h = if s.z < 0.0 { -s } else { s };
    let len = h.length();
    if len <= 0.0 {
        return None;
    }
    let h = h / len;
    let (wh, vh) = (w.dot(h), v.dot(h));
    if wh <= 0.0 || vh >= 0.0 {
        return None;
    }
    let d = mf.d(h);
    if d <= 0.0 {
        return None;
    }
    let denom = wh + eta * vh;
    let jacobian = eta * eta * -vh / (denom * denom);
    let lens = wh * d * jacobian / w.z;
    // `w` sees `h` from the front (wh > 0, w.z > 0): its masking is the
    // precomputed one.
    let p = out.g1_exact * lens;
    let f = (1.0 - fresnel_dielectric(wh, eta)) * (out.g1 * mf.g1(v, h)) * lens;
    Some((p, f))
}

/// How far a rough face turns a direction it refracts, in half-vector
/// slope: `(eta - 1) m / sqrt 2`, about 1.4 times the standard deviation
/// of the lobe it makes (module doc, "Evaluation").
fn face_width(f: &RoughDielectric) -> f64 {
    (f.eta - 1.0) * f.m * std::f64::consts::FRAC_1_SQRT_2
}
