//! Exact unpolarised Fresnel reflectance of a smooth dielectric interface.
//!
//! Formulas: Born & Wolf, Principles of Optics, section 1.5; the same as
//! Mitsuba 3's `fresnel()` and pbrt-v4's `FrDielectric`.

/// Fresnel reflectance for light meeting an interface at `cos_i` (cosine with the
/// interface normal, which points into the medium of index 1 when positive) with
/// relative index `eta` = (index on the negative side) / (index on the positive
/// side). A negative `cos_i` means the light comes from the `eta` side. Total
/// internal reflection gives 1; `eta == 1` gives 0.
#[inline]
pub fn fresnel_dielectric(cos_i: f64, eta: f64) -> f64 {
    if eta == 1.0 {
        return 0.0;
    }
    let (eta_it, cos_i) = if cos_i >= 0.0 {
        (eta, cos_i)
    } else {
        (1.0 / eta, -cos_i)
    };
    let cos_i = cos_i.min(1.0);
    let sin2_t = (1.0 - cos_i * cos_i) / (eta_it * eta_it);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    if cos_i == 0.0 {
        return 1.0;
    }
    fresnel_from_cosines(cos_i, (1.0 - sin2_t).sqrt(), eta_it)
}

/// The unpolarised reflectance `(r_s^2 + r_p^2) / 2` from the cosines of the
/// incident and transmitted directions (`cos_i > 0`, `cos_t >= 0`) and the
/// index ratio `eta_it` (transmitted over incident side): the last step of
/// [`fresnel_dielectric`], for callers that have `cos_t` already.
#[inline]
pub fn fresnel_from_cosines(cos_i: f64, cos_t: f64, eta_it: f64) -> f64 {
    // r_s = n_s / d_s, r_p = n_p / d_p, summed over one division.
    let (n_s, d_s) = (cos_i - eta_it * cos_t, cos_i + eta_it * cos_t);
    let (n_p, d_p) = (cos_t - eta_it * cos_i, cos_t + eta_it * cos_i);
    let (d_s2, d_p2) = (d_s * d_s, d_p * d_p);
    0.5 * (n_s * n_s * d_p2 + n_p * n_p * d_s2) / (d_s2 * d_p2)
}

/// Cosine of the transmitted direction for light at `cos_i` (sign convention as
/// in [`fresnel_dielectric`]); `None` at total internal reflection. The result has
/// the opposite sign of `cos_i`.
#[inline]
pub fn cos_transmitted(cos_i: f64, eta: f64) -> Option<f64> {
    let eta_ti = if cos_i >= 0.0 { 1.0 / eta } else { eta };
    let sin2_t = eta_ti * eta_ti * (1.0 - cos_i * cos_i).max(0.0);
    if sin2_t >= 1.0 {
        None
    } else {
        Some(-(1.0 - sin2_t).sqrt().copysign(cos_i))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_incidence_closed_form() {
        for eta in [1.1, 1.5, 2.0, 5.0] {
            let r0: f64 = ((eta - 1.0) / (eta + 1.0)) * ((eta - 1.0) / (eta + 1.0));
            assert!((fresnel_dielectric(1.0, eta) - r0).abs() < 1e-12);
            assert!((fresnel_dielectric(-1.0, eta) - r0).abs() < 1e-12);
        }
    }

    #[test]
    fn brewster_p_polarisation_vanishes() {
        // At Brewster's angle the p amplitude is zero, so R = R_s / 2.
        let eta: f64 = 1.5;
        let tb = eta.atan();
        let ci = tb.cos();
        let ct = (1.0 - (tb.sin() / eta).powi(2)).sqrt();
        let rs = ((ci - eta * ct) / (ci + eta * ct)).powi(2);
        assert!((fresnel_dielectric(ci, eta) - 0.5 * rs).abs() < 1e-12);
    }

    #[test]
    fn total_internal_reflection_and_symmetry() {
        let eta = 1.5;
        let crit = (1.0f64 / eta).asin();
        assert_eq!(fresnel_dielectric(-(crit + 0.01).cos(), eta), 1.0);
        // Stokes relations: R is the same on both sides of a refraction pair.
        for ci in [0.1, 0.4, 0.8, 1.0] {
            let ct = cos_transmitted(ci, eta).unwrap();
            let a = fresnel_dielectric(ci, eta);
            let b = fresnel_dielectric(ct, eta);
            assert!((a - b).abs() < 1e-12, "{a} {b}");
        }
    }
}
