//! Fitting straight from a measured BSDF file (an RGL `.bsdf`,
//! [`paperbsdf_io::MeasuredBsdf`]): the measurement is sampled on a documented
//! set of direction pairs, in and out of the plane of incidence, and those
//! samples are fitted like any measurement file; plus the filters that real
//! goniometer data need and the measured directional albedo.
//!
//! The default set of pairs ([`Sampling::default`]): the light at
//! `theta_i` = 0, 15, 30, 45, 60, 75 degrees in the x-z plane (`+x` side, as
//! the in-plane convention of docs/design.md section 2); for each, the in-plane
//! viewers `theta_o` = -85 to 85 in steps of 5 (35 points), and out of the
//! plane the viewers at polar angles 5 to 85 in steps of 10 and azimuths 30 to
//! 150 in steps of 30 degrees from the light's plane (45 points): 480 pairs.
//! Azimuths beyond 180 are their mirror images for an isotropic material; for an
//! anisotropic file the light stays at azimuth 0 (one slice of its data).
//! Values are [`paperbsdf_core::Bsdf::eval`] of the file (negative ringing of the
//! stored representation set to zero).

use crate::error::FitError;
use crate::measurement::{Kind, Point};
use paperbsdf_core::geometry::in_plane_directions;
use paperbsdf_core::{Bsdf, DVec3, Rgb};
use paperbsdf_io::MeasuredBsdf;

/// The direction pairs at which a measured file is sampled.
#[derive(Clone, Debug)]
pub struct Sampling {
    /// Incident polar angles, degrees.
    pub theta_i: Vec<f64>,
    /// In-plane signed viewing angles, degrees.
    pub in_plane_theta_o: Vec<f64>,
    /// Out-of-plane viewing polar angles, degrees.
    pub out_theta_o: Vec<f64>,
    /// Out-of-plane viewing azimuths from the light's plane, degrees (0 is the light's side).
    pub out_phi_o: Vec<f64>,
}

fn range(from: f64, to: f64, step: f64) -> Vec<f64> {
    let n = ((to - from) / step + 1e-9).floor() as usize;
    (0..=n).map(|k| from + k as f64 * step).collect()
}

impl Default for Sampling {
    fn default() -> Self {
        Sampling {
            theta_i: range(0.0, 75.0, 15.0),
            in_plane_theta_o: range(-85.0, 85.0, 5.0),
            out_theta_o: range(5.0, 85.0, 10.0),
            out_phi_o: range(30.0, 150.0, 30.0),
        }
    }
}

/// Filters for what goniometers cannot measure: near retro-reflection (the
/// detector blocks the light) and at the most grazing angles.
#[derive(Clone, Copy, Debug, Default)]
pub struct PointFilter {
    /// Drop reflection points whose viewer is within this angle (degrees) of the light.
    pub exclude_retro_deg: Option<f64>,
    /// Drop points whose light or viewer is further than this (degrees) from the normal.
    pub max_theta_deg: Option<f64>,
}

impl PointFilter {
    /// Checks the ranges: `--exclude-retro` in [0, 180), `--max-theta` in (0, 90].
    pub fn validate(&self) -> Result<(), FitError> {
        if let Some(r) = self.exclude_retro_deg {
            if !(0.0..180.0).contains(&r) {
                return Err(FitError::ExcludeRetro(r));
            }
        }
        if let Some(m) = self.max_theta_deg {
            if !(m > 0.0 && m <= 90.0) {
                return Err(FitError::MaxTheta(m));
            }
        }
        Ok(())
    }
    /// Whether a pair of directions is kept.
    pub fn keeps(&self, wi: DVec3, wo: DVec3) -> bool {
        if let Some(r) = self.exclude_retro_deg {
            let reflection = wi.z * wo.z > 0.0;
            if reflection && wi.normalize().dot(wo.normalize()).clamp(-1.0, 1.0).acos().to_degrees() < r {
                return false;
            }
        }
        if let Some(m) = self.max_theta_deg {
            let polar = |w: DVec3| w.z.abs().min(1.0).acos().to_degrees();
            if polar(wi) > m + 1e-9 || polar(wo) > m + 1e-9 {
                return false;
            }
        }
        true
    }
    /// The points it keeps.
    pub fn apply(&self, points: Vec<Point>) -> Vec<Point> {
        points.into_iter().filter(|p| self.keeps(p.wi, p.wo)).collect()
    }
}

/// Whether a point lies in the plane of incidence.
pub fn in_plane(p: &Point) -> bool {
    p.theta_o.is_some() || (p.wi.y.abs() < 1e-12 && p.wo.y.abs() < 1e-12)
}

/// Samples `b` on the pairs of `s` (reflection only, `line` 0).
pub fn sample_measured(b: &MeasuredBsdf, s: &Sampling) -> Vec<Point> {
    let mut pts = Vec::new();
    for &ti in &s.theta_i {
        for &to in &s.in_plane_theta_o {
            let (wi, wo) = in_plane_directions(ti, to, false);
            pts.push(point(b, ti, Some(to), wi, wo));
        }
        let wi = in_plane_directions(ti, 0.0, false).0;
        for &to in &s.out_theta_o {
            for &po in &s.out_phi_o {
                let (t, p) = (to.to_radians(), po.to_radians());
                let wo = DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
                pts.push(point(b, ti, None, wi, wo));
            }
        }
    }
    pts
}

/// In-plane slices of `b`: reflection points at every incident angle of
/// `theta_i` and signed viewing angle of `theta_o` (degrees, docs/design.md
/// section 2) that `filter` keeps, in that order; what `paperbsdf convert`
/// writes and `paperbsdf plot` draws for a `.bsdf` file.
pub fn sample_in_plane(b: &MeasuredBsdf, theta_i: &[f64], theta_o: &[f64], filter: &PointFilter) -> Vec<Point> {
    let mut pts = Vec::new();
    for &ti in theta_i {
        for &to in theta_o {
            let (wi, wo) = in_plane_directions(ti, to, false);
            if filter.keeps(wi, wo) {
                pts.push(point(b, ti, Some(to), wi, wo));
            }
        }
    }
    pts
}

fn point(b: &MeasuredBsdf, ti: f64, to: Option<f64>, wi: DVec3, wo: DVec3) -> Point {
    Point {
        kind: Kind::R,
        theta_i: ti,
        theta_o: to,
        wi,
        wo,
        f: b.eval(wi, wo),
        stderr: None,
        line: 0,
    }
}

/// The measured directional albedo `int f cos dwo` over the upper hemisphere for
/// the light at `theta_i_deg`, per channel, by the midpoint rule on a 96 x 192
/// grid uniform in `cos^2 theta_o` and azimuth (the cosine-weighted measure, so
/// each cell has equal weight). Sharp peaks narrower than a cell are
/// under-resolved; this is a check, not a reference value.
pub fn directional_albedo(b: &dyn Bsdf, theta_i_deg: f64) -> Rgb {
    let wi = in_plane_directions(theta_i_deg, 0.0, false).0;
    let (nu, np) = (96usize, 192usize);
    let mut sum = Rgb::ZERO;
    for i in 0..nu {
        let mu2 = (i as f64 + 0.5) / nu as f64;
        let (mu, st) = (mu2.sqrt(), (1.0 - mu2).sqrt());
        for j in 0..np {
            let phi = std::f64::consts::TAU * (j as f64 + 0.5) / np as f64;
            let wo = DVec3::new(st * phi.cos(), st * phi.sin(), mu);
            sum += b.eval(wi, wo);
        }
    }
    // int f cos dw = pi * mean of f over the cosine-weighted measure
    sum * (std::f64::consts::PI / (nu * np) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use paperbsdf_core::{BsdfFlags, BsdfSample};

    struct Lambert(f64);
    impl Bsdf for Lambert {
        fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
            if wi.z > 0.0 && wo.z > 0.0 {
                Rgb::splat(self.0 / std::f64::consts::PI)
            } else {
                Rgb::ZERO
            }
        }
        fn sample(&self, _: DVec3, _: f64, _: [f64; 2]) -> Option<BsdfSample> {
            None
        }
        fn pdf(&self, _: DVec3, _: DVec3) -> f64 {
            0.0
        }
        fn flags(&self) -> BsdfFlags {
            BsdfFlags::REFLECTION
        }
    }

    /// A Lambertian surface of albedo 0.7 has directional albedo 0.7 at every angle (closed form).
    #[test]
    fn albedo_of_lambert_is_its_weight() {
        for t in [0.0, 45.0, 80.0] {
            let a = directional_albedo(&Lambert(0.7), t);
            assert!((a.0[0] - 0.7).abs() < 1e-12, "{t}: {a:?}");
        }
    }

    #[test]
    fn filters_drop_retro_and_grazing_pairs() {
        let f = PointFilter {
            exclude_retro_deg: Some(5.0),
            max_theta_deg: Some(70.0),
        };
        let (wi, wo) = in_plane_directions(30.0, 27.0, false);
        assert!(!f.keeps(wi, wo), "3 degrees from retro-reflection");
        let (wi, wo) = in_plane_directions(30.0, 20.0, false);
        assert!(f.keeps(wi, wo));
        let (wi, wo) = in_plane_directions(30.0, -75.0, false);
        assert!(!f.keeps(wi, wo), "viewer at 75 degrees");
        let (wi, wo) = in_plane_directions(75.0, 0.0, false);
        assert!(!f.keeps(wi, wo), "light at 75 degrees");
        // transmission is never retro-reflection
        let (wi, wo) = in_plane_directions(30.0, 30.0, true);
        assert!(f.keeps(wi, wo));
        assert!(PointFilter {
            exclude_retro_deg: Some(-1.0),
            max_theta_deg: None
        }
        .validate()
        .is_err());
        assert!(PointFilter {
            exclude_retro_deg: None,
            max_theta_deg: Some(0.0)
        }
        .validate()
        .is_err());
    }

    #[test]
    fn default_sampling_has_480_pairs() {
        let s = Sampling::default();
        assert_eq!(
            s.theta_i.len() * (s.in_plane_theta_o.len() + s.out_theta_o.len() * s.out_phi_o.len()),
            480
        );
    }
}
