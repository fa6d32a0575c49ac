//! The predicted cost of a run ([`estimate_work`]), for a refusal or a time
//! estimate before absurd runs: an order-of-magnitude model of the collisions
//! per walk from the slab's optical thickness, albedo and face indices (the
//! exit time of a random walk from a strip, the returns by total internal
//! reflection, absorption and the per-walk cap; see [`collisions_per_walk`]),
//! and a pilot measurement of this machine's collision rate
//! ([`measure_collision_rate`]).

use super::SimConfig;
use crate::slab::Slab;
use crate::walk::{Tally, Tracer, MAX_COLLISIONS_PER_WALK};
use paperbsdf_core::DVec3;
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;

/// The predicted cost of a run, from the slab's optical properties.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Work {
    /// Predicted mean collisions per walk (worst colour channel).
    pub collisions_per_walk: f64,
    /// Walks over all channels (the first round's with `rel_stderr`; `max_samples` for `max_walks`).
    pub walks: f64,
    /// `walks * collisions_per_walk`.
    pub collisions: f64,
    /// The same with `rel_stderr` when every round up to `max_samples` is run.
    pub max_collisions: f64,
}

/// Predicted mean number of collisions of a walk in channel medium `m` of a
/// slab of thickness `d`, mm, between faces of relative index `eta` (the larger
/// one). Three bounds, the smallest applies: a random walk started near a face
/// leaves a slab of optical thickness `tau` after about `tau` collisions (mean
/// exit time of a walk one step from the edge of a strip `tau` wide), times
/// the returns from the faces' total internal reflection, `1 / (1 - R_int)`
/// with `R_int = 1 - 1 / eta^2` for diffuse light inside; absorption ends it
/// after about `6 / (1 - albedo)` (weight 0.01 then Russian roulette with
/// survival 0.1); and the per-walk cap makes the heavy tail of a conservative
/// half-space (`P(N > n) ~ n^-1/2`) cost about `2 sqrt(MAX_COLLISIONS_PER_WALK)`.
/// An order-of-magnitude model, checked to a factor of 3 in `tests/limits.rs`.
pub fn collisions_per_walk(m: crate::slab::Medium, d: f64, eta: f64) -> f64 {
    collisions_per_walk_capped(m, d, eta, MAX_COLLISIONS_PER_WALK as u64)
}

/// [`collisions_per_walk`] with walks cut at `cap` collisions.
fn collisions_per_walk_capped(m: crate::slab::Medium, d: f64, eta: f64, cap: u64) -> f64 {
    let tau = m.sigma_t * d;
    let returns = eta.max(1.0).powi(2);
    let absorb = 6.0 / (1.0 - m.albedo).max(f64::MIN_POSITIVE);
    // A walk never exceeds the cap itself.
    let cap = (2.0 * (cap as f64).sqrt()).min(cap as f64);
    1.0 + (m.albedo * tau * returns).min(absorb).min(cap)
}

/// Predicts the collisions a run of `cfg` over `n_dirs` incident directions takes.
pub fn estimate_work(slab: &Slab, cfg: &SimConfig, n_dirs: usize) -> Work {
    let reps = slab.distinct_channels();
    let channels = (0..3).filter(|&c| reps[c] == c).count() as f64;
    let per_walk = (0..3)
        .filter(|&c| reps[c] == c)
        .map(|c| {
            let eta = slab.sheet.front.eta.max(slab.sheet.back.eta);
            collisions_per_walk_capped(slab.medium(c), slab.d, eta, cfg.max_collisions_per_walk.max(1))
        })
        .fold(0.0, f64::max);
    let nb = cfg.batches.max(1) as u64;
    let first = cfg.samples.div_ceil(nb).max(1) * nb;
    let walks = first as f64 * channels * n_dirs as f64;
    let max_walks = match cfg.rel_stderr {
        Some(_) => cfg.max_samples.max(first) as f64 * channels * n_dirs as f64,
        None => walks,
    };
    Work {
        collisions_per_walk: per_walk,
        walks,
        collisions: walks * per_walk,
        max_collisions: max_walks * per_walk,
    }
}

/// Measures this machine's collision rate (collisions per second over all
/// cores) on `slab` lit from `wi`, with walks of a separate generator for
/// about `seconds` (a pilot for time estimates; it changes no result).
pub fn measure_collision_rate(slab: &Slab, wi: DVec3, wos: &[DVec3], seconds: f64) -> f64 {
    let start = std::time::Instant::now();
    let mut rng = Pcg64Mcg::seed_from_u64(0x9170_7000);
    let tracer = Tracer::new(slab, 0, wos);
    let mut tally = Tally::new(wos.len());
    let mut collisions = 0u64;
    while start.elapsed().as_secs_f64() < seconds {
        tally.clear();
        tracer.walk(wi, &mut rng, &mut tally);
        collisions += tally.collisions.max(1);
    }
    collisions as f64 / start.elapsed().as_secs_f64().max(1e-9) * rayon::current_num_threads() as f64
}
