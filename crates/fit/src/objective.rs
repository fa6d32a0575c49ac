//! The fit error of docs/design.md section 5: the root mean square of
//! `ln((f_model + e) / (f_meas + e))` over all points and channels.
//!
//! * `e` = [`LOG_OFFSET`] = 1e-3 (1/sr). Paper's in-plane BSDF values lie
//!   between about 0.01 (grazing transmission) and tens (a glossy peak); the
//!   offset only matters for values near or below 1e-3, where it turns the
//!   relative error into an absolute one so that a zero measurement does not
//!   give an infinite error.
//! * Weighting: when a point has a standard error `s`, its log-space standard
//!   error is `sigma = s / (f_meas + e)` (delta method) and its weight is
//!   `1 / max(sigma, SIGMA_FLOOR)^2` with [`SIGMA_FLOOR`] = 1e-3 (so that a
//!   point with `s = 0` has a large but finite weight). Without a standard
//!   error every point has weight 1. The reported error is
//!   `sqrt(sum w r^2 / sum w)`: still a log-space RMS (a constant 1% error
//!   scores 0.01 whatever the weights). The unweighted RMS is reported beside it.

use crate::measurement::Point;
use crate::model::ComponentModel;

/// The offset `e` added to model and measurement inside the logarithm (1/sr).
pub const LOG_OFFSET: f64 = 1e-3;
/// The smallest log-space standard error used for weighting.
pub const SIGMA_FLOOR: f64 = 1e-3;

/// The log residual of one channel.
#[inline]
pub fn log_residual(model: f64, meas: f64) -> f64 {
    ((model.max(0.0) + LOG_OFFSET) / (meas + LOG_OFFSET)).ln()
}

/// The weight of channel `c` of point `p` (see the module doc).
#[inline]
pub fn weight(p: &Point, c: usize) -> f64 {
    match p.stderr {
        Some(s) => {
            let sigma = (s.0[c] / (p.f.0[c] + LOG_OFFSET)).max(SIGMA_FLOOR);
            1.0 / (sigma * sigma)
        }
        None => 1.0,
    }
}

/// Weighted and unweighted RMS log error of `model` over `points`
/// (`channels` = 1 or 3). `None` when there are no points.
pub fn rms_log_error(model: &dyn ComponentModel, points: &[&Point], channels: usize) -> Option<(f64, f64)> {
    if points.is_empty() {
        return None;
    }
    let (mut sw, mut swr, mut sr, mut n) = (0.0, 0.0, 0.0, 0.0);
    for p in points {
        let f = model.eval(p.wi, p.wo);
        for c in 0..channels {
            let r = log_residual(f.0[c], p.f.0[c]);
            let w = weight(p, c);
            sw += w;
            swr += w * r * r;
            sr += r * r;
            n += 1.0;
        }
    }
    Some(((swr / sw).sqrt(), (sr / n).sqrt()))
}

/// Fills `out` with the residuals `sqrt(w / sum w) r` whose sum of squares is
/// the squared weighted RMS error. Returns false if a value is not finite.
pub fn residuals(
    model: &dyn ComponentModel,
    points: &[&Point],
    sqrt_w: &[f64],
    channels: usize,
    out: &mut [f64],
) -> bool {
    let mut k = 0;
    for p in points {
        let f = model.eval(p.wi, p.wo);
        for c in 0..channels {
            let r = sqrt_w[k] * log_residual(f.0[c], p.f.0[c]);
            if !r.is_finite() {
                return false;
            }
            out[k] = r;
            k += 1;
        }
    }
    true
}

/// The normalised residual weights `sqrt(w / sum w)` of `points`, in the order of [`residuals`].
pub fn sqrt_weights(points: &[&Point], channels: usize) -> Vec<f64> {
    let mut w = Vec::with_capacity(points.len() * channels);
    for p in points {
        for c in 0..channels {
            w.push(weight(p, c));
        }
    }
    let s: f64 = w.iter().sum();
    w.iter().map(|x| (x / s).sqrt()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn residual_is_relative_error_in_log_space() {
        // A 1% error on a value well above the offset is ln(1.01) ~ 0.00995.
        let r = log_residual(1.01, 1.0);
        assert!((r - (1.01f64 + 1e-3).ln() + (1.0f64 + 1e-3).ln()).abs() < 1e-15);
        assert!((r - 0.00995).abs() < 1e-4);
        // A zero measurement gives a finite residual.
        assert!(log_residual(0.0, 0.0) == 0.0);
    }
}
