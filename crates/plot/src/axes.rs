//! Axes: round tick values (1, 2 or 5 times a power of ten; on a log axis the
//! powers of ten and their 2 and 5 multiples), their labels without float
//! noise, the value range of a panel, and [`TickedAxis`], a plotters axis whose
//! grid lines are exactly the chosen ticks.

use crate::Panel;

/// A tick value as people write it: at most `digits` significant digits,
/// no float noise (`0.30000000000000004` is `0.3`), no trailing zeros, and
/// scientific notation below 1e-3 or from 1e5 on.
pub fn tick_label(x: f64, digits: usize) -> String {
    if x == 0.0 || !x.is_finite() {
        return if x == 0.0 { "0".into() } else { format!("{x}") };
    }
    let e = x.abs().log10().floor() as i32;
    if !(-3..5).contains(&e) {
        let s = format!("{:.*e}", digits.saturating_sub(1), x);
        // 2.0e-4 -> 2e-4
        let (m, ex) = s.split_once('e').unwrap_or((&s, "0"));
        let m = if m.contains('.') {
            m.trim_end_matches('0').trim_end_matches('.')
        } else {
            m
        };
        return format!("{m}e{ex}");
    }
    let d = (digits as i32 - 1 - e).max(0) as usize;
    let s = format!("{x:.d$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Tick positions for a log axis from `10^lo` to `10^hi` (arguments are
/// log10 values; so are the results): the powers of ten, with 2 and 5 times
/// them when fewer than four decades are shown, and every 1..9 multiple when
/// less than one is, so that a panel always has at least two labelled ticks.
pub fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let span = hi - lo;
    let mults: &[f64] = if span < 1.0 {
        &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]
    } else if span < 4.0 {
        &[1.0, 2.0, 5.0]
    } else {
        &[1.0]
    };
    let mut v = Vec::new();
    for k in (lo.floor() as i32 - 1)..=(hi.ceil() as i32) {
        for m in mults {
            let x = (m * 10f64.powi(k)).log10();
            if x >= lo - 1e-9 && x <= hi + 1e-9 {
                v.push(x);
            }
        }
    }
    if v.len() > 8 {
        // Thin to at most 8 ticks, keeping every n-th.
        let n = v.len().div_ceil(8);
        v = v.into_iter().step_by(n).collect();
    }
    v
}

/// Tick positions for a linear axis from `lo` to `hi`: 1, 2 or 5 times a
/// power of ten apart, about `n` of them.
pub fn linear_ticks(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let raw = (hi - lo) / n.max(1) as f64;
    if !(raw > 0.0 && raw.is_finite()) {
        return vec![lo];
    }
    let p = 10f64.powf(raw.log10().floor());
    // The round step nearest to `raw` in ratio, so that the count is about `n`
    // from either side (0..0.43 in 4: steps of 0.1, five ticks, not 0.2 and three).
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * p)
        .min_by(|a, b| (a / raw).ln().abs().total_cmp(&(b / raw).ln().abs()))
        .unwrap_or(p);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step + 1e-9).floor() as i64;
    (first..=last).map(|k| k as f64 * step).collect()
}

/// A linear axis from `lo` to `hi` whose grid lines and labels are exactly
/// `ticks` (plotters chooses its own key points otherwise, which on a log10
/// axis fall at non-round values).
#[derive(Clone, Debug)]
pub struct TickedAxis {
    /// Lower end of the axis.
    pub lo: f64,
    /// Upper end of the axis.
    pub hi: f64,
    /// Positions of the grid lines and labels.
    pub ticks: Vec<f64>,
}

impl plotters::coord::ranged1d::Ranged for TickedAxis {
    type FormatOption = plotters::coord::ranged1d::DefaultFormatting;
    type ValueType = f64;
    fn map(&self, v: &f64, limit: (i32, i32)) -> i32 {
        let f = (v - self.lo) / (self.hi - self.lo);
        limit.0 + (f * (limit.1 - limit.0) as f64).round() as i32
    }
    fn key_points<H: plotters::coord::ranged1d::KeyPointHint>(&self, hint: H) -> Vec<f64> {
        if hint.max_num_points() == 0 {
            return Vec::new();
        }
        self.ticks.clone()
    }
    fn range(&self) -> std::ops::Range<f64> {
        self.lo..self.hi
    }
}

/// The value range of `panel` (log10 values on a log axis): from 0 (or
/// down to the smallest positive value, at most four decades below the top) to
/// a little above the largest value or error-bar top.
pub(crate) fn y_range(panel: &Panel, log_y: bool) -> (f64, f64) {
    // Values and the tops of the error bars.
    let vals = panel.series.iter().flat_map(|s| {
        s.points
            .iter()
            .enumerate()
            .map(move |(i, p)| p.1 + s.stderr.get(i).copied().unwrap_or(0.0))
    });
    if log_y {
        let pos: Vec<f64> = vals.filter(|v| *v > 0.0 && v.is_finite()).collect();
        let hi = pos.iter().cloned().fold(1e-6, f64::max);
        // Down to the smallest positive value (measurement or component), but at
        // most four decades below the largest.
        let min = pos.iter().cloned().fold(f64::INFINITY, f64::min);
        let lo = (min * 0.8).max(hi * 1e-4).min(hi * 0.1);
        (lo.log10(), hi.log10() + 0.15)
    } else {
        let hi = vals.filter(|v| v.is_finite()).fold(0.0, f64::max);
        (0.0, if hi > 0.0 { hi * 1.08 } else { 1.0 })
    }
}
