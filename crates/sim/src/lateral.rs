//! Where light leaves the slab: the lateral spread of reflected light, the
//! exact counterpart of the multipole profile `R(r)` of the supplement
//! (equations 1 and 2; section 1's photographed shadow edge).
//!
//! A collimated beam enters at the origin of the front face; each walk is the
//! simulator's own analog walk ([`Tracer::walk_with_exits_at`]: the same face
//! events, free paths and phase-function draws as every other estimate of this
//! crate), which reports the lateral offset of the point where the light
//! leaves. The flux leaving through the lit face (every order of scattering,
//! the first-surface reflection at offset 0 included) is binned by its offset
//! `x` along one axis: that is the line spread function of reflection, and its
//! running sum is the edge response of a half-plane illumination (module
//! `paperbsdf_metrics::edge`).
//!
//! The detector is an integrating one: all reflected flux counts, whatever its
//! direction (the multipole `R(r)` is a flux density too).

use crate::estimate::SimError;
use crate::slab::{Side, Slab};
use crate::walk::{Tally, Tracer};
use indicatif::{ProgressBar, ProgressStyle};
use paperbsdf_core::{DVec3, Rgb};
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;

/// Settings of [`simulate_exit_profile`].
#[derive(Clone, Debug, PartialEq)]
pub struct LateralConfig {
    /// Walks per distinct colour channel (rounded up to a multiple of `batches`).
    pub samples: u64,
    /// Independent batches (at least 2), run in parallel.
    pub batches: u32,
    /// Seed of the run.
    pub seed: u64,
    /// The histogram covers offsets `[-half_width, half_width]` mm; flux
    /// beyond is added to the outermost bins (so no flux is lost).
    pub half_width: f64,
    /// Number of bins (odd, so that offset 0 is the centre of a bin).
    pub bins: usize,
    /// Show a progress bar on standard error.
    pub progress: bool,
}

impl Default for LateralConfig {
    fn default() -> Self {
        LateralConfig {
            samples: 1 << 18,
            batches: 16,
            seed: 1,
            half_width: 5.0,
            bins: 5001,
            progress: false,
        }
    }
}

/// The reflected flux per unit incident flux, binned by the exit offset `x` (mm).
#[derive(Clone, Debug, PartialEq)]
pub struct ExitProfile {
    /// Half width of the histogram, mm.
    pub half_width: f64,
    /// Per channel, the flux in each bin (bin `k` covers
    /// `[-h + k w, -h + (k + 1) w]`, `w = 2 h / bins`); the sum is the reflectance.
    pub reflected: [Vec<f64>; 3],
    /// Total reflectance per channel.
    pub reflectance: Rgb,
    /// Standard error of the reflectance (from the batch means).
    pub reflectance_stderr: Rgb,
    /// Walks run per channel.
    pub samples: u64,
}

impl ExitProfile {
    /// Width of one bin, mm.
    pub fn bin_width(&self) -> f64 {
        2.0 * self.half_width / self.reflected[0].len() as f64
    }
    /// Centre of bin `k`, mm.
    pub fn bin_centre(&self, k: usize) -> f64 {
        -self.half_width + (k as f64 + 0.5) * self.bin_width()
    }
}

fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Simulates the lateral profile of the light reflected by `slab` for a
/// collimated beam from `wi` (unit, toward the light, `wi.z > 0`: the front face).
pub fn simulate_exit_profile(slab: &Slab, wi: DVec3, cfg: &LateralConfig) -> Result<ExitProfile, SimError> {
    if !(wi.is_finite() && (wi.length() - 1.0).abs() < 1e-6 && wi.z > 0.0) {
        return Err(SimError::BadDirection {
            what: "wi (must light the front face)",
            x: wi.x,
            y: wi.y,
            z: wi.z,
        });
    }
    if cfg.batches < 2 || cfg.samples == 0 {
        return Err(SimError::BadConfig {
            name: "batches",
            value: cfg.batches as f64,
            message: "need at least 2 batches and one walk",
        });
    }
    if !(cfg.half_width > 0.0 && cfg.half_width.is_finite()) || cfg.bins < 3 || cfg.bins.is_multiple_of(2) {
        return Err(SimError::BadConfig {
            name: "bins",
            value: cfg.bins as f64,
            message: "need an odd number of bins (at least 3) over a positive finite half width",
        });
    }
    let reps = slab.distinct_channels();
    let channels: Vec<usize> = (0..3).filter(|&c| reps[c] == c).collect();
    let nb = cfg.batches as u64;
    let per_batch = cfg.samples.div_ceil(nb).max(1);
    let pb = if cfg.progress {
        let pb = ProgressBar::new(per_batch * nb * channels.len() as u64);
        pb.set_style(
            ProgressStyle::with_template("lateral [{elapsed_precise}] {wide_bar} {pos}/{len} walks (eta {eta})")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        pb
    } else {
        ProgressBar::hidden()
    };
    let (h, nbins) = (cfg.half_width, cfg.bins);
    let inv_w = nbins as f64 / (2.0 * h);
    let lit = Side::of(wi);
    let jobs: Vec<(usize, u64)> = channels.iter().flat_map(|&c| (0..nb).map(move |b| (c, b))).collect();
    let results: Vec<(usize, Vec<f64>, f64)> = jobs
        .par_iter()
        .map(|&(c, b)| {
            let mut rng = Pcg64Mcg::seed_from_u64(mix(cfg.seed ^ mix(0x1a7e_u64 ^ mix(((c as u64) << 48) ^ b))));
            let tracer = Tracer::new(slab, c, &[]);
            let mut hist = vec![0.0; nbins];
            let mut r = 0.0;
            let mut tally = Tally::new(0);
            for i in 0..per_batch {
                tally.clear();
                tracer.walk_with_exits_at(wi, &mut rng, &mut tally, &mut |dir, flux, xy| {
                    if Side::of(dir) == lit {
                        let k = ((xy.x + h) * inv_w).floor().clamp(0.0, (nbins - 1) as f64) as usize;
                        hist[k] += flux;
                        r += flux;
                    }
                });
                if i % 1024 == 1023 {
                    pb.inc(1024);
                }
            }
            let inv = 1.0 / per_batch as f64;
            hist.iter_mut().for_each(|v| *v *= inv);
            (c, hist, r * inv)
        })
        .collect();
    pb.finish_and_clear();
    let mut reflected: [Vec<f64>; 3] = std::array::from_fn(|_| vec![0.0; nbins]);
    let (mut mean, mut se) = (Rgb::ZERO, Rgb::ZERO);
    for &c in &channels {
        let rs: Vec<f64> = results.iter().filter(|x| x.0 == c).map(|x| x.2).collect();
        let n = rs.len() as f64;
        let m = rs.iter().sum::<f64>() / n;
        let var = rs.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0);
        mean.0[c] = m;
        se.0[c] = (var / n).sqrt();
        for (_, hist, _) in results.iter().filter(|x| x.0 == c) {
            for (a, v) in reflected[c].iter_mut().zip(hist) {
                *a += v / n;
            }
        }
    }
    for c in 0..3 {
        if reps[c] != c {
            reflected[c] = reflected[reps[c]].clone();
            mean.0[c] = mean.0[reps[c]];
            se.0[c] = se.0[reps[c]];
        }
    }
    Ok(ExitProfile {
        half_width: h,
        reflected,
        reflectance: mean,
        reflectance_stderr: se,
        samples: per_batch * nb,
    })
}
