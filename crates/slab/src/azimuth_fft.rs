//! Fourier coefficients of samples on the azimuth rule of
//! [`crate::interface::azimuth_rule`]: the one projection in azimuth of the
//! faces' projections (Walter's blocks and cell averages in
//! [`crate::interface`], the microsurface walk's kernel in
//! [`crate::face_walk`]). A matrix product with the rule's weighted
//! cosines, and by FFT for the long series of the walk's reflection at
//! grazing incidence (up to 640 orders,
//! [`crate::face_walk::outside_reflection`]).
//!
//! The rule on `[0, pi]` has `P = max(16, L)` panels of width `w = pi / P`
//! for `L` orders, the first split geometrically toward `phi = 0`
//! ([`crate::interface::AZIMUTH_GRADING_LEVELS`]), each with the same `q`
//! Gauss-Legendre points. The coefficients are
//! `c_m = sum_k w_k f(phi_k) cos(m phi_k)`. On the uniform panels
//! `p = 1 .. P - 1` the points are `phi = w (p + x_i)` with weights
//! `2 w w_i`, so their part of `c_m` is, per point `i` of the panel,
//! `2 w w_i Re[exp(i m w x_i) G_i(m)]` with
//! `G_i(m) = sum_p f(w (p + x_i)) exp(2 pi i m p / 2P)`: a discrete Fourier
//! transform of length `2P` (the samples padded with zeros), `O(P log P)`
//! per point of the panel instead of the matrix product's `O(P L)`. Two
//! real sequences share one complex transform (the real and imaginary
//! parts). The graded first panel (`15 q` points) keeps the matrix
//! product. `rustfft` (re-exported by `rustdct`) computes the transforms.
//!
//! Tested against the direct sums (unit tests below) to `1e-13` of the sum
//! of the terms' magnitudes.

use crate::interface::{azimuth_rule, AZIMUTH_GRADING_LEVELS, MIN_AZIMUTH_PANELS};
use nalgebra::DMatrix;
use paperbsdf_core::quadrature::gauss_legendre_01;
use rustdct::rustfft::num_complex::Complex;
use rustdct::rustfft::{Fft, FftPlanner};
use std::f64::consts::PI;
use std::sync::Arc;

/// Orders from which [`RuleProjection`] takes the uniform panels by FFT:
/// below it the matrix product is as fast (48 orders: 240 points per
/// series, a transform of 96 per point of the panel).
pub const FFT_MIN_ORDERS: usize = 128;

/// The Fourier projection of samples at the points of
/// `azimuth_rule(orders, q)` onto the orders `from..orders`, with the
/// rule's points (where the samples are taken).
pub struct RuleProjection {
    /// `(cos phi_k, sin phi_k)` of the rule's points.
    phis: Vec<(f64, f64)>,
    from: usize,
    orders: usize,
    q: usize,
    /// Uniform panels on `[0, pi]` (`P`).
    panels: usize,
    /// Points of the graded first panel (the first of the rule's points).
    graded: usize,
    /// `cos(m phi_k)` times the weight for the graded points (all points
    /// without the FFT), points x `orders - from`.
    cos_w: DMatrix<f64>,
    /// Per point `i` of a uniform panel: its weight `2 w w_i` and
    /// `(cos, sin)(m w x_i)` for `m` in `from..orders`.
    phases: Vec<(f64, Vec<(f64, f64)>)>,
    /// The inverse transform of length `2P` (`None`: matrix product only).
    fft: Option<Arc<dyn Fft<f64>>>,
}

impl RuleProjection {
    /// The projection for `azimuth_rule(orders, q)` onto `from..orders`,
    /// by FFT on the uniform panels from [`FFT_MIN_ORDERS`].
    pub fn new(orders: usize, q: usize, from: usize) -> RuleProjection {
        Self::with_fft(orders, q, from, orders >= FFT_MIN_ORDERS)
    }

    /// [`RuleProjection::new`] with the FFT chosen by `fft`.
    pub fn with_fft(orders: usize, q: usize, from: usize, fft: bool) -> RuleProjection {
        assert!(from < orders && q >= 1, "orders {from}..{orders}, q {q}");
        let rule = azimuth_rule(orders, q);
        let panels = MIN_AZIMUTH_PANELS.max(orders);
        let graded = q * (AZIMUTH_GRADING_LEVELS as usize + 1);
        debug_assert_eq!(rule.len(), graded + q * (panels - 1));
        let direct = if fft { graded } else { rule.len() };
        let cos_w = DMatrix::from_fn(direct, orders - from, |k, m| {
            rule[k].1 * ((from + m) as f64 * rule[k].0).cos()
        });
        let width = PI / panels as f64;
        let (x, w) = gauss_legendre_01(q);
        let phases = if fft {
            x.iter()
                .zip(&w)
                .map(|(&xi, &wi)| {
                    let ph = (from..orders)
                        .map(|m| {
                            let a = m as f64 * width * xi;
                            (a.cos(), a.sin())
                        })
                        .collect();
                    (2.0 * width * wi, ph)
                })
                .collect()
        } else {
            Vec::new()
        };
        RuleProjection {
            phis: rule.iter().map(|&(phi, _)| (phi.cos(), phi.sin())).collect(),
            from,
            orders,
            q,
            panels,
            graded,
            cos_w,
            phases,
            fft: fft.then(|| FftPlanner::new().plan_fft_inverse(2 * panels)),
        }
    }

    /// `(cos phi_k, sin phi_k)` of the rule's points, in its order.
    pub fn phis(&self) -> &[(f64, f64)] {
        &self.phis
    }

    /// The coefficients per row of [`RuleProjection::project`]'s result:
    /// `orders - from`.
    pub fn coefficients(&self) -> usize {
        self.orders - self.from
    }

    /// The coefficients of each row of `vals` (samples at the rule's
    /// points, in its order): rows x `orders - from`.
    pub fn project(&self, vals: &DMatrix<f64>) -> DMatrix<f64> {
        let Some(fft) = &self.fft else {
            return vals * &self.cos_w;
        };
        let rows = vals.nrows();
        let big_p = self.panels;
        let n = 2 * big_p;
        let mut out = vals.columns(0, self.graded) * &self.cos_w;
        let mut buf = vec![Complex::new(0.0, 0.0); n];
        let mut scratch = vec![Complex::new(0.0, 0.0); fft.get_inplace_scratch_len()];
        let at = |p: usize, i: usize| self.graded + (p - 1) * self.q + i;
        for r in 0..rows {
            for i0 in (0..self.q).step_by(2) {
                let i1 = (i0 + 1 < self.q).then_some(i0 + 1);
                buf.iter_mut().for_each(|z| *z = Complex::new(0.0, 0.0));
                for p in 1..big_p {
                    let im = i1.map_or(0.0, |i1| vals[(r, at(p, i1))]);
                    buf[p] = Complex::new(vals[(r, at(p, i0))], im);
                }
                fft.process_with_scratch(&mut buf, &mut scratch);
                // Split the two real sequences' transforms:
                // G0 = (Z(m) + conj Z(-m)) / 2, G1 = (Z(m) - conj Z(-m)) / 2i.
                let (w0, ph0) = &self.phases[i0];
                let second = i1.map(|i1| &self.phases[i1]);
                for (k, m) in (self.from..self.orders).enumerate() {
                    let z = buf[m];
                    let zc = buf[(n - m) % n].conj();
                    let g0 = 0.5 * (z + zc);
                    let (c0, s0) = ph0[k];
                    let mut v = w0 * (c0 * g0.re - s0 * g0.im);
                    if let Some((w1, ph1)) = second {
                        let d = z - zc;
                        // (d / 2i) = (d.im, -d.re) / 2
                        let g1 = Complex::new(0.5 * d.im, -0.5 * d.re);
                        let (c1, s1) = ph1[k];
                        v += w1 * (c1 * g1.re - s1 * g1.im);
                    }
                    out[(r, k)] += v;
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The FFT's coefficients against the direct sums over the rule's
    /// points, for samples of a narrow peak and of noise, with `q` odd and
    /// even, orders below and above the panels' minimum, and a range that
    /// does not start at 0: within `1e-13` of the sum of the terms'
    /// magnitudes (rounding of a transform of length `2P`: `log2(2P)`
    /// roundings per term).
    #[test]
    fn fft_matches_the_direct_sums() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(12345);
        for &(orders, q, from) in &[
            (8, 3, 0),
            (48, 4, 0),
            (131, 1, 5),
            (256, 4, 48),
            (640, 4, 48),
            (300, 5, 17),
        ] {
            let rule = azimuth_rule(orders, q);
            let rows = 3;
            let vals = DMatrix::from_fn(rows, rule.len(), |r, k| {
                let phi = rule[k].0;
                match r {
                    0 => (-(phi / 0.01).powi(2)).exp(),
                    1 => rng.gen_range(-0.5..0.5),
                    _ => 1.0 + phi.cos(),
                }
            });
            let fast = RuleProjection::with_fft(orders, q, from, true).project(&vals);
            let slow = RuleProjection::with_fft(orders, q, from, false).project(&vals);
            for r in 0..rows {
                let scale: f64 = (0..rule.len()).map(|k| (rule[k].1 * vals[(r, k)]).abs()).sum();
                for m in 0..orders - from {
                    let direct: f64 = (0..rule.len())
                        .map(|k| rule[k].1 * vals[(r, k)] * ((from + m) as f64 * rule[k].0).cos())
                        .sum();
                    for (name, got) in [("fft", fast[(r, m)]), ("product", slow[(r, m)])] {
                        assert!(
                            (got - direct).abs() <= 1e-13 * scale,
                            "{name}: orders {orders} q {q} row {r} m {}: {got} against {direct}",
                            from + m
                        );
                    }
                }
            }
        }
    }
}
