use paperbsdf_core::presets::preset;
use paperbsdf_slab::SlabBsdf;
fn main() {
    let name = std::env::args().nth(1).unwrap_or("glossy".into());
    let p = preset(&name).unwrap();
    for _ in 0..3 {
        let t = std::time::Instant::now();
        let b = SlabBsdf::new(&p).unwrap();
        println!("{:.3} s {}", t.elapsed().as_secs_f64(), b.memory_bytes());
    }
}
