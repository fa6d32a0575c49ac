//! Directions where the lobes kept analytic through two rough crossings
//! are and around them (tests/two_crossings.rs and
//! examples/two_crossings.rs share them).

use paperbsdf_core::DVec3;

/// Unit direction at polar angle `t` and azimuth `p` (degrees).
pub fn dir(t: f64, p: f64) -> DVec3 {
    let (t, p) = (t.to_radians(), p.to_radians());
    DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

/// Normal, oblique and grazing incidence, the mirror (straight-through)
/// direction and off it in and out of the plane, near and on the far
/// flanks (`(theta_i, theta_o, phi_o)`, `wi` at azimuth 180 degrees so that
/// the lobe's centre is at `phi_o = 0`).
pub const POINTS: [(f64, f64, f64); 11] = [
    (0.0, 0.0, 0.0),
    (0.0, 3.0, 40.0),
    (0.0, 20.0, 0.0),
    (0.0, 40.0, 0.0),
    (40.0, 40.0, 0.0),
    (40.0, 44.0, 3.0),
    (40.0, 37.0, 8.0),
    (40.0, 60.0, 0.0),
    (70.0, 70.0, 0.0),
    (70.0, 66.0, 2.0),
    (70.0, 73.0, 6.0),
];
