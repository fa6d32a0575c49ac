//! Ground truth for the measurements: the simulator's exact random walk
//! through a pad of identical sheets separated by air gaps, over a black
//! cavity or a Lambertian backing, as the instruments see it.
//!
//! Each sheet is the simulator's slab ([`paperbsdf_sim::Slab`]) and each walk
//! inside a sheet is the simulator's own analog walk
//! ([`paperbsdf_sim::walk::Tracer::walk_with_exits`]); light leaving a sheet
//! into a gap enters the neighbouring sheet with the same direction (the
//! sheets are laterally infinite and the gaps are air), light leaving the last
//! sheet falls on the backing, which absorbs it (black) or reflects the
//! fraction `rho` into a cosine-distributed direction (Lambertian). Nothing is
//! assumed about the angular distribution in the gaps: this is what the
//! Kubelka/Stokes stacking of [`crate::instrument`] approximates.
//!
//! By reciprocity (every sheet has air on both sides), the `d/0` reading with
//! a gloss trap is the flux reflected for a collimated beam along the normal,
//! leaving out the exits within the trap's cone about the normal; the `15/d`
//! reading is the flux reflected for a beam at 15 degrees.

use paperbsdf_core::geometry::sample_cosine_hemisphere;
use paperbsdf_core::{DVec3, Rgb};
use paperbsdf_sim::walk::{Tally, Tracer};
use paperbsdf_sim::{Estimate, Slab};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;

/// What lies behind the pad.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Backing {
    /// A black cavity: light leaving the last sheet is gone.
    Black,
    /// A Lambertian reflector of this reflectance.
    Lambertian(f64),
}

/// Settings of a pad simulation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PadConfig {
    /// Photons per distinct channel (rounded up to a multiple of `batches`).
    pub samples: u64,
    /// Independent batches (at least 2), run in parallel.
    pub batches: u32,
    /// Seed.
    pub seed: u64,
}

impl Default for PadConfig {
    fn default() -> Self {
        PadConfig {
            samples: 1 << 16,
            batches: 16,
            seed: 7,
        }
    }
}

/// Result of [`simulate_pad`], per channel with standard errors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PadResult {
    /// Flux reflected by the pad (all directions).
    pub reflected: Estimate,
    /// Flux reflected outside the trap's cone (equal to `reflected` without a trap).
    pub reflected_trapped: Estimate,
    /// Flux leaving through the back of the last sheet (absorbed by a black backing).
    pub transmitted: Estimate,
}

fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Simulates `sheets` sheets of `slab` with air gaps over `backing`, lit by a
/// collimated beam from `wi` (toward the light, `wi.z > 0`); `trap_cos` is the
/// cosine of the trap's half-angle about the normal (`None`: no trap).
pub fn simulate_pad(
    slab: &Slab,
    sheets: usize,
    backing: Backing,
    wi: DVec3,
    trap_cos: Option<f64>,
    cfg: &PadConfig,
) -> PadResult {
    assert!(
        sheets >= 1 && wi.z > 0.0 && cfg.batches >= 2,
        "simulate_pad: bad arguments"
    );
    let reps = slab.distinct_channels();
    let channels: Vec<usize> = (0..3).filter(|&c| reps[c] == c).collect();
    let nb = cfg.batches as u64;
    let per = cfg.samples.div_ceil(nb).max(1);
    let jobs: Vec<(usize, u64)> = channels.iter().flat_map(|&c| (0..nb).map(move |b| (c, b))).collect();
    let res: Vec<(usize, [f64; 3])> = jobs
        .par_iter()
        .map(|&(c, b)| {
            let mut rng = Pcg64Mcg::seed_from_u64(mix(cfg.seed ^ mix(0x9ad_u64 ^ mix(((c as u64) << 40) ^ b))));
            let tracer = Tracer::new(slab, c, &[]);
            let mut tally = Tally::new(0);
            let (mut r, mut rt, mut t) = (0.0, 0.0, 0.0);
            for _ in 0..per {
                let (mut k, mut w_in, mut weight) = (0usize, wi, 1.0f64);
                loop {
                    tally.clear();
                    let mut exit = None;
                    tracer.walk_with_exits(w_in, &mut rng, &mut tally, &mut |d, f| exit = Some((d, f)));
                    let Some((dir, f)) = exit else { break };
                    weight *= f;
                    if dir.z > 0.0 {
                        if k == 0 {
                            r += weight;
                            if trap_cos.is_none_or(|c| dir.z <= c) {
                                rt += weight;
                            }
                            break;
                        }
                        k -= 1;
                        w_in = -dir;
                    } else if k + 1 == sheets {
                        match backing {
                            Backing::Black => {
                                t += weight;
                                break;
                            }
                            Backing::Lambertian(rho) => {
                                t += weight;
                                weight *= rho;
                                // Up from the backing: wi (toward the light) points down.
                                let u = sample_cosine_hemisphere([rng.gen(), rng.gen()]);
                                w_in = DVec3::new(u.x, u.y, -u.z);
                            }
                        }
                    } else {
                        k += 1;
                        w_in = -dir;
                    }
                    if weight < 0.01 {
                        if rng.gen::<f64>() < 0.1 {
                            weight *= 10.0;
                        } else {
                            break;
                        }
                    }
                }
            }
            let inv = 1.0 / per as f64;
            (c, [r * inv, rt * inv, t * inv])
        })
        .collect();
    let mut est = [Estimate {
        mean: Rgb::ZERO,
        stderr: Rgb::ZERO,
    }; 3];
    for &c in &channels {
        let v: Vec<[f64; 3]> = res.iter().filter(|x| x.0 == c).map(|x| x.1).collect();
        let n = v.len() as f64;
        for (q, e) in est.iter_mut().enumerate() {
            let m = v.iter().map(|x| x[q]).sum::<f64>() / n;
            let var = v.iter().map(|x| (x[q] - m).powi(2)).sum::<f64>() / (n - 1.0);
            e.mean.0[c] = m;
            e.stderr.0[c] = (var / n).sqrt();
        }
    }
    for (c, &rc) in reps.iter().enumerate() {
        if rc != c {
            for e in est.iter_mut() {
                e.mean.0[c] = e.mean.0[rc];
                e.stderr.0[c] = e.stderr.0[rc];
            }
        }
    }
    PadResult {
        reflected: est[0],
        reflected_trapped: est[1],
        transmitted: est[2],
    }
}
