use paperbsdf_core::*;
fn main() {
    let text = std::fs::read_to_string("../shared/reference/rough_dev_albedo.csv").unwrap();
    for l in text.lines().filter(|l| !l.starts_with('#')).skip(1) {
        let c: Vec<&str> = l.split(',').collect();
        let b = RoughDielectric::new(Distribution::parse(c[0]).unwrap(), c[1].parse().unwrap(), c[2].parse().unwrap()).unwrap();
        let side: f64 = c[3].parse().unwrap();
        let th = c[4].parse::<f64>().unwrap().to_radians();
        let w = DVec3::new(th.sin(), 0.0, side * th.cos());
        let (r, t) = boundary::directional_albedo_n(&b, w, 32);
        let (r2, t2) = boundary::directional_albedo_n(&b, w, 96);
        let rr: f64 = c[5].parse().unwrap(); let tt: f64 = c[7].parse().unwrap();
        let rs: f64 = c[6].parse().unwrap(); let ts: f64 = c[8].parse().unwrap();
        let bad = (r - rr).abs() > 4.0*rs + 0.002 || (t-tt).abs() > 4.0*ts+0.002;
        if bad || (r-r2).abs() > 1e-3 { println!("{l} | ours R {r:.5} ({r2:.5}) T {t:.5} ({t2:.5}) {}", if bad {"BAD"} else {""}); }
    }
}
