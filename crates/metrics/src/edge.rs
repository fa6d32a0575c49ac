//! Scatter distance: the response of reflected light to a hard shadow edge at
//! normal incidence (supplement, section 1 and Figure 2), its 5-95 % width,
//! and the same with a Gaussian instrument blur.
//!
//! Light falling on the half plane `x < 0` and reflected at offset `X` from its
//! point of entry is seen at `x' + X`; the reflected light at `x` is therefore
//! `R P(X > x)`, and its 95 %-to-5 % width is the distance between the 5 % and
//! 95 % quantiles of the flux-weighted distribution of `X` (the cumulative
//! line spread function `F(x) = P(X < x)`). The photographed edge is also
//! blurred by the camera: convolving with a Gaussian whose own 5-95 % width is
//! `w_b` (`sigma = w_b / (2 * 1.6449)`; the supplement's brushed metal gives
//! 0.2 mm) gives the width the supplement measured (0.72 mm on matte paper).
//!
//! - **Exact**: `F` from the simulator's lateral exit profile
//!   ([`paperbsdf_sim::lateral`]), every order of scattering and the
//!   first-surface reflection included.
//! - **Model**: the multipole reflectance profile `R(r)` (supplement eq. 1,
//!   Donner & Jensen 2005) that the model's multiple-scattering term
//!   integrates to `R_d`, built from [`paperbsdf_core::paper::multipole::Multipole`]
//!   with the internal diffuse reflectances of the model's own faces
//!   ([`sheet_multipoles`]: energy-compensated for `face_scattering =
//!   "multiple"`, the default, and with a front coating's boundary); it carries the model's
//!   multiple-scattering albedo at normal incidence (from
//!   `eval_component(.., Multiple)`), and the rest of the model's reflectance
//!   (surface and single scattering, which the BSDF places at the point of
//!   entry) is a step at `x = 0`.
//!
//! RGB: the widths are those of the luminance `Y` of the profile (channels
//! weighted by `Y_c R_c`).

use crate::instrument::Y_WEIGHTS;
use paperbsdf_core::models::ComponentModel;
use paperbsdf_core::paper::multipole::Multipole;
use paperbsdf_core::paper::{Component, PaperBsdf, Side};
use paperbsdf_core::quadrature::gauss_legendre_01;
use paperbsdf_core::sheet::Sheet;
use paperbsdf_core::{DVec3, PaperParams, Rgb};

/// 5-95 % width of the instrument blur of the supplement (brushed metal), mm.
pub const SUPPLEMENT_BLUR_MM: f64 = 0.2;
/// The standard normal quantile at 95 %.
const Z95: f64 = 1.644_853_626_951_472_2;

/// A cumulative profile `F(x) = P(X < x)` on a uniform grid.
#[derive(Clone, Debug, PartialEq)]
pub struct EdgeProfile {
    /// Grid start, mm.
    pub x0: f64,
    /// Grid step, mm.
    pub h: f64,
    /// `F` at `x0 + k h`, from 0 to 1.
    pub cdf: Vec<f64>,
}

impl EdgeProfile {
    /// The grid positions, mm.
    pub fn xs(&self) -> Vec<f64> {
        (0..self.cdf.len()).map(|k| self.x0 + k as f64 * self.h).collect()
    }

    /// The position where `F` first reaches `p` (linear interpolation).
    pub fn quantile(&self, p: f64) -> f64 {
        let c = &self.cdf;
        for k in 1..c.len() {
            if c[k] >= p {
                let (a, b) = (c[k - 1], c[k]);
                let t = if b > a { (p - a) / (b - a) } else { 0.5 };
                return self.x0 + (k as f64 - 1.0 + t) * self.h;
            }
        }
        self.x0 + (c.len() - 1) as f64 * self.h
    }

    /// The 5-95 % width, mm.
    pub fn width_5_95(&self) -> f64 {
        self.quantile(0.95) - self.quantile(0.05)
    }

    /// Convolved with a Gaussian of 5-95 % width `w` mm (`F` is 0 below and 1 above the grid).
    pub fn blurred(&self, w: f64) -> EdgeProfile {
        let sigma = w / (2.0 * Z95);
        if sigma <= 0.0 {
            return self.clone();
        }
        let half = (6.0 * sigma / self.h).ceil() as isize;
        let kern: Vec<f64> = (-half..=half)
            .map(|k| (-0.5 * (k as f64 * self.h / sigma).powi(2)).exp())
            .collect();
        let ks: f64 = kern.iter().sum();
        let n = self.cdf.len() as isize;
        // Pad the grid so the blurred profile also reaches 0 and 1.
        let pad = half;
        let m = n + 2 * pad;
        let at = |i: isize| -> f64 {
            if i < 0 {
                0.0
            } else if i >= n {
                1.0
            } else {
                self.cdf[i as usize]
            }
        };
        let cdf = (0..m)
            .map(|j| {
                let i = j - pad;
                kern.iter()
                    .enumerate()
                    .map(|(k, kv)| kv * at(i - (k as isize - half)))
                    .sum::<f64>()
                    / ks
            })
            .collect();
        EdgeProfile {
            x0: self.x0 - pad as f64 * self.h,
            h: self.h,
            cdf,
        }
    }

    /// The reflected light across the edge normalised to 1 in the lit region: `1 - F(x)`.
    pub fn edge_response(&self) -> Vec<f64> {
        self.cdf.iter().map(|f| 1.0 - f).collect()
    }
}

/// Scatter distances, mm.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct ScatterDistance {
    /// 5-95 % width of the edge response itself.
    pub width_mm: f64,
    /// With the supplement's instrument blur (a Gaussian of 5-95 % width 0.2 mm).
    pub width_blurred_mm: f64,
}

impl ScatterDistance {
    /// Both widths of a profile.
    pub fn of(p: &EdgeProfile) -> Self {
        ScatterDistance {
            width_mm: p.width_5_95(),
            width_blurred_mm: p.blurred(SUPPLEMENT_BLUR_MM).width_5_95(),
        }
    }
}

/// The multipole reflectance profile `R(r)` per unit area (1/mm^2) per unit
/// flux entering (supplement eq. 1): `a'/(4 pi) sum_i [z_r (1 + s d_r) e^{-s d_r}
/// / d_r^3 - z_v (1 + s d_v) e^{-s d_v} / d_v^3]`, `d = sqrt(r^2 + z^2)`,
/// `z_r,i = 2 i P + l`, `z_v,i = 2 i P - l - 2 z_b0`, `P = d + z_b0 + z_bd`,
/// summed over `i = -n..n` until further pairs change nothing (a pair's
/// contribution below 1e-12 of the sum; the pairs' sum converges like `1/i^3`).
pub fn multipole_r(m: &Multipole, r: f64) -> f64 {
    let p = m.d + m.zb_entry + m.zb_exit;
    let s = m.sigma_tr;
    let term = |z: f64| -> f64 {
        let dd = (r * r + z * z).sqrt();
        z * (1.0 + s * dd) * (-s * dd).exp() / (dd * dd * dd)
    };
    let pair = |i: f64| term(2.0 * i * p + m.l) - term(2.0 * i * p - m.l - 2.0 * m.zb_entry);
    let mut sum = pair(0.0);
    for i in 1..100_000 {
        let c = pair(i as f64) + pair(-(i as f64));
        sum += c;
        if i > 2 && c.abs() <= 1e-12 * sum.abs() {
            break;
        }
    }
    m.alpha_p / (4.0 * std::f64::consts::PI) * sum
}

/// `R(r)` tabulated on `r_k = r_max (k / N)^2` (dense where it peaks, near
/// the point of entry) and interpolated linearly in `k`.
struct RadialTable {
    r_max: f64,
    vals: Vec<f64>,
}

impl RadialTable {
    const N: usize = 4000;
    fn new(m: &Multipole, r_max: f64) -> Self {
        use rayon::prelude::*;
        let vals = (0..=Self::N)
            .into_par_iter()
            .map(|k| multipole_r(m, r_max * (k as f64 / Self::N as f64).powi(2)))
            .collect();
        RadialTable { r_max, vals }
    }
    fn at(&self, r: f64) -> f64 {
        if r >= self.r_max {
            return 0.0;
        }
        let u = (r.max(0.0) / self.r_max).sqrt() * Self::N as f64;
        let k = (u as usize).min(Self::N - 1);
        let t = u - k as f64;
        self.vals[k] * (1.0 - t) + self.vals[k + 1] * t
    }
}

/// `P(X > x)` for `x >= 0` under the radial profile `R(r)`, unnormalised:
/// `int_x^inf R(r) r 2 acos(x / r) dr` (the part of each ring beyond the line),
/// with `r = x + t^2` to remove the square-root edge of `acos`.
fn tail(tab: &RadialTable, x: f64, nodes: &(Vec<f64>, Vec<f64>)) -> f64 {
    let t_max = (tab.r_max - x).max(0.0).sqrt();
    let (xs, ws) = nodes;
    // Two panels: the first tenth of t (where R peaks for x ~ 0), then the rest.
    let mut s = 0.0;
    for (lo, hi) in [(0.0, 0.1 * t_max), (0.1 * t_max, t_max)] {
        for (&u, &w) in xs.iter().zip(ws) {
            let t = lo + (hi - lo) * u;
            let r = x + t * t;
            if r <= 0.0 {
                continue;
            }
            let ang = if x <= 0.0 {
                std::f64::consts::FRAC_PI_2
            } else {
                (x / r).clamp(-1.0, 1.0).acos()
            };
            s += w * (hi - lo) * tab.at(r) * r * 2.0 * ang * 2.0 * t;
        }
    }
    s
}

/// The multipoles (one per channel) of a sheet for light entering its front
/// face, as the Paper BSDF's multiple-scattering term builds them: reduced
/// scattering `sigma_s (1 - g)` (`g` the phase function's mean cosine) and
/// absorption of each channel, and the internal diffuse reflectances `rho_in`
/// of `paper`'s own faces ([`PaperBsdf::face_inside_hemispherical`]): Walter's
/// interface for `face_scattering = "single"`, with the energy compensation
/// for `"multiple"`, and over a front coating's smooth boundary when
/// `eta_f != eta_b`. `paper` must be the Paper BSDF of `p`.
pub fn sheet_multipoles(paper: &PaperBsdf, p: &PaperParams) -> Option<[Multipole; 3]> {
    let sheet = Sheet::from_params(p).ok()?;
    let (rf, rb) = (
        paper.face_inside_hemispherical(Side::Front).0,
        paper.face_inside_hemispherical(Side::Back).0,
    );
    let sigma_s_p = sheet.sigma_s * (1.0 - sheet.phase.mean_cosine());
    let out: [Option<Multipole>; 3] =
        std::array::from_fn(|c| Multipole::new(sigma_s_p.0[c], sheet.sigma_a.0[c], p.d, rf, rb));
    Some([out[0]?, out[1]?, out[2]?])
}

/// `F(x)` of one multipole on the grid `x0 + k h`, `k < n` (symmetric about 0).
fn multipole_cdf(m: &Multipole, x0: f64, h: f64, n: usize) -> Vec<f64> {
    let p = m.d + m.zb_entry + m.zb_exit;
    // R(r) decays like exp(-r / L) with L at most P / pi (the slab's lowest
    // mode) and 1 / sigma_tr: 60 L is far beyond anything that matters.
    let l_decay = (p / std::f64::consts::PI).min(if m.sigma_tr > 0.0 {
        1.0 / m.sigma_tr
    } else {
        f64::INFINITY
    });
    let r_max = 60.0 * l_decay + (x0.abs() + n as f64 * h);
    let tab = RadialTable::new(m, r_max);
    let nodes = gauss_legendre_01(32);
    let total = 2.0 * tail(&tab, 0.0, &nodes);
    (0..n)
        .map(|k| {
            let x = x0 + k as f64 * h;
            let tl = tail(&tab, x.abs(), &nodes) / total;
            if x >= 0.0 {
                1.0 - tl
            } else {
                tl
            }
        })
        .collect()
}

/// The model's edge profile (module doc): `model` is a Paper BSDF built from
/// `p` (the default one, or the reduced multilayer model); the multipole's
/// faces are those of the sheet of `p` as [`PaperBsdf::new`] builds them
/// (the internal reflectances do not depend on the options). `None` when
/// nothing scatters or `p` is invalid.
pub fn model_edge(model: &dyn ComponentModel, p: &PaperParams, half_width: f64, n: usize) -> Option<EdgeProfile> {
    let paper = PaperBsdf::new(p).ok()?;
    let mps = sheet_multipoles(&paper, p)?;
    // Reflectance at normal incidence: total (sampled albedo) and the multiple-scattering part.
    let (r_tot, _) = paperbsdf_core::bsdf::sampled_albedo(model, DVec3::Z, 128);
    let (x, w) = gauss_legendre_01(16);
    let mut r_ms = Rgb::ZERO;
    let nphi = 8;
    for (&u, &wu) in x.iter().zip(&w) {
        // Cosine-weighted: mu = sqrt(u), d(omega) cos = pi du over the azimuth average.
        let mu = u.sqrt();
        let s = (1.0 - mu * mu).max(0.0).sqrt();
        for j in 0..nphi {
            let phi = 2.0 * std::f64::consts::PI * (j as f64 + 0.5) / nphi as f64;
            let wo = DVec3::new(s * phi.cos(), s * phi.sin(), mu);
            r_ms += model.eval_component(DVec3::Z, wo, Component::Multiple) * (wu * std::f64::consts::PI / nphi as f64);
        }
    }
    let h = 2.0 * half_width / (n - 1) as f64;
    let x0 = -half_width;
    let mut cdf = vec![0.0; n];
    let mut wsum = 0.0;
    let reps: [usize; 3] = std::array::from_fn(|c| (0..c).find(|&k| mps[k] == mps[c]).unwrap_or(c));
    let mut per: [Option<Vec<f64>>; 3] = [None, None, None];
    for c in 0..3 {
        if reps[c] == c {
            per[c] = Some(multipole_cdf(&mps[c], x0, h, n));
        }
    }
    for c in 0..3 {
        let fc = per[reps[c]].as_ref()?;
        let ms = r_ms.0[c].clamp(0.0, r_tot.0[c].max(0.0));
        let local = (r_tot.0[c] - ms).max(0.0);
        let wc = Y_WEIGHTS[c];
        for (k, v) in cdf.iter_mut().enumerate() {
            let xk = x0 + k as f64 * h;
            let step = if xk > 0.0 {
                1.0
            } else if xk < 0.0 {
                0.0
            } else {
                0.5
            };
            *v += wc * (local * step + ms * fc[k]);
        }
        wsum += wc * (local + ms);
    }
    if wsum <= 0.0 {
        return None;
    }
    cdf.iter_mut().for_each(|v| *v /= wsum);
    Some(EdgeProfile { x0, h, cdf })
}

/// The exact edge profile from the simulator's lateral exit profile (luminance-weighted).
pub fn truth_edge(prof: &paperbsdf_sim::ExitProfile) -> Option<EdgeProfile> {
    let n = prof.reflected[0].len();
    let mut cdf = vec![0.0; n + 1];
    let mut acc = 0.0;
    let total: f64 = (0..3)
        .map(|c| Y_WEIGHTS[c] * prof.reflected[c].iter().sum::<f64>())
        .sum();
    if total <= 0.0 {
        return None;
    }
    for k in 0..n {
        acc += (0..3).map(|c| Y_WEIGHTS[c] * prof.reflected[c][k]).sum::<f64>();
        cdf[k + 1] = acc / total;
    }
    Some(EdgeProfile {
        x0: -prof.half_width,
        h: prof.bin_width(),
        cdf,
    })
}
