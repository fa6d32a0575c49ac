//! Use paperbsdf in your renderer: the Paper BSDF at one shading point.
//!
//! A renderer has world-space directions and a shading normal; the BSDF works
//! in a local frame with the sheet's front normal `+z`, `wi` toward the light
//! and `wo` toward the viewer, values without the cosine (docs/design.md section 2).
//! This program builds that frame, evaluates the BSDF for a light (next-event
//! estimation), samples it to continue a path, and checks the sampled
//! estimate of the sheet's reflectance and transmittance against quadrature.
//!
//! `cargo run --release -p paperbsdf-core --example renderer [PRESET]`

use paperbsdf_core::{presets, Bsdf, DVec3, PaperBsdf, Rgb};

/// An orthonormal frame around a normal (Duff et al. 2017, "Building an
/// orthonormal basis, revisited"): world <-> local.
struct Frame {
    s: DVec3,
    t: DVec3,
    n: DVec3,
}

impl Frame {
    fn from_normal(n: DVec3) -> Frame {
        let sign = 1f64.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let s = DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = DVec3::new(b, sign + n.y * n.y * a, -n.y);
        Frame { s, t, n }
    }
    fn to_local(&self, v: DVec3) -> DVec3 {
        DVec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }
    fn to_world(&self, v: DVec3) -> DVec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}

/// A small deterministic generator (PCG-style LCG) so the example needs no crates.
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn main() {
    let name = std::env::args().nth(1).unwrap_or_else(|| "matte".into());
    let Some(params) = presets::preset(&name) else {
        eprintln!("unknown preset `{name}`; presets: {}", presets::PRESET_NAMES.join(", "));
        std::process::exit(2);
    };
    // Build once per material (tens of microseconds), share across threads (PaperBsdf is Send + Sync).
    let bsdf = PaperBsdf::new(&params).expect("presets are valid");

    // A sheet tilted in the world, a camera ray arriving at it and a point light.
    let normal = DVec3::new(0.3, -0.2, 1.0).normalize();
    let frame = Frame::from_normal(normal);
    let hit = DVec3::new(0.0, 0.0, 0.0);
    let camera = DVec3::new(0.5, -2.0, 1.5);
    let light_pos = DVec3::new(-1.0, 0.5, 2.0);
    let light_power = Rgb::splat(10.0); // radiant intensity, W/sr

    let wo = frame.to_local((camera - hit).normalize());
    let to_light = light_pos - hit;
    let wi = frame.to_local(to_light.normalize());

    // Next-event estimation: L = f(wi, wo) |cos wi| I / r^2 (wi.z > 0: the light is on the front side).
    let f = bsdf.eval(wi, wo);
    let radiance = f * (wi.z.abs() * 1.0 / to_light.length_squared()) * light_power;
    println!("preset {name}: f(wi, wo) = {:.4?} 1/sr", f.0);
    println!("reflected radiance from the point light: {:.4?}", radiance.0);

    // Continue the path: sample wi for wo; the weight f |cos| / pdf multiplies the throughput.
    // A light behind the sheet would be reached by a sample with wi.z < 0 (transmission).
    let mut rng = Lcg(2014);
    let n = 200_000;
    let (mut refl, mut trans) = (Rgb::ZERO, Rgb::ZERO);
    for _ in 0..n {
        if let Some(s) = bsdf.sample(wo, rng.next(), [rng.next(), rng.next()]) {
            let _world_dir = frame.to_world(s.wi); // the next ray's direction
            if s.wi.z * wo.z > 0.0 {
                refl += s.weight();
            } else {
                trans += s.weight();
            }
        }
    }
    let (refl, trans) = (refl * (1.0 / n as f64), trans * (1.0 / n as f64));
    println!(
        "albedo seen from the camera, by sampling ({n} samples): R = {:.4?}, T = {:.4?}",
        refl.0, trans.0
    );

    // The same two numbers by stratified quadrature of the library's own sampler.
    let (r, t) = paperbsdf_core::bsdf::sampled_albedo(&bsdf, wo, 256);
    println!(
        "                                 by quadrature:         R = {:.4?}, T = {:.4?}",
        r.0, t.0
    );
    for c in 0..3 {
        assert!((refl.0[c] - r.0[c]).abs() < 0.01 && (trans.0[c] - t.0[c]).abs() < 0.01);
    }
}
