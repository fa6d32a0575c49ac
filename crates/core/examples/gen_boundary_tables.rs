//! Writes crates/core/data/boundary_tables.bin (see `paperbsdf_core::boundary::tables`).
//! Run: `cargo run --release -p paperbsdf-core --example gen_boundary_tables`.
use paperbsdf_core::boundary::tables::*;
use paperbsdf_core::boundary::SurfaceIntegrals;
use paperbsdf_core::{Distribution, RoughDielectric};
use std::sync::atomic::{AtomicUsize, Ordering};

fn main() {
    // PAPERBSDF_TABLE_ONLY=ggx|beckmann recomputes one distribution and keeps the
    // other's values from the existing table file.
    let only = std::env::var("PAPERBSDF_TABLE_ONLY")
        .ok()
        .and_then(|s| Distribution::parse(&s));
    let dists: Vec<Distribution> = [Distribution::Ggx, Distribution::Beckmann]
        .into_iter()
        .filter(|d| only.is_none_or(|o| o == *d))
        .collect();
    let jobs: Vec<(Distribution, usize, usize)> = dists
        .iter()
        .flat_map(|&d| (0..N_ETA).flat_map(move |i| (0..N_M).map(move |j| (d, i, j))))
        .collect();
    let mut init = vec![0f32; TABLE_LEN];
    if only.is_some() {
        let existing = std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/data/boundary_tables.bin")).unwrap();
        assert_eq!(existing.len(), 4 * TABLE_LEN, "existing table has another layout");
        for (v, c) in init.iter_mut().zip(existing.chunks_exact(4)) {
            *v = f32::from_le_bytes([c[0], c[1], c[2], c[3]]);
        }
    }
    let out = std::sync::Mutex::new(init);
    let next = AtomicUsize::new(0);
    let threads = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(2);
    std::thread::scope(|sc| {
        for _ in 0..threads {
            sc.spawn(|| loop {
                let k = next.fetch_add(1, Ordering::Relaxed);
                if k >= jobs.len() {
                    break;
                }
                let (d, i, j) = jobs[k];
                // eta = 1 nodes: the limit of a rough face as eta -> 1+.
                let eta = eta_node(i).max(1.0 + 1e-9);
                let b = RoughDielectric::new(d, eta, m_node(j)).unwrap();
                let s = SurfaceIntegrals::direct(&b, TABLE_QUADRATURE_POINTS);
                let v = encode_node(&s);
                let o = node_offset(d, i, j);
                out.lock().unwrap()[o..o + NODE_LEN].copy_from_slice(&v);
                if k.is_multiple_of(50) {
                    eprintln!("{k}/{}", jobs.len());
                }
            });
        }
    });
    let bytes: Vec<u8> = out.into_inner().unwrap().iter().flat_map(|x| x.to_le_bytes()).collect();
    // PAPERBSDF_TABLE_OUT overrides the output path (to generate beside the table in use).
    let path = std::env::var("PAPERBSDF_TABLE_OUT")
        .unwrap_or_else(|_| concat!(env!("CARGO_MANIFEST_DIR"), "/data/boundary_tables.bin").to_string());
    let tmp = format!("{path}.tmp");
    std::fs::write(&tmp, bytes).unwrap();
    std::fs::rename(&tmp, &path).unwrap();
    eprintln!("wrote {path}");
}
