//! Running many walks: independent batches in parallel (rayon), means and
//! standard errors, optional adaptive stopping at a relative standard error,
//! and a progress bar.
//!
//! Every batch has its own PCG generator (`rand_pcg::Pcg64Mcg`) seeded from the
//! user's seed, the incident direction, the colour channel and the batch index,
//! so a run is reproducible for a given seed whatever the number of threads and
//! whatever other directions are simulated with it. The standard error of each
//! estimate is the standard deviation of the batch means over `sqrt(batches)`
//! (all batches have the same number of walks).
//!
//! Limits: at most [`MAX_BATCHES`] batches; each walk is cut after
//! [`SimConfig::max_collisions_per_walk`] collisions ([`MAX_COLLISIONS_PER_WALK`]
//! by default), and the runs report how many walks were cut ([`BsdfRun::truncated`]) so that a cut never biases a result
//! silently. [`estimate_work`] predicts the collisions a run will take (for a
//! refusal before absurd runs), and the achieved precision is reported
//! ([`BsdfRun::worst_rel_stderr`], [`BsdfRun::target_reached`]). When standard
//! error is not a terminal, progress is printed as a line every
//! [`PLAIN_PROGRESS_SECONDS`] seconds instead of a bar (the environment
//! variable `PAPERBSDF_PROGRESS_SECONDS` sets another interval, e.g. for logs).

mod work;

pub use work::{collisions_per_walk, estimate_work, measure_collision_rate, Work};

use crate::slab::Slab;
use crate::walk::{Tally, Tracer, MAX_COLLISIONS_PER_WALK};
use indicatif::{ProgressBar, ProgressStyle};
use paperbsdf_core::geometry::sample_cosine_hemisphere;
use paperbsdf_core::{DVec3, Rgb};
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;

/// Size of the per-batch pool of exit-face draws (see `Tracer::with_exit_pool`):
/// eight per walk, between 256 and 4096.
fn exit_pool_size(walks_per_batch: u64) -> usize {
    (walks_per_batch.saturating_mul(8)).clamp(256, 4096) as usize
}

/// Largest number of batches (each holds a vector of means; more batches add
/// nothing to the standard error's accuracy, which is already 1 part in 300).
pub const MAX_BATCHES: u32 = 100_000;

/// Seconds between progress lines when standard error is not a terminal.
pub const PLAIN_PROGRESS_SECONDS: u64 = 10;

/// How many walks to run and how.
#[derive(Clone, Debug, PartialEq)]
pub struct SimConfig {
    /// Walks per incident direction and colour channel (rounded up to a
    /// multiple of `batches`). With `rel_stderr` it is the first round's count.
    pub samples: u64,
    /// Number of independent batches the walks are split into (at least 2).
    pub batches: u32,
    /// Seed of the run.
    pub seed: u64,
    /// When set, keep adding rounds of batches until every estimate with a
    /// positive mean has `stderr <= rel_stderr * mean`, or `max_samples` is reached.
    pub rel_stderr: Option<f64>,
    /// Cap on the walks per incident direction and channel in adaptive mode.
    pub max_samples: u64,
    /// Show a progress bar on standard error (drawn only when it is a terminal).
    pub progress: bool,
    /// Also estimate `f` split by scattering order ([`BsdfRun::by_order`]).
    pub by_order: bool,
    /// Scattering events after which a walk is cut, at least 1 (default
    /// [`MAX_COLLISIONS_PER_WALK`], which cuts nothing in paper). The cut walks
    /// are counted ([`BsdfRun::truncated`]); their remaining flux is missing
    /// from every estimate. A bound on the work of absurd slabs, and a way for
    /// tests to reach the cut.
    pub max_collisions_per_walk: u64,
}

impl Default for SimConfig {
    fn default() -> Self {
        SimConfig {
            samples: 1 << 16,
            batches: 32,
            seed: 1,
            rel_stderr: None,
            max_samples: 1 << 26,
            progress: false,
            by_order: false,
            max_collisions_per_walk: MAX_COLLISIONS_PER_WALK as u64,
        }
    }
}

/// Errors of a simulation request.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    /// A direction that is not a unit vector or lies in the plane of the faces.
    #[error("{what} = ({x}, {y}, {z}) is not a unit vector off the plane of the faces (need |w| = 1 and w.z != 0)")]
    BadDirection {
        /// Which direction.
        what: &'static str,
        /// Components.
        x: f64,
        /// Components.
        y: f64,
        /// Components.
        z: f64,
    },
    /// A configuration value out of range.
    #[error("simulation setting `{name}` = {value}: {message}")]
    BadConfig {
        /// The setting.
        name: &'static str,
        /// Its value.
        value: f64,
        /// What is allowed.
        message: &'static str,
    },
}

/// A Monte Carlo estimate per colour channel with its standard error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    /// Mean.
    pub mean: Rgb,
    /// Standard error of the mean (from the spread of independent batch means).
    pub stderr: Rgb,
}

/// Result of [`simulate_bsdf`] for one incident direction.
#[derive(Clone, Debug, PartialEq)]
pub struct BsdfRun {
    /// `f(wi, wo_j)` without cosine for each requested `wo_j` (delta lobes excluded).
    pub f: Vec<Estimate>,
    /// Total reflectance (flux leaving through the lit face per unit incident flux).
    pub reflectance: Estimate,
    /// Total transmittance (flux leaving through the other face).
    pub transmittance: Estimate,
    /// With [`SimConfig::by_order`]: per `wo_j`, `f` from paths with 0, 1 and
    /// 2 or more volume scattering events (they sum to `f`). Order 0 is the
    /// lit face's reflection plus light that crossed the slab unscattered
    /// (internal reflections included); order 1 is single scattering with any
    /// surface bounces; the rest is multiple scattering.
    pub by_order: Option<Vec<[Estimate; 3]>>,
    /// Walks run per colour channel.
    pub samples: u64,
    /// Walks (over all channels) cut at [`SimConfig::max_collisions_per_walk`]
    /// collisions; each carried at most unit flux, which is added to no
    /// estimate, so at most `truncated / samples` of the incident flux is
    /// missing (per channel, for a run with one distinct channel; the channels
    /// of an RGB run add up). Zero for paper.
    pub truncated: u64,
    /// Volume scattering events simulated by the run, over all channels
    /// (`collisions / (samples * distinct channels)` is the mean per walk).
    pub collisions: u64,
    /// Largest `stderr / mean` over every estimate with a positive mean (0 when none).
    pub worst_rel_stderr: f64,
    /// With [`SimConfig::rel_stderr`]: whether the target was reached (else
    /// `max_samples` stopped the run). `true` without a target.
    pub target_reached: bool,
}

/// Totals of [`simulate_totals`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Totals {
    /// Total reflectance.
    pub reflectance: Estimate,
    /// Total transmittance.
    pub transmittance: Estimate,
    /// Walks run per colour channel.
    pub samples: u64,
    /// Walks cut at [`SimConfig::max_collisions_per_walk`] collisions (see [`BsdfRun::truncated`]).
    pub truncated: u64,
    /// Volume scattering events simulated by the run (see [`BsdfRun::collisions`]).
    pub collisions: u64,
    /// Largest `stderr / mean` over the estimates with a positive mean.
    pub worst_rel_stderr: f64,
    /// Whether the `rel_stderr` target was reached (see [`BsdfRun::target_reached`]).
    pub target_reached: bool,
}

/// How the incident light is distributed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Incidence {
    /// A collimated beam from direction `wi` (unit, toward the light).
    Collimated(DVec3),
    /// Diffuse (Lambertian, cosine-weighted) light on the front (`true`) or back face.
    Diffuse {
        /// Whether the light falls on the front face.
        front: bool,
    },
}

fn check_dir(what: &'static str, w: DVec3) -> Result<(), SimError> {
    if !(w.is_finite() && (w.length() - 1.0).abs() < 1e-6 && w.z != 0.0) {
        return Err(SimError::BadDirection {
            what,
            x: w.x,
            y: w.y,
            z: w.z,
        });
    }
    Ok(())
}

fn check_config(c: &SimConfig) -> Result<(), SimError> {
    if c.batches < 2 || c.batches > MAX_BATCHES {
        return Err(SimError::BadConfig {
            name: "batches",
            value: c.batches as f64,
            message: "need 2 to 100000 batches",
        });
    }
    if c.rel_stderr.is_some() && c.max_samples == 0 {
        return Err(SimError::BadConfig {
            name: "max_samples",
            value: 0.0,
            message: "need at least one walk",
        });
    }
    if c.samples == 0 {
        return Err(SimError::BadConfig {
            name: "samples",
            value: 0.0,
            message: "need at least one walk",
        });
    }
    if c.max_collisions_per_walk == 0 {
        return Err(SimError::BadConfig {
            name: "max_collisions_per_walk",
            value: 0.0,
            message: "allowed range is 1 to 18446744073709551615 collisions per walk (default 1e7)",
        });
    }
    if let Some(x) = c.rel_stderr {
        if !(x > 0.0 && x.is_finite()) {
            return Err(SimError::BadConfig {
                name: "rel_stderr",
                value: x,
                message: "must be positive and finite",
            });
        }
    }
    Ok(())
}

/// Largest optical thickness `sigma_t * d` simulated. Beyond it the mean free
/// path is below 1e-9 of the thickness, a few million units in the last place
/// of a depth near the back face, and rounding of the positions (subnormal
/// numbers near the front face for `sigma_s = 1e308`) biases the walk: such a
/// slab would give a wrong answer quietly, so it is refused. Paper is 10 to 100.
pub const MAX_OPTICAL_THICKNESS: f64 = 1e9;

/// Refuses a slab thicker than [`MAX_OPTICAL_THICKNESS`] in any channel.
pub fn check_slab(slab: &Slab) -> Result<(), SimError> {
    for c in 0..3 {
        let tau = slab.medium(c).sigma_t * slab.d;
        if tau.is_nan() || tau > MAX_OPTICAL_THICKNESS {
            return Err(SimError::BadConfig {
                name: "sigma_t * d",
                value: tau,
                message: "the slab is more than 1e9 mean free paths thick (sigma_t = sigma_a + sigma_s times d): \
the walk's depths cannot be resolved in double precision and the result would be wrong; \
nothing physical is that thick (paper is 10 to 100)",
            });
        }
    }
    Ok(())
}

/// SplitMix64 finaliser, to derive independent seeds.
fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

fn incidence_key(inc: Incidence) -> u64 {
    match inc {
        Incidence::Collimated(w) => mix(w.x.to_bits() ^ mix(w.y.to_bits() ^ mix(w.z.to_bits()))),
        Incidence::Diffuse { front } => mix(0xd1ff_u64 + front as u64),
    }
}

/// What a run did besides its estimates.
struct RunStats {
    samples: u64,
    truncated: u64,
    collisions: u64,
    worst_rel_stderr: f64,
    target_reached: bool,
}

/// Largest `stderr / mean` over the estimates with a positive mean.
fn worst_rel(est: &[Estimate]) -> f64 {
    let mut worst: f64 = 0.0;
    for e in est {
        for k in 0..3 {
            if e.mean.0[k] > 0.0 {
                worst = worst.max(e.stderr.0[k] / e.mean.0[k]);
            }
        }
    }
    worst
}

/// Runs the walks of one incident light distribution: batch means per
/// channel, each a vector `[f_0, .., f_{n-1}, R, T]`.
fn run(slab: &Slab, inc: Incidence, wos: &[DVec3], cfg: &SimConfig, pb: &ProgressBar) -> (Vec<Estimate>, RunStats) {
    let truncated = std::sync::atomic::AtomicU64::new(0);
    let collisions = std::sync::atomic::AtomicU64::new(0);
    let reps = slab.distinct_channels();
    let channels: Vec<usize> = (0..3).filter(|&c| reps[c] == c).collect();
    let nb = cfg.batches as u64;
    let per_batch = cfg.samples.div_ceil(nb).max(1);
    let key = incidence_key(inc);
    let n = wos.len();
    let n_out = n + 2 + if cfg.by_order { 3 * n } else { 0 };
    pb.set_length(per_batch * nb * channels.len() as u64);

    let run_batch = |c: usize, b: u64| -> Vec<f64> {
        let mut rng = Pcg64Mcg::seed_from_u64(mix(cfg.seed ^ mix(key ^ mix(((c as u64) << 48) ^ b))));
        let tracer = Tracer::with_exit_pool(slab, c, wos, exit_pool_size(per_batch), &mut rng)
            .with_max_collisions(usize::try_from(cfg.max_collisions_per_walk).unwrap_or(usize::MAX));
        let tr = &tracer;
        let (mut sum, mut one) = if cfg.by_order {
            (Tally::with_orders(n), Tally::with_orders(n))
        } else {
            (Tally::new(n), Tally::new(n))
        };
        for i in 0..per_batch {
            one.clear();
            let wi = match inc {
                Incidence::Collimated(w) => w,
                Incidence::Diffuse { front } => {
                    use rand::Rng;
                    let w = sample_cosine_hemisphere([rng.gen(), rng.gen()]);
                    if front {
                        w
                    } else {
                        DVec3::new(w.x, w.y, -w.z)
                    }
                }
            };
            if wi.z != 0.0 {
                tr.walk(wi, &mut rng, &mut one);
            }
            sum.add(&one);
            if i % 256 == 255 {
                pb.inc(256);
            }
        }
        pb.inc(per_batch % 256);
        collisions.fetch_add(sum.collisions, std::sync::atomic::Ordering::Relaxed);
        truncated.fetch_add(sum.truncated, std::sync::atomic::Ordering::Relaxed);
        let inv = 1.0 / per_batch as f64;
        let mut v: Vec<f64> = sum.f.iter().map(|x| x * inv).collect();
        v.push(sum.r * inv);
        v.push(sum.t * inv);
        if let Some(b) = &sum.by_order {
            for k in 0..3 {
                v.extend(b.iter().map(|x| x[k] * inv));
            }
        }
        v
    };

    // batch_means[c][b] = vector of n_out means.
    let mut batch_means: Vec<Vec<Vec<f64>>> = vec![Vec::new(); 3];
    let mut done_batches = 0u64;
    let mut target_batches = nb;
    loop {
        let jobs: Vec<(usize, u64)> = channels
            .iter()
            .flat_map(|&c| (done_batches..target_batches).map(move |b| (c, b)))
            .collect();
        let res: Vec<Vec<f64>> = jobs.par_iter().map(|&(c, b)| run_batch(c, b)).collect();
        for ((c, _), r) in jobs.iter().zip(res) {
            batch_means[*c].push(r);
        }
        done_batches = target_batches;
        let est = summarise(&batch_means, &reps, n_out);
        let achieved = worst_rel(&est);
        let stats = |reached: bool| RunStats {
            samples: done_batches * per_batch,
            truncated: truncated.load(std::sync::atomic::Ordering::Relaxed),
            collisions: collisions.load(std::sync::atomic::Ordering::Relaxed),
            worst_rel_stderr: achieved,
            target_reached: reached,
        };
        let Some(x) = cfg.rel_stderr else {
            return (est, stats(true));
        };
        // Worst ratio (stderr / (x mean)) over estimates with a positive mean.
        let worst = achieved / x;
        let max_batches = (cfg.max_samples / per_batch).max(nb);
        if worst <= 1.0 || done_batches >= max_batches {
            return (est, stats(worst <= 1.0));
        }
        // Walks needed scale with the square of the ratio; add 10% and at least one round's worth / 4.
        let need = ((done_batches as f64) * worst * worst * 1.1).ceil() as u64;
        target_batches = need.max(done_batches + nb / 4 + 1).min(max_batches);
        pb.inc_length((target_batches - done_batches) * per_batch * channels.len() as u64);
    }
}

fn summarise(batch_means: &[Vec<Vec<f64>>], reps: &[usize; 3], n_out: usize) -> Vec<Estimate> {
    let mut out = vec![
        Estimate {
            mean: Rgb::ZERO,
            stderr: Rgb::ZERO
        };
        n_out
    ];
    for c in 0..3 {
        let bm = &batch_means[reps[c]];
        let n = bm.len() as f64;
        for (j, o) in out.iter_mut().enumerate() {
            let mean = bm.iter().map(|v| v[j]).sum::<f64>() / n;
            let var = bm.iter().map(|v| (v[j] - mean).powi(2)).sum::<f64>() / (n - 1.0);
            o.mean.0[c] = mean;
            o.stderr.0[c] = (var / n).sqrt();
        }
    }
    out
}

/// Prints `pb`'s position as a line on standard error every
/// [`PLAIN_PROGRESS_SECONDS`] while `work` runs, when standard error is not a
/// terminal (indicatif draws nothing then); returns `work`'s result.
fn with_plain_progress<T: Send>(cfg: &SimConfig, pb: &ProgressBar, msg: &str, work: impl FnOnce() -> T + Send) -> T {
    use std::io::IsTerminal;
    if !cfg.progress || std::io::stderr().is_terminal() {
        return work();
    }
    let (tx, rx) = std::sync::mpsc::channel::<()>();
    std::thread::scope(|s| {
        s.spawn(move || {
            let start = std::time::Instant::now();
            let secs = std::env::var("PAPERBSDF_PROGRESS_SECONDS")
                .ok()
                .and_then(|v| v.parse::<f64>().ok())
                .filter(|v| v.is_finite() && *v > 0.0)
                .unwrap_or(PLAIN_PROGRESS_SECONDS as f64);
            let every = std::time::Duration::from_secs_f64(secs.min(1e6));
            while let Err(std::sync::mpsc::RecvTimeoutError::Timeout) = rx.recv_timeout(every) {
                let (pos, len) = (pb.position(), pb.length().unwrap_or(0));
                eprintln!(
                    "{msg}: {pos} of {len} walks ({:.0}%) after {:.0} s",
                    100.0 * pos as f64 / len.max(1) as f64,
                    start.elapsed().as_secs_f64()
                );
            }
        });
        let out = work();
        drop(tx);
        out
    })
}

fn progress_bar(cfg: &SimConfig, msg: &str) -> ProgressBar {
    if !cfg.progress {
        return ProgressBar::hidden();
    }
    // Counts positions even when nothing is drawn (standard error not a terminal).
    let pb = ProgressBar::with_draw_target(Some(0), indicatif::ProgressDrawTarget::stderr());
    pb.set_style(
        ProgressStyle::with_template("{msg} [{elapsed_precise}] {wide_bar} {pos}/{len} walks ({per_sec}, eta {eta})")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    pb.set_message(msg.to_string());
    pb
}

/// Simulates `f(wi, wo)` (without cosine) for one incident direction `wi` and
/// every `wo` in `wos` (unit vectors, slab frame, either side), with the total
/// reflectance and transmittance of the same walks.
pub fn simulate_bsdf(slab: &Slab, wi: DVec3, wos: &[DVec3], cfg: &SimConfig) -> Result<BsdfRun, SimError> {
    check_config(cfg)?;
    check_slab(slab)?;
    check_dir("wi", wi)?;
    for &wo in wos {
        check_dir("wo", wo)?;
    }
    let pb = progress_bar(cfg, "simulate");
    let (est, st) = with_plain_progress(cfg, &pb, "simulate", || {
        run(slab, Incidence::Collimated(wi), wos, cfg, &pb)
    });
    pb.finish_and_clear();
    let n = wos.len();
    let by_order = cfg.by_order.then(|| {
        (0..n)
            .map(|j| [est[n + 2 + j], est[2 * n + 2 + j], est[3 * n + 2 + j]])
            .collect()
    });
    Ok(BsdfRun {
        f: est[..n].to_vec(),
        reflectance: est[n],
        transmittance: est[n + 1],
        by_order,
        samples: st.samples,
        truncated: st.truncated,
        collisions: st.collisions,
        worst_rel_stderr: st.worst_rel_stderr,
        target_reached: st.target_reached,
    })
}

/// Simulates the total reflectance and transmittance for collimated or
/// diffuse incident light.
pub fn simulate_totals(slab: &Slab, inc: Incidence, cfg: &SimConfig) -> Result<Totals, SimError> {
    check_config(cfg)?;
    check_slab(slab)?;
    if let Incidence::Collimated(wi) = inc {
        check_dir("wi", wi)?;
    }
    let pb = progress_bar(cfg, "totals");
    let (est, st) = with_plain_progress(cfg, &pb, "totals", || run(slab, inc, &[], cfg, &pb));
    pb.finish_and_clear();
    Ok(Totals {
        reflectance: est[0],
        transmittance: est[1],
        samples: st.samples,
        truncated: st.truncated,
        collisions: st.collisions,
        worst_rel_stderr: st.worst_rel_stderr,
        target_reached: st.target_reached,
    })
}
