//! Small direction helpers in the local frame (`+z` = macro normal of the front face).

use glam::DVec3;

/// `cos theta` of a unit direction.
#[inline]
pub fn cos_theta(w: DVec3) -> f64 {
    w.z
}

/// `tan^2 theta` of a unit direction (infinite at grazing).
#[inline]
pub fn tan2_theta(w: DVec3) -> f64 {
    let c2 = w.z * w.z;
    (1.0 - c2).max(0.0) / c2
}

/// Mirror reflection of `w` about the unit normal `n` (both pointing away from the surface).
#[inline]
pub fn reflect(w: DVec3, n: DVec3) -> DVec3 {
    2.0 * w.dot(n) * n - w
}

/// Refraction of `w` (pointing away from the surface) through a surface with unit
/// normal `n`, where `eta_ti` is the index of `w`'s side divided by the index of
/// the other side (Snell: `sin t = eta_ti sin i`). Returns `None` at total
/// internal reflection. `n` may face either side.
#[inline]
pub fn refract(w: DVec3, n: DVec3, eta_ti: f64) -> Option<DVec3> {
    let cos_i = w.dot(n);
    let sin2_t = eta_ti * eta_ti * (1.0 - cos_i * cos_i).max(0.0);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    // The refracted direction lies on the far side of n relative to w.
    let t = -eta_ti * w + (eta_ti * cos_i - cos_t.copysign(cos_i)) * n;
    Some(t.normalize())
}

/// The unit direction with polar angle `theta` (radians, from `+z`) and azimuth `phi`.
#[inline]
pub fn spherical_direction(theta: f64, phi: f64) -> DVec3 {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    DVec3::new(st * cp, st * sp, ct)
}

/// Directions of an in-plane measurement (docs/design.md section 2): the light at
/// `theta_i_deg` on the `+x` side above the front face; the viewer at signed
/// `theta_o_deg` (positive on the light's side), above the sheet for reflection,
/// below it (measured from `-z`) for transmission. Returns `(wi, wo)`.
pub fn in_plane_directions(theta_i_deg: f64, theta_o_deg: f64, transmission: bool) -> (DVec3, DVec3) {
    let ti = theta_i_deg.to_radians();
    let to = theta_o_deg.to_radians();
    let wi = DVec3::new(ti.sin(), 0.0, ti.cos());
    let z = if transmission { -to.cos() } else { to.cos() };
    let wo = DVec3::new(to.sin(), 0.0, z);
    (wi, wo)
}

/// An orthonormal basis `(t, b)` completing the unit vector `n` (Duff et al. 2017).
#[inline]
pub fn coordinate_system(n: DVec3) -> (DVec3, DVec3) {
    let sign = 1.0f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        DVec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

/// `y.round()` (halves away from zero), bit for bit, without the library
/// call that x86-64's baseline instruction set needs for it: below `2^52`
/// the truncation `t` is exact through a conversion to `i64`, and so is
/// `y - t`; from `2^52` on (and for NaN and infinities) `y` is its own rounding.
#[inline(always)]
fn round_half_away(y: f64) -> f64 {
    if y.is_nan() || y.abs() >= 4_503_599_627_370_496.0 {
        return y;
    }
    let t = y as i64 as f64;
    let d = y - t;
    if d >= 0.5 {
        t + 1.0
    } else if d <= -0.5 {
        t - 1.0
    } else {
        // The sign of a zero as `round` gives it (`-0.3` rounds to `-0`).
        t.copysign(y)
    }
}

/// `(sin 2 pi u, cos 2 pi u)` for `u` in `[0, 1]`, faster than `f64::sin_cos`
/// for the azimuths of samplers: the turn is reduced to a quarter-turn index
/// and an angle `x` in `[-pi/4, pi/4]`, where the Taylor series of `sin` to
/// `x^17` and of `cos` to `x^18` are exact to double precision (next terms
/// below `1e-19`). Within a few ulps of `f64::sin_cos` (tested).
#[inline]
pub fn sin_cos_2pi(u: f64) -> (f64, f64) {
    let q = round_half_away(4.0 * u);
    let x = std::f64::consts::TAU * (u - 0.25 * q);
    let x2 = x * x;
    // 1/n! for the odd and even terms.
    let s = x
        * (1.0
            + x2 * (-1.0 / 6.0
                + x2 * (1.0 / 120.0
                    + x2 * (-1.0 / 5040.0
                        + x2 * (1.0 / 362_880.0
                            + x2 * (-1.0 / 39_916_800.0
                                + x2 * (1.0 / 6_227_020_800.0
                                    + x2 * (-1.0 / 1_307_674_368_000.0 + x2 * (1.0 / 355_687_428_096_000.0)))))))));
    let c = 1.0
        + x2 * (-0.5
            + x2 * (1.0 / 24.0
                + x2 * (-1.0 / 720.0
                    + x2 * (1.0 / 40_320.0
                        + x2 * (-1.0 / 3_628_800.0
                            + x2 * (1.0 / 479_001_600.0
                                + x2 * (-1.0 / 87_178_291_200.0
                                    + x2 * (1.0 / 20_922_789_888_000.0 + x2 * (-1.0 / 6_402_373_705_728_000.0)))))))));
    match (q as i64).rem_euclid(4) {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// Cosine-weighted direction on the upper hemisphere (Malley's method).
#[inline]
pub fn sample_cosine_hemisphere(u: [f64; 2]) -> DVec3 {
    let r = u[0].sqrt();
    let (sin, cos) = sin_cos_2pi(u[1]);
    let z = (1.0 - u[0]).max(0.0).sqrt();
    DVec3::new(r * cos, r * sin, z)
}

/// Uniform direction on the unit sphere.
#[inline]
pub fn sample_uniform_sphere(u: [f64; 2]) -> DVec3 {
    let z = 1.0 - 2.0 * u[0];
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (sin, cos) = sin_cos_2pi(u[1]);
    DVec3::new(r * cos, r * sin, z)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rounding of [`sin_cos_2pi`] against `f64::round`, bit for bit:
    /// halves, neighbours of halves, signed zeros, large values, NaN.
    #[test]
    fn round_half_away_matches_std() {
        let mut xs = vec![0.0, -0.0, 0.5, -0.5, 1.5, -1.5, 2.5, 3.5, 4.0, 0.3, -0.3, 0.7, -0.7];
        for h in [0.5f64, 1.5, 2.5, 3.5, 1e15 + 0.5, 4_503_599_627_370_495.5] {
            for x in [h, -h] {
                xs.extend([x, f64::from_bits(x.to_bits() + 1), f64::from_bits(x.to_bits() - 1)]);
            }
        }
        xs.extend([
            4_503_599_627_370_496.0,
            1e300,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MIN_POSITIVE,
            5e-324,
        ]);
        for k in 0..=40_000 {
            xs.push(k as f64 / 10_000.0);
            xs.push(4.0 * (k as f64 + 0.37) / 40_000.0);
        }
        for x in xs {
            assert_eq!(round_half_away(x).to_bits(), x.round().to_bits(), "{x:e}");
        }
        assert!(round_half_away(f64::NAN).is_nan());
    }

    /// The reduced Taylor series against the standard library over the whole
    /// turn, quarter-turn boundaries included.
    #[test]
    fn sin_cos_2pi_matches_std() {
        let mut worst = 0.0f64;
        let n = 100_000;
        for k in 0..=n {
            for u in [k as f64 / n as f64, (k as f64 + 0.37) / n as f64] {
                if u > 1.0 {
                    continue;
                }
                let (s, c) = sin_cos_2pi(u);
                let (s0, c0) = (std::f64::consts::TAU * u).sin_cos();
                worst = worst.max((s - s0).abs()).max((c - c0).abs());
            }
        }
        // A few ulps of 1 (2.2e-16), plus the rounding of TAU * u itself
        // (up to 1.4e-15 near u = 1, where std::sin_cos sees an argument
        // rounded to an ulp of 2 pi).
        eprintln!("worst deviation from std: {worst:e}");
        assert!(worst < 2e-15, "worst {worst:e}");
        assert_eq!(sin_cos_2pi(0.0), (0.0, 1.0));
        let (s, c) = sin_cos_2pi(0.25);
        assert!((s - 1.0).abs() < 1e-16 && c.abs() < 1e-16);
    }
}
