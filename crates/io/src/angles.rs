//! Lists of in-plane angles given on the command line: a single angle (`30`)
//! or a range `FROM:TO:STEP` in degrees (TO included when the steps reach it).
//!
//! Grid angles are `FROM + k * STEP` rounded to [`ANGLE_DECIMALS`] decimals, so
//! `0:1:0.1` gives `0.3`, not `0.30000000000000004`: the rounded value is the
//! one used and printed. Errors quote the text as given. [`check_angles`]
//! checks angles against an allowed range.

use std::ops::{Bound, RangeBounds};

/// Decimals grid angles are rounded to (far below any measurement's precision).
pub const ANGLE_DECIMALS: i32 = 9;

/// An angle list that cannot be used; the message quotes what was given.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct AngleError(pub String);

/// Rounds a grid angle to [`ANGLE_DECIMALS`] decimals.
pub fn round_angle(x: f64) -> f64 {
    // Beyond a million degrees the decimals are not representable anyway (and
    // x * 1e9 could overflow): such angles are kept for the range check to refuse.
    if x.is_nan() || x.abs() >= 1e6 {
        return x;
    }
    let s = 10f64.powi(ANGLE_DECIMALS);
    let r = (x * s).round() / s;
    // -0 prints as "-0"; an angle of zero has no sign.
    if r == 0.0 {
        0.0
    } else {
        r
    }
}

/// Parses `s`: one angle, or `FROM:TO:STEP` (degrees); `what` names the option
/// in errors and `max_count` bounds the number of angles.
pub fn parse_angles(s: &str, what: &str, max_count: usize) -> Result<Vec<f64>, AngleError> {
    let e = |m: String| AngleError(format!("{what} `{s}`: {m}"));
    let num = |p: &str| {
        p.trim()
            .parse::<f64>()
            .map_err(|_| e(format!("`{}` is not a number", p.trim())))
    };
    let parts: Vec<&str> = s.split(':').collect();
    match parts.len() {
        1 => {
            let a = num(parts[0])?;
            if !a.is_finite() {
                return Err(e("the angle must be a finite number of degrees".into()));
            }
            Ok(vec![a])
        }
        3 => {
            let (from, to, step) = (num(parts[0])?, num(parts[1])?, num(parts[2])?);
            if !(from.is_finite() && to.is_finite()) {
                return Err(e("FROM and TO must be finite numbers of degrees".into()));
            }
            if !(step.is_finite() && step > 0.0) {
                return Err(e(format!(
                    "STEP `{}` must be a positive finite number of degrees",
                    parts[2].trim()
                )));
            }
            if to < from {
                return Err(e("TO is below FROM".into()));
            }
            // Steps that reach TO (to a part in 1e9 of a step, against rounding).
            let n = ((to - from) / step + 1e-9).floor();
            if n.is_nan() || n >= max_count as f64 {
                return Err(e(format!(
                    "{} angles, more than the limit of {max_count}; use a larger STEP",
                    if n.is_finite() {
                        format!("{}", n + 1.0)
                    } else {
                        "too many".into()
                    }
                )));
            }
            Ok((0..=n as usize).map(|k| round_angle(from + k as f64 * step)).collect())
        }
        _ => Err(e(
            "expected one angle (e.g. 30) or FROM:TO:STEP in degrees (e.g. -80:80:10)".into(),
        )),
    }
}

/// Checks that every angle of `v` is finite and within `range` (degrees; any
/// mix of open and closed ends, e.g. `0.0..90.0` for `[0, 90)`); the error
/// names the option `what`, the value and the range:
/// `--theta-i = 95 is outside the allowed range [0, 90) degrees`.
pub fn check_angles(v: &[f64], what: &str, range: impl RangeBounds<f64>) -> Result<(), AngleError> {
    let Some(bad) = v.iter().find(|a| !(a.is_finite() && range.contains(a))) else {
        return Ok(());
    };
    let (open, lo) = match range.start_bound() {
        Bound::Included(x) => ('[', x.to_string()),
        Bound::Excluded(x) => ('(', x.to_string()),
        Bound::Unbounded => ('(', "-inf".into()),
    };
    let (hi, close) = match range.end_bound() {
        Bound::Included(x) => (x.to_string(), ']'),
        Bound::Excluded(x) => (x.to_string(), ')'),
        Bound::Unbounded => ("inf".into(), ')'),
    };
    Err(AngleError(format!(
        "{what} = {bad} is outside the allowed range {open}{lo}, {hi}{close} degrees"
    )))
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn ranges_open_and_closed() {
        assert!(check_angles(&[0.0, 90.0], "x", 0.0..=90.0).is_ok());
        let e = check_angles(&[30.0, 95.0], "--theta-i", 0.0..90.0).unwrap_err().0;
        assert_eq!(e, "--theta-i = 95 is outside the allowed range [0, 90) degrees");
        let open = (Bound::Excluded(-90.0), Bound::Excluded(90.0));
        let e = check_angles(&[-90.0], "--theta-o", open).unwrap_err().0;
        assert_eq!(e, "--theta-o = -90 is outside the allowed range (-90, 90) degrees");
        let e = check_angles(&[f64::NAN], "--theta-o", -89.999..=89.999).unwrap_err().0;
        assert_eq!(
            e,
            "--theta-o = NaN is outside the allowed range [-89.999, 89.999] degrees"
        );
    }
    #[test]
    fn single_angle_and_clean_grid() {
        // Issue 17 item 7: `--theta-o 0` was rejected.
        assert_eq!(parse_angles("0", "--theta-o", 10).unwrap(), vec![0.0]);
        assert_eq!(parse_angles(" -45.5 ", "--theta-o", 10).unwrap(), vec![-45.5]);
        // Issue 16: 0:1:0.1 printed 0.30000000000000004.
        let v = parse_angles("0:1:0.1", "--theta-o", 100).unwrap();
        let shown: Vec<String> = v.iter().map(|x| x.to_string()).collect();
        assert_eq!(
            shown,
            ["0", "0.1", "0.2", "0.3", "0.4", "0.5", "0.6", "0.7", "0.8", "0.9", "1"]
        );
        // Negative start crossing zero: no "-0".
        let v = parse_angles("-0.2:0.2:0.1", "x", 100).unwrap();
        assert_eq!(
            v.iter().map(|x| x.to_string()).collect::<Vec<_>>(),
            ["-0.2", "-0.1", "0", "0.1", "0.2"]
        );
        // TO not on the grid: the last angle below it.
        assert_eq!(parse_angles("0:10:3", "x", 100).unwrap(), vec![0.0, 3.0, 6.0, 9.0]);
        assert_eq!(parse_angles("5:5:1", "x", 100).unwrap(), vec![5.0]);
    }
    #[test]
    fn errors_quote_what_was_given() {
        // Issue 16: `-90:90:inf` reported `--theta-o = NaN`.
        let m = parse_angles("-90:90:inf", "--theta-o", 100).unwrap_err().0;
        assert!(
            m.contains("`-90:90:inf`") && m.contains("STEP `inf`") && !m.contains("NaN"),
            "{m}"
        );
        let m = parse_angles("0:10:-1", "--theta-o", 100).unwrap_err().0;
        assert!(m.contains("STEP `-1`"), "{m}");
        let m = parse_angles("0:nan:1", "--theta-o", 100).unwrap_err().0;
        assert!(m.contains("finite"), "{m}");
        let m = parse_angles("10:0:1", "--theta-o", 100).unwrap_err().0;
        assert!(m.contains("TO is below FROM"), "{m}");
        let m = parse_angles("-89:89:0.002", "--theta-o", 1000).unwrap_err().0;
        assert!(m.contains("89001 angles") && m.contains("limit of 1000"), "{m}");
        let m = parse_angles("0:1e300:1e-300", "--theta-o", 1000).unwrap_err().0;
        assert!(m.contains("limit of 1000"), "{m}");
        let m = parse_angles("1:2", "--theta-o", 10).unwrap_err().0;
        assert!(m.contains("FROM:TO:STEP"), "{m}");
        assert!(parse_angles("abc", "--theta-o", 10)
            .unwrap_err()
            .0
            .contains("`abc` is not a number"));
        assert!(parse_angles("inf", "--theta-o", 10).is_err());
        // Exactly at the limit is accepted.
        assert_eq!(parse_angles("0:9:1", "x", 10).unwrap().len(), 10);
        assert!(parse_angles("0:10:1", "x", 10).is_err());
    }
}
