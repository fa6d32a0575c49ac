//! # paperbsdf-render
//!
//! A small physically based renderer for paper scenes: a unidirectional path
//! tracer with next-event estimation and multiple importance sampling (power
//! heuristic), Russian roulette, a binned-SAH BVH, and tiles rendered in
//! parallel with rayon. Materials are Lambertian, rough dielectric (Walter et
//! al. 2007) and the Paper BSDF (Papas, de Mesa, Jensen, EGSR 2014) from
//! `paperbsdf-core`, with thickness and ink maps and cut-out masks.
//!
//! Scenes are TOML files (see `docs/scenes.md`) or built-in scenes by name
//! ([`builtin`]). Rendering is deterministic for a seed: the generator of
//! sample `k` of pixel `i` is seeded from `(seed, i, k)`, so the image does not
//! depend on the number of threads or on how samples are split into passes.
//! The conventions match Mitsuba 3 so that its renderings are a reference
//! (see the tests against `reference/scene_ref.exr`).

#![warn(missing_docs)]

pub mod builtin;
pub mod error;
pub mod film;
pub mod integrator;
pub mod material;
pub mod math;
pub mod mesh;
pub mod paper_model;
pub mod scene;
pub mod shapes;
pub mod spec;
pub mod texture;

pub use error::{ImageError, RenderError, SceneError};
pub use film::Film;
pub use scene::{Scene, Settings};
pub use spec::{load_scene, load_scene_str};

use indicatif::{ProgressBar, ProgressStyle};
use math::{mix64, Pcg32};
use paperbsdf_core::Rgb;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Options of one render run.
#[derive(Clone, Debug)]
pub struct RenderOptions {
    /// Samples per pixel to take.
    pub spp: u32,
    /// Samples per pixel per pass (progress and Ctrl-C granularity).
    pub pass_spp: u32,
    /// Show a progress bar (on a terminal).
    pub progress: bool,
}

/// The outcome of a render.
#[derive(Clone, Debug)]
pub struct RenderOutput {
    /// The accumulated image.
    pub film: Film,
    /// Wall-clock time spent rendering.
    pub elapsed: Duration,
    /// Camera samples taken in total.
    pub samples: u64,
    /// Whether the render was stopped before all samples were taken.
    pub cancelled: bool,
}

impl RenderOutput {
    /// Camera samples per second.
    pub fn samples_per_second(&self) -> f64 {
        self.samples as f64 / self.elapsed.as_secs_f64().max(1e-9)
    }
}

const TILE: usize = 16;

/// A tile's origin and, per pixel, the sums of samples and of their squares (RGB).
type TileSums = ((usize, usize), Vec<[[f64; 3]; 2]>);

/// The generator of sample `k` of pixel `i` for a seed.
#[inline]
pub fn sample_rng(seed: u64, pixel: usize, k: u32) -> Pcg32 {
    let ph = mix64(seed ^ mix64(pixel as u64 ^ 0x5EED_0000_0000_0000));
    Pcg32::new(mix64(ph ^ k as u64), ph >> 1)
}

/// Radiance estimate of sample `k` of pixel `(x, y)` (box filter: uniform over the pixel).
#[inline]
pub fn render_sample(scene: &Scene, seed: u64, x: usize, y: usize, k: u32) -> Rgb {
    let s = &scene.settings;
    let mut rng = sample_rng(seed, y * s.width + x, k);
    let [jx, jy] = rng.next_2d();
    let ray = scene.camera.ray(x as f64 + jx, y as f64 + jy, s.width, s.height);
    let v = scene.li(ray, &mut rng);
    // A non-finite sample (a numerical failure) is dropped rather than poisoning the pixel.
    if v.is_finite() {
        v
    } else {
        Rgb::ZERO
    }
}

/// Renders `scene` with `opts.spp` samples per pixel, in passes, tiles in
/// parallel on rayon's current pool. When `cancel` becomes true, the tiles not
/// yet started are skipped and the film holds what was completed (each pixel
/// averages over its own sample count).
pub fn render(scene: &Scene, opts: &RenderOptions, cancel: &AtomicBool) -> RenderOutput {
    let s = &scene.settings;
    let (w, h) = (s.width, s.height);
    let mut film = Film::new(w, h);
    let tiles: Vec<(usize, usize)> = (0..h.div_ceil(TILE))
        .flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| (tx * TILE, ty * TILE)))
        .collect();
    let pass_spp = opts.pass_spp.max(1);
    let passes = opts.spp.div_ceil(pass_spp);
    let pb = if opts.progress {
        ProgressBar::new(passes as u64 * tiles.len() as u64)
    } else {
        ProgressBar::hidden()
    };
    pb.set_style(
        ProgressStyle::with_template("{spinner} [{elapsed_precise}] {wide_bar} {percent}% eta {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let seed = scene.seed_hash();
    let start = Instant::now();
    let mut samples = 0u64;
    let mut cancelled = false;
    for pass in 0..passes {
        let k0 = pass * pass_spp;
        let k1 = ((pass + 1) * pass_spp).min(opts.spp);
        let results: Vec<Option<TileSums>> = tiles
            .par_iter()
            .map(|&(x0, y0)| {
                if cancel.load(Ordering::Relaxed) {
                    return None;
                }
                let (x1, y1) = ((x0 + TILE).min(w), (y0 + TILE).min(h));
                let mut acc = Vec::with_capacity((x1 - x0) * (y1 - y0));
                for y in y0..y1 {
                    for x in x0..x1 {
                        let mut a = [[0.0; 3]; 2];
                        for k in k0..k1 {
                            let v = render_sample(scene, seed, x, y, k);
                            for (c, vc) in v.0.iter().enumerate() {
                                a[0][c] += vc;
                                a[1][c] += vc * vc;
                            }
                        }
                        acc.push(a);
                    }
                }
                pb.inc(1);
                Some(((x0, y0), acc))
            })
            .collect();
        for r in results {
            let Some(((x0, y0), acc)) = r else {
                cancelled = true;
                continue;
            };
            let x1 = (x0 + TILE).min(w);
            let tw = x1 - x0;
            for (j, a) in acc.iter().enumerate() {
                let i = (y0 + j / tw) * w + x0 + j % tw;
                for (c, (s, q)) in a[0].iter().zip(&a[1]).enumerate() {
                    film.sum[i][c] += s;
                    film.sum_sq[i][c] += q;
                }
                film.count[i] += k1 - k0;
                samples += (k1 - k0) as u64;
            }
        }
        if cancelled || cancel.load(Ordering::Relaxed) {
            cancelled = cancelled || pass + 1 < passes;
            break;
        }
    }
    pb.finish_and_clear();
    RenderOutput {
        film,
        elapsed: start.elapsed(),
        samples,
        cancelled,
    }
}

/// Installs a Ctrl-C handler that sets the returned flag (the render then stops
/// at the next tile and the partial image is still written). A second Ctrl-C
/// removes every temporary output file being written and exits at once with
/// code 130. Fails if a handler is installed already.
pub fn install_ctrlc_flag() -> Result<&'static AtomicBool, RenderError> {
    static FLAG: AtomicBool = AtomicBool::new(false);
    ctrlc::set_handler(|| {
        if FLAG.swap(true, Ordering::SeqCst) {
            paperbsdf_io::atomic::remove_temp_files();
            std::process::exit(130);
        }
        eprintln!("\ninterrupted: finishing the current tiles and writing the partial image (Ctrl-C again to quit)");
    })
    .map_err(RenderError::CtrlC)?;
    Ok(&FLAG)
}

/// Bytes a render of `width x height` pixels holds at its peak: the film's
/// sums, squares and counts (52 bytes a pixel), one pass of tile results (48),
/// the mean image (24) and the encoders' buffers (EXR 12, PNG 3), with 10%
/// for allocator slack: about 153 bytes a pixel (2.6 GB at 4096 x 4096).
pub fn estimate_memory_bytes(width: usize, height: usize) -> f64 {
    (52.0 + 48.0 + 24.0 + 12.0 + 3.0) * 1.1 * width as f64 * height as f64
}

/// Memory this process may use, bytes: the smallest of the machine's
/// available memory (`MemAvailable` in `/proc/meminfo`) and the cgroup's
/// limit (`memory.max`, v2); `None` where neither can be read.
pub fn available_memory_bytes() -> Option<f64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok().and_then(|t| {
        t.lines()
            .find_map(|l| l.strip_prefix("MemAvailable:"))
            .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok())
            .map(|kb| kb * 1024.0)
    });
    let cgroup = std::fs::read_to_string("/sys/fs/cgroup/memory.max")
        .ok()
        .and_then(|t| t.trim().parse::<f64>().ok());
    match (meminfo, cgroup) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

/// Refuses an image whose estimated memory ([`estimate_memory_bytes`]) is more
/// than `available` bytes, with both numbers in the message.
pub fn check_memory(width: usize, height: usize, available: Option<f64>) -> Result<(), RenderError> {
    let need = estimate_memory_bytes(width, height);
    match available {
        Some(available) if need > available => Err(RenderError::Memory {
            width,
            height,
            need,
            available,
        }),
        _ => Ok(()),
    }
}

/// [`render`] on a pool of `threads` workers (`None`: one per core); also returns the number of workers.
pub fn render_with_threads(
    scene: &Scene,
    opts: &RenderOptions,
    cancel: &AtomicBool,
    threads: Option<usize>,
) -> Result<(RenderOutput, usize), RenderError> {
    if threads == Some(0) {
        return Err(RenderError::NoThreads);
    }
    check_memory(scene.settings.width, scene.settings.height, available_memory_bytes())?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map_err(RenderError::Threads)?;
    let n = pool.current_num_threads();
    Ok((pool.install(|| render(scene, opts, cancel)), n))
}
