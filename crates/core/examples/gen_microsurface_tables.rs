//! Writes crates/core/data/microsurface_tables.bin (see `paperbsdf_core::microsurface_tables`):
//! at every other (distribution, eta, m) node of the boundary tables' grid, the
//! cosine-weighted hemispherical fractions of the energy carried by orders >= 2
//! of the multiple-scattering walk, for diffuse light from outside and from inside.
//!
//! Run (CPU-heavy; both cores through rayon):
//! `nice -n 10 cargo run --release -p paperbsdf-core --example gen_microsurface_tables`.
//! `PAPERBSDF_MS_WALKS` sets the walks per node and side (default
//! `microsurface_tables::TABLE_WALKS`); `PAPERBSDF_MS_TABLE_OUT` another output path.
use indicatif::{ProgressBar, ProgressStyle};
use paperbsdf_core::microsurface_tables::{
    hemispherical_estimate, node_eta_m, node_offset, NODE_LEN, N_ETA, N_M, TABLE_LEN, TABLE_WALKS,
};
use paperbsdf_core::Distribution;
use rand::{Rng, SeedableRng};
use rayon::prelude::*;

fn main() {
    let walks: usize = std::env::var("PAPERBSDF_MS_WALKS")
        .ok()
        .map(|s| s.parse().expect("PAPERBSDF_MS_WALKS must be a whole number"))
        .unwrap_or(TABLE_WALKS);
    let jobs: Vec<(Distribution, usize, usize)> = [Distribution::Ggx, Distribution::Beckmann]
        .into_iter()
        .flat_map(|d| (0..N_ETA).flat_map(move |i| (0..N_M).map(move |j| (d, i, j))))
        .collect();
    let bar = ProgressBar::new(jobs.len() as u64);
    bar.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} nodes, eta {msg}")
            .expect("valid template"),
    );
    let t0 = std::time::Instant::now();
    let nodes: Vec<(usize, [f32; NODE_LEN])> = jobs
        .par_iter()
        .map(|&(d, i, j)| {
            let mut rng = rand_pcg::Pcg64::seed_from_u64(node_offset(d, i, j) as u64 + 0x5eed);
            let (eta, m) = node_eta_m(i, j);
            let e = hemispherical_estimate(d, eta, m, walks, &mut || rng.gen::<f64>());
            bar.inc(1);
            bar.set_message(format!("{eta:.2}"));
            let mut v = [0f32; NODE_LEN];
            for k in 0..4 {
                v[k] = e.value[k] as f32;
                v[4 + k] = e.std_err[k] as f32;
            }
            (node_offset(d, i, j), v)
        })
        .collect();
    bar.finish();
    let mut out = vec![0f32; TABLE_LEN];
    for (o, v) in nodes {
        out[o..o + NODE_LEN].copy_from_slice(&v);
    }
    let bytes: Vec<u8> = out.iter().flat_map(|x| x.to_le_bytes()).collect();
    let path = std::env::var("PAPERBSDF_MS_TABLE_OUT")
        .unwrap_or_else(|_| concat!(env!("CARGO_MANIFEST_DIR"), "/data/microsurface_tables.bin").to_string());
    let tmp = format!("{path}.tmp");
    std::fs::write(&tmp, bytes).expect("write the temporary table");
    std::fs::rename(&tmp, &path).expect("rename the table into place");
    eprintln!(
        "wrote {path}: {} nodes, {walks} walks per node and side, {:.1} s",
        jobs.len(),
        t0.elapsed().as_secs_f64()
    );
}
