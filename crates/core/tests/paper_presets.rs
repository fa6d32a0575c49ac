//! The presets build, and their albedos are those of real papers: office
//! paper reflects 70 to 90 % and transmits 10 to 30 % of normally incident
//! light (ISO brightness ~90 %, opacity ~90 %: a sheet over black reflects about
//! 0.9 of what a pad of sheets does); photo papers, thicker and pigmented,
//! transmit less. The albedo is the quadrature of `eval * cos` over each
//! hemisphere (no delta lobes: every preset face is rough).

use paperbsdf_core::paper::PaperBsdf;
use paperbsdf_core::presets::{preset, PRESET_NAMES};
use paperbsdf_core::{Bsdf, DVec3, Rgb};
use std::f64::consts::PI;

fn albedo(b: &PaperBsdf, wi: DVec3, n: usize) -> (Rgb, Rgb) {
    let mut out = [Rgb::ZERO; 2];
    for (h, side) in [1.0, -1.0].into_iter().enumerate() {
        for i in 0..n {
            let t = (i as f64 + 0.5) / n as f64;
            let mu = t * t;
            let st = (1.0 - mu * mu).sqrt();
            for j in 0..2 * n {
                let phi = (j as f64 + 0.5) / (2 * n) as f64 * 2.0 * PI;
                let wo = DVec3::new(st * phi.cos(), st * phi.sin(), side * mu);
                out[h] += b.eval(wi, wo) * (mu * 2.0 * t / n as f64 * PI / n as f64);
            }
        }
    }
    (out[0], out[1])
}

#[test]
fn presets_are_plausible_papers() {
    let mut t_matte = 0.0;
    for name in PRESET_NAMES {
        let p = preset(name).unwrap();
        p.validate().unwrap();
        let b = PaperBsdf::new(&p).unwrap();
        // Normal incidence: the glossy papers' specular peak is narrow, so
        // evaluate 10 degrees off the normal with a fine grid.
        let wi = DVec3::new(10f64.to_radians().sin(), 0.0, 10f64.to_radians().cos());
        let (r, t) = albedo(&b, wi, 400);
        eprintln!("{name}: R = {:?}, T = {:?}", r.0, t.0);
        for c in 0..3 {
            assert!((0.6..0.95).contains(&r.0[c]), "{name}: R = {}", r.0[c]);
            assert!((0.005..0.35).contains(&t.0[c]), "{name}: T = {}", t.0[c]);
        }
        if name == "matte" {
            t_matte = t.mean();
            assert!(t_matte > 0.1, "office paper transmits 10 to 30 %: {t_matte}");
        } else {
            assert!(t.mean() < t_matte, "{name} should be more opaque than office paper");
        }
    }
    assert!(preset("no-such-paper").is_none());
}
