//! Tables of the energy that Walter's single-scattering face drops and the
//! multiple-scattering face ([`crate::microsurface`]) returns: for diffuse
//! light, the fractions carried by orders >= 2 of the walk on the Smith
//! microsurface (Heitz, Hanika, d'Eon, Dachsbacher 2016), for the model's
//! compensation of energy-conserving faces (docs/design.md 4.1).
//!
//! At every other (distribution, eta, m) node of the grid of
//! [`crate::boundary::tables`] ([`eta_node`], [`m_node`]: 25 x 25 per
//! distribution, the same coordinates) the table holds four cosine-weighted hemispherical averages,
//! each `2 int_0^1 X(mu) mu dmu`, flux fractions (no `eta^2`):
//! `r_out2`, `t_out2` (light from outside reflected / transmitted by orders >= 2)
//! and `r_in2`, `t_in2` (light from inside, the medium side, total internal
//! reflection included), with the standard error of each. Generalised
//! reciprocity makes `t_out2 = eta^2 t_in2`, and energy conservation of the walk
//! `r_out2 + t_out2 = 1 - (R + T of Walter's face for diffuse light from outside)`
//! (the same from inside); both are tested, not imposed.
//!
//! The values are randomised quasi-Monte Carlo estimates
//! ([`hemispherical_estimate`]), written as little-endian f32
//! in `data/microsurface_tables.bin` by
//! `nice -n 10 cargo run --release -p paperbsdf-core --example gen_microsurface_tables`.
//! The `m = 0` nodes are exactly 0 (a smooth face scatters once); the `eta = 1`
//! nodes are the limit `eta -> 1+` of a rough face (an index-matched
//! microsurface still masks, and its walk returns that light).

use crate::boundary::tables::{bilinear_corners, decode_f32_table, eta_node, m_node};
use crate::microfacet::{Distribution, Microfacet};
use crate::microsurface::Microsurface;
use glam::DVec3;
use std::sync::OnceLock;

/// Walks per node and side of the committed table.
pub const TABLE_WALKS: usize = 24_000;
/// Every `STRIDE`-th node of the boundary tables' grid in each of eta and m is
/// a node here (the lost energy is smooth in (eta, m); the interpolation error
/// of the coarser grid is measured in the tests).
pub const STRIDE: usize = 2;
/// Nodes in eta (`boundary::tables::eta_node(STRIDE * i)`).
pub const N_ETA: usize = (crate::boundary::tables::N_ETA - 1) / STRIDE + 1;
/// Nodes in m (`boundary::tables::m_node(STRIDE * j)`).
pub const N_M: usize = (crate::boundary::tables::N_M - 1) / STRIDE + 1;
/// f32 values per node: `r_out2, t_out2, r_in2, t_in2` and their standard errors.
pub const NODE_LEN: usize = 8;
/// Number of f32 values in the table file.
pub const TABLE_LEN: usize = 2 * N_ETA * N_M * NODE_LEN;

/// Offset of node (dist, i, j) in the table (the layout of `boundary::tables`).
pub fn node_offset(dist: Distribution, i: usize, j: usize) -> usize {
    let d = match dist {
        Distribution::Ggx => 0,
        Distribution::Beckmann => 1,
    };
    ((d * N_ETA + i) * N_M + j) * NODE_LEN
}

/// Hemispherical fractions of the flux carried by orders >= 2 of the walk, for
/// diffuse (cosine-weighted) light (see the module doc).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LostEnergy {
    /// Light from outside, reflected by orders >= 2.
    pub r_out2: f64,
    /// Light from outside, transmitted by orders >= 2.
    pub t_out2: f64,
    /// Light from inside, reflected (back inside) by orders >= 2.
    pub r_in2: f64,
    /// Light from inside, transmitted (out) by orders >= 2.
    pub t_in2: f64,
}

/// A Monte Carlo estimate of the four values of a node, in the order
/// `r_out2, t_out2, r_in2, t_in2`, with their standard errors.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HemisphericalEstimate {
    /// The estimates.
    pub value: [f64; 4],
    /// Their standard errors (from the spread of the randomised replicas).
    pub std_err: [f64; 4],
}

impl HemisphericalEstimate {
    /// The values as a [`LostEnergy`].
    pub fn lost_energy(&self) -> LostEnergy {
        LostEnergy {
            r_out2: self.value[0],
            t_out2: self.value[1],
            r_in2: self.value[2],
            t_in2: self.value[3],
        }
    }
}

/// Independent randomised replicas of the quasi-Monte Carlo estimate in
/// [`hemispherical_estimate`] (their spread gives the standard error).
pub const REPLICAS: usize = 16;

/// Estimates the four hemispherical values of the face (dist, eta, m) with
/// `walks` walks per side, from the uniform numbers of `rnd`. The incident
/// cosine and the three numbers of the first
/// scattering event (the facet and the Fresnel choice, where most of the
/// variance is) come from a 4-dimensional rank-1 lattice (the cosine drawn from
/// a mixture that also covers grazing incidence, weighted) (Roberts' `R_4`
/// sequence), randomly shifted in each of [`REPLICAS`] replicas (Cranley-Patterson
/// rotation: unbiased, and the replicas' spread is an honest standard error);
/// the rest of each walk is plain Monte Carlo with the escapes replaced by
/// their expected value. `eta = 1` is the limit of a rough face as
/// `eta -> 1+`; `m = 0` (smooth) gives exactly 0.
pub fn hemispherical_estimate(
    dist: Distribution,
    eta: f64,
    m: f64,
    walks: usize,
    rnd: &mut impl FnMut() -> f64,
) -> HemisphericalEstimate {
    let mut out = HemisphericalEstimate::default();
    if m <= 0.0 || walks == 0 {
        return out;
    }
    let s = Microsurface::new(Microfacet::new(dist, m), eta);
    // R_4: alpha_k = phi^-k with phi the real root of x^5 = x + 1.
    let phi = 1.167_303_978_261_418_7_f64;
    let alpha = [1.0 / phi, phi.powi(-2), phi.powi(-3), phi.powi(-4)];
    let per = walks.div_ceil(REPLICAS);
    // The width of the grazing band where a nearly smooth face loses its energy.
    let scale = (0.25 * m).max(1e-5);
    for (side, sign) in [(0usize, 1.0f64), (1, -1.0)] {
        let mut reps = [[0.0f64; 2]; REPLICAS];
        for rep in reps.iter_mut() {
            let shift = [rnd(), rnd(), rnd(), rnd()];
            for k in 0..per {
                let mut q = [0.0; 4];
                for d in 0..4 {
                    q[d] = (shift[d] + (k as f64 + 1.0) * alpha[d]).fract();
                }
                let mu_c = (sign < 0.0 && eta > 1.0).then(|| crate::boundary::critical_mu(eta));
                let (mu, weight) = incidence(q[0], scale, mu_c);
                let a = DVec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, sign * mu);
                let mut used = 0;
                let mut next = || {
                    used += 1;
                    if used < 4 {
                        q[used]
                    } else {
                        rnd()
                    }
                };
                let (r, t) = s.higher_order_albedo_estimate(a, &mut next);
                rep[0] += weight * r / per as f64;
                rep[1] += weight * t / per as f64;
            }
        }
        for q in 0..2 {
            let n = REPLICAS as f64;
            let mean = reps.iter().map(|r| r[q]).sum::<f64>() / n;
            let var = reps.iter().map(|r| (r[q] - mean) * (r[q] - mean)).sum::<f64>() / (n - 1.0);
            out.value[2 * side + q] = mean;
            out.std_err[2 * side + q] = (var / n).sqrt();
        }
    }
    out
}

/// The incident cosine for the uniform number `x`, and its weight: drawn from
/// an equal mixture of the cosine-weighted density `2 mu`, a density
/// `1 / ((mu + w) ln(1 + 1/w))` uniform in `ln(mu + w)` (`w` = `scale`), which
/// puts samples where a nearly smooth face loses energy at grazing (`mu < m`,
/// which cosine weighting reaches with probability `m^2`), and, from inside
/// (`mu_c` = the critical cosine, `Some`), a density uniform in
/// `ln(|mu - mu_c| + w')` on each side of the critical angle
/// (`w' = scale sin theta_c`), where a nearly smooth face loses the light it
/// refracts out at grazing. The weight `2 mu / p(mu)` makes the average over
/// `x` the cosine-weighted mean.
#[inline]
fn incidence(x: f64, scale: f64, mu_c: Option<f64>) -> (f64, f64) {
    let k = if mu_c.is_some() { 3.0 } else { 2.0 };
    let l = (1.0 + 1.0 / scale).ln();
    let crit = mu_c.map(|c| {
        let w = (scale * (1.0 - c * c).sqrt()).max(1e-6);
        (c, w, (1.0 + c / w).ln(), (1.0 + (1.0 - c) / w).ln())
    });
    let y = x * k;
    let mu = if y < 1.0 {
        y.sqrt()
    } else if y < 2.0 {
        scale * (((y - 1.0) * l).exp() - 1.0)
    } else {
        let (c, w, l_lo, l_hi) = crit.expect("third component only with mu_c");
        let z = 2.0 * (y - 2.0);
        if z < 1.0 {
            c - w * ((z * l_lo).exp() - 1.0)
        } else {
            c + w * (((z - 1.0) * l_hi).exp() - 1.0)
        }
    }
    .clamp(1e-9, 1.0);
    let mut p = 2.0 * mu + 1.0 / ((mu + scale) * l);
    if let Some((c, w, l_lo, l_hi)) = crit {
        let d = (mu - c).abs();
        p += 0.5 / ((d + w) * if mu < c { l_lo } else { l_hi });
    }
    (mu, 2.0 * mu * k / p)
}

static TABLE_BYTES: &[u8] = include_bytes!("../data/microsurface_tables.bin");

fn table() -> &'static [f32] {
    static TABLE: OnceLock<Vec<f32>> = OnceLock::new();
    TABLE.get_or_init(|| decode_f32_table(TABLE_BYTES, TABLE_LEN, "microsurface_tables.bin"))
}

/// The stored values and standard errors of node (dist, i, j), as generated.
pub fn node(dist: Distribution, i: usize, j: usize) -> HemisphericalEstimate {
    let t = table();
    let o = node_offset(dist, i, j);
    let mut e = HemisphericalEstimate::default();
    for k in 0..4 {
        e.value[k] = t[o + k] as f64;
        e.std_err[k] = t[o + 4 + k] as f64;
    }
    e
}

/// The shares `(k_o, k_i)` of the energy-conserving face's compensation that
/// go to transmission, for light from outside and from inside: `k_o` is the
/// walk's own share `t_out2 / (t_out2 + r_out2)` of [`lost_energy`], and `k_i`
/// follows from reciprocity, `k_o Lbar_o = eta^2 k_i Lbar_i`, where `lbar_o`,
/// `lbar_i` are the hemispherical energies the single-scattering face loses
/// from outside and inside. Where that would need `k_i > 1` (the walk's share
/// is not reachable with separable lobes), `k_i = 1` and `k_o` is lowered to
/// keep reciprocity; with nothing lost inside (`lbar_i <= 1e-12`) both are 0.
/// Used by the Paper BSDF's faces and the adding-doubling faces of
/// `paperbsdf-slab`, so both compensate alike.
pub fn compensation_shares(dist: Distribution, eta: f64, m: f64, lbar_o: f64, lbar_i: f64) -> (f64, f64) {
    let lost = lost_energy(dist, eta, m);
    let tot = lost.t_out2 + lost.r_out2;
    let k_o = if tot > 0.0 {
        (lost.t_out2 / tot).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let e2 = eta * eta;
    if lbar_i > 1e-12 {
        let k_i = k_o * lbar_o.max(0.0) / (e2 * lbar_i);
        if k_i > 1.0 {
            (e2 * lbar_i / lbar_o, 1.0)
        } else {
            (k_o, k_i)
        }
    } else {
        (0.0, 0.0)
    }
}

/// The orders >= 2 fractions of the face (dist, eta, m), bilinear in the
/// coordinates of [`crate::boundary::tables`] (`sqrt((eta - 1) / 4)`,
/// `sqrt(m / (pi / 2))`). `eta` in [1, 5], `m` in [0, pi/2] (validate with
/// [`crate::RoughDielectric::new`]; values beyond are read at the grid's
/// edge). Continuous down to `m = 0` and `eta = 1`, where the nodes hold the
/// limits; a caller that treats `m < M_SMOOTH` as smooth or `eta = 1` as no
/// interface decides itself whether to use these (they are below 1e-6 for
/// `m < 1e-4`).
pub fn lost_energy(dist: Distribution, eta: f64, m: f64) -> LostEnergy {
    let mut v = [0.0; 4];
    for (ci, cj, w) in bilinear_corners(eta, m, N_ETA, N_M) {
        if w == 0.0 {
            continue;
        }
        let n = node(dist, ci, cj);
        for (a, b) in v.iter_mut().zip(n.value) {
            *a += w * b;
        }
    }
    LostEnergy {
        r_out2: v[0],
        t_out2: v[1],
        r_in2: v[2],
        t_in2: v[3],
    }
}

/// `(eta, m)` of node (i, j): those of node `(STRIDE i, STRIDE j)` of
/// [`crate::boundary::tables`].
pub fn node_eta_m(i: usize, j: usize) -> (f64, f64) {
    (eta_node(STRIDE * i), m_node(STRIDE * j))
}
