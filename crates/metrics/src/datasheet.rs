//! A sheet from its datasheet: Paper BSDF parameters that reproduce a
//! paper's grammage, caliper, ISO opacity and optionally ISO brightness,
//! 75-degree gloss and tint, through the same measurements as
//! [`crate::measure::measure_model`].
//!
//! **What is fixed.** `d` is the caliper. Both faces have index 1.5
//! (cellulose, polymer coatings); the back face is GGX with `m_b = 0.15`; the
//! phase function is the matte preset's (`g_f = 0.8`, `g_b = -0.4`,
//! `w_b = 0.2`). **What is solved.** `sigma_s` (one value) for the opacity;
//! `sigma_a` per channel for the pad reflectance `R_inf` (blue from the
//! brightness, red and green from the tint: `R_inf,c = R457/100 * tint_c / tint_b`);
//! `m_f` for the gloss (GGX below 30 GU, Beckmann above, as the supplement
//! finds for uncoated and coated papers). Without `--brightness` the pad
//! reflectance is taken as [`DEFAULT_BRIGHTNESS`] (said so in the report);
//! without `--gloss75` the front is the matte preset's (`m_f = 0.15`, GGX).
//!
//! **How.** Nested one-dimensional root finding in log space (Illinois
//! regula falsi within a bracket, each measurement being monotone in its
//! parameter): for each trial `sigma_s`, the three `sigma_a` are solved
//! together (the channels are independent), then `sigma_s` for the opacity;
//! `m_f` is solved for the gloss before and after the body (gloss hardly
//! depends on the body). **Impossible targets** are found at the ends of the
//! brackets and reported with the reason: a pad reflectance above what a
//! non-absorbing slab with these faces reflects (it needs fluorescent
//! whitening), an opacity above what the caliper reaches with the most
//! scattering allowed ([`SIGMA_S_RANGE`]) or below what the faces' own
//! reflection gives, a gloss above a smooth face of index 1.5, a density
//! above that of solid cellulose.

use crate::gloss::{self, GEOMETRIES};
use crate::instrument::{self, luminance, Quality};
use crate::measure::{measure_model, Measurements, Selection};
use paperbsdf_core::paper::PaperBsdf;
use paperbsdf_core::{Colour, Distribution, PaperParams, Rgb};

/// The pad reflectance (as ISO brightness, %) assumed when none is given.
pub const DEFAULT_BRIGHTNESS: f64 = 85.0;
/// Range searched for `sigma_s`, 1/mm (the upper end is far beyond the most
/// strongly scattering pigment coatings: `sigma_s' = 2000` /mm).
pub const SIGMA_S_RANGE: (f64, f64) = (0.5, 10_000.0);
/// Range searched for `sigma_a`, 1/mm.
pub const SIGMA_A_RANGE: (f64, f64) = (1e-7, 500.0);
/// Range searched for `m_f`.
pub const M_F_RANGE: (f64, f64) = (0.01, 1.2);
/// Density of solid cellulose, g/cm^3: no sheet is denser.
pub const MAX_DENSITY: f64 = 1.6;

/// A datasheet.
#[derive(Clone, Debug, PartialEq)]
pub struct Datasheet {
    /// Grammage, g/m^2.
    pub grammage: f64,
    /// Caliper (thickness), mm.
    pub caliper: f64,
    /// ISO 2471 opacity, %.
    pub opacity: f64,
    /// ISO 2470-1 brightness R457, %.
    pub brightness: Option<f64>,
    /// TAPPI T480 75-degree gloss, GU.
    pub gloss75: Option<f64>,
    /// Relative pad reflectance of the R, G, B channels, each in (0, 1].
    pub tint: Option<[f64; 3]>,
}

/// Why a datasheet gave no parameters.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DatasheetError {
    /// A value outside its allowed range.
    #[error("{0}")]
    BadInput(String),
    /// Targets that no sheet of this kind can meet, with the reason.
    #[error("{0}")]
    Impossible(String),
    /// The pad reflectance cannot be reached at one trial `sigma_s` (internal
    /// to the search: more scattering may reach it).
    #[error("{0}")]
    Unreachable(String),
}

impl Datasheet {
    /// Checks every value's range; the error names the option, the value and the range.
    pub fn validate(&self) -> Result<(), DatasheetError> {
        let bad = |m: String| Err(DatasheetError::BadInput(m));
        if !(self.grammage.is_finite() && self.grammage > 0.0) {
            return bad(format!("--grammage {}: must be positive (g/m^2)", self.grammage));
        }
        if !(self.caliper.is_finite() && self.caliper > 0.0) {
            return bad(format!("--caliper {}: must be positive (mm)", self.caliper));
        }
        if !(self.opacity.is_finite() && self.opacity > 0.0 && self.opacity <= 100.0) {
            return bad(format!("--opacity {}: must be in (0, 100] (%)", self.opacity));
        }
        if let Some(b) = self.brightness {
            if !(b.is_finite() && b > 0.0) {
                return bad(format!("--brightness {b}: must be positive (%)"));
            }
        }
        if let Some(g) = self.gloss75 {
            if !(g.is_finite() && g >= 0.0) {
                return bad(format!("--gloss75 {g}: must be at least 0 (GU)"));
            }
        }
        if let Some(t) = self.tint {
            for (c, v) in ["R", "G", "B"].iter().zip(t) {
                if !(v.is_finite() && v > 0.0 && v <= 1.0) {
                    return bad(format!("--tint {c} = {v}: each channel must be in (0, 1]"));
                }
            }
        }
        Ok(())
    }
}

/// What [`fit_datasheet`] found.
#[derive(Clone, Debug, PartialEq)]
pub struct DatasheetFit {
    /// The parameters.
    pub params: PaperParams,
    /// Their measurements (default quality, as `measure` reports them).
    pub measured: Measurements,
    /// `(name, target, achieved)` for every given target.
    pub targets: Vec<(&'static str, f64, f64)>,
    /// Notes: assumptions taken for targets that were not given.
    pub notes: Vec<String>,
}

fn params(d: f64, sigma_s: f64, sigma_a: [f64; 3], m_f: f64, dist_f: Distribution) -> PaperParams {
    PaperParams {
        name: Some("from datasheet".into()),
        d,
        sigma_a: if sigma_a[0] == sigma_a[1] && sigma_a[1] == sigma_a[2] {
            Colour::Scalar(sigma_a[0])
        } else {
            Colour::Rgb(sigma_a)
        },
        sigma_s: Colour::Scalar(sigma_s),
        g_f: 0.8,
        g_b: -0.4,
        w_b: 0.2,
        eta_f: 1.5,
        eta_b: 1.5,
        m_f,
        m_b: 0.15,
        dist_f,
        dist_b: Distribution::Ggx,
        face_scattering: Default::default(),
    }
}

/// Illinois regula falsi for an increasing `g` (in `x`) and target 0, on a
/// bracket `[lo, hi]` with `g(lo) <= 0 <= g(hi)`, to `|g| < tol` or 60 steps.
fn illinois(mut lo: (f64, f64), mut hi: (f64, f64), tol: f64, mut g: impl FnMut(f64) -> f64) -> f64 {
    let mut side = 0i32;
    for _ in 0..60 {
        let x = if hi.1 != lo.1 {
            (lo.0 * hi.1 - hi.0 * lo.1) / (hi.1 - lo.1)
        } else {
            0.5 * (lo.0 + hi.0)
        };
        let x = x.clamp(lo.0.min(hi.0), lo.0.max(hi.0));
        let v = g(x);
        if v.abs() < tol || (hi.0 - lo.0).abs() < 1e-12 {
            return x;
        }
        if v < 0.0 {
            lo = (x, v);
            if side == -1 {
                hi.1 *= 0.5;
            }
            side = -1;
        } else {
            hi = (x, v);
            if side == 1 {
                lo.1 *= 0.5;
            }
            side = 1;
        }
    }
    if lo.1.abs() < hi.1.abs() {
        lo.0
    } else {
        hi.0
    }
}

/// Pad reflectance `R_inf` (per channel) and ISO opacity of a parameter set, fast quality.
fn body(p: &PaperParams, q: &Quality) -> Result<([f64; 3], f64), DatasheetError> {
    let b = PaperBsdf::new(p).map_err(|e| DatasheetError::BadInput(e.to_string()))?;
    let r = instrument::stack(&instrument::model_factors(&b, q));
    let (r0, rinf) = (luminance(Rgb(r.r0)), luminance(Rgb(r.r_inf)));
    Ok((r.r_inf, if rinf > 0.0 { 100.0 * r0 / rinf } else { 100.0 }))
}

fn gloss75(p: &PaperParams) -> Result<f64, DatasheetError> {
    let b = PaperBsdf::new(p).map_err(|e| DatasheetError::BadInput(e.to_string()))?;
    Ok(gloss::gloss(&b, &GEOMETRIES[0]))
}

/// Finds parameters for `ds` (module doc).
pub fn fit_datasheet(ds: &Datasheet) -> Result<DatasheetFit, DatasheetError> {
    ds.validate()?;
    let mut notes = Vec::new();
    let density = ds.grammage / (ds.caliper * 1000.0);
    if density > MAX_DENSITY {
        return Err(DatasheetError::Impossible(format!(
            "grammage {} g/m^2 at caliper {} mm is a density of {density:.2} g/cm^3, above the {MAX_DENSITY} of solid cellulose: check the units (g/m^2, mm)",
            ds.grammage, ds.caliper
        )));
    }
    let brightness = match ds.brightness {
        Some(b) => b,
        None => {
            notes.push(format!(
                "no --brightness: the pad reflectance R_inf is taken as {DEFAULT_BRIGHTNESS} % (assumed, not a target)"
            ));
            DEFAULT_BRIGHTNESS
        }
    };
    if brightness > 100.0 {
        return Err(DatasheetError::Impossible(format!(
            "brightness {brightness} %: a pad reflects at most all the light (100 %); an ISO brightness above 100 needs fluorescent whitening, which this model (no fluorescence) cannot represent"
        )));
    }
    let tint = ds.tint.unwrap_or([1.0, 1.0, 1.0]);
    let target_rinf: [f64; 3] = std::array::from_fn(|c| brightness / 100.0 * tint[c] / tint[2]);
    if let Some(c) = (0..3).find(|&c| target_rinf[c] > 1.0) {
        return Err(DatasheetError::Impossible(format!(
            "--tint with brightness {brightness} % asks the {} channel for a pad reflectance of {:.1} %, above 100 %",
            ["red", "green", "blue"][c],
            100.0 * target_rinf[c]
        )));
    }
    let (dist_f, mut m_f) = match ds.gloss75 {
        Some(g) if g >= 30.0 => (Distribution::Beckmann, 0.05),
        Some(_) => (Distribution::Ggx, 0.15),
        None => {
            notes.push("no --gloss75: the front face is the matte preset's (GGX, m_f = 0.15)".into());
            (Distribution::Ggx, 0.15)
        }
    };
    let q = Quality::fast();
    let d = ds.caliper;
    let ln = f64::ln;
    let channel = ["red", "green", "blue"];

    // Solve m_f for the gloss with the body `ss`, `sa`.
    let solve_gloss = |ss: f64, sa: [f64; 3], target: f64| -> Result<f64, DatasheetError> {
        let g_at = |m: f64| gloss75(&params(d, ss, sa, m, dist_f));
        let (glo, ghi) = (g_at(M_F_RANGE.1)?, g_at(M_F_RANGE.0)?);
        if target > ghi + 0.05 {
            return Err(DatasheetError::Impossible(format!(
                "75-degree gloss {target} GU: even a nearly smooth front of index 1.5 (m_f = {}) gives {ghi:.1} GU",
                M_F_RANGE.0
            )));
        }
        if target < glo - 0.05 {
            return Err(DatasheetError::Impossible(format!(
                "75-degree gloss {target} GU: even the roughest front searched (m_f = {}) gives {glo:.1} GU",
                M_F_RANGE.1
            )));
        }
        // Gloss decreases with m: solve in -ln m so the function increases.
        let err = std::cell::RefCell::new(None);
        let x = illinois(
            (-ln(M_F_RANGE.1), glo - target),
            (-ln(M_F_RANGE.0), ghi - target),
            0.01,
            |x| match g_at((-x).exp()) {
                Ok(v) => v - target,
                Err(e) => {
                    *err.borrow_mut() = Some(e);
                    0.0
                }
            },
        );
        match err.into_inner() {
            Some(e) => Err(e),
            None => Ok((-x).exp()),
        }
    };

    // For a sigma_s, the sigma_a of each channel that gives the pad
    // reflectance `trinf` (safeguarded secant in ln sigma_a, all channels at
    // once, started from `guess`); returns them and the opacity.
    let solve_absorption = |ss: f64,
                            m: f64,
                            guess: [f64; 3],
                            trinf: [f64; 3]|
     -> Result<([f64; 3], f64), DatasheetError> {
        let eval = |x: [f64; 3]| body(&params(d, ss, [x[0].exp(), x[1].exp(), x[2].exp()], m, dist_f), &q);
        let (xa, xb) = (ln(SIGMA_A_RANGE.0), ln(SIGMA_A_RANGE.1));
        // v(x) = trinf - R_inf(x) increases with x (more absorption, darker pad).
        let mut lo: [Option<(f64, f64)>; 3] = [None; 3];
        let mut hi: [Option<(f64, f64)>; 3] = [None; 3];
        let mut x: [f64; 3] = std::array::from_fn(|c| ln(guess[c].clamp(SIGMA_A_RANGE.0, SIGMA_A_RANGE.1)));
        let mut prev: [Option<(f64, f64)>; 3] = [None; 3];
        let mut last_op = 0.0;
        for it in 0..40 {
            let (r, op) = eval(x)?;
            last_op = op;
            let mut done = true;
            let mut need_min = false;
            let mut next = x;
            for c in 0..3 {
                let v = trinf[c] - r[c];
                if v.abs() < 1e-5 {
                    continue;
                }
                done = false;
                if v < 0.0 {
                    lo[c] = Some((x[c], v));
                } else {
                    hi[c] = Some((x[c], v));
                    if lo[c].is_none() {
                        need_min = true;
                    }
                }
                // Secant through the last two points, kept inside the bracket.
                let (blo, bhi) = (lo[c].map_or(xa, |p| p.0), hi[c].map_or(xb, |p| p.0));
                let mut xn = match prev[c] {
                    Some((xp, vp)) if vp != v => x[c] - v * (x[c] - xp) / (v - vp),
                    _ => x[c] - v.signum() * 0.7,
                };
                if !(xn > blo && xn < bhi && xn.is_finite()) {
                    xn = match (lo[c], hi[c]) {
                        (Some(l), Some(h)) => 0.5 * (l.0 + h.0),
                        (None, _) => (x[c] - 2.0).max(xa),
                        (_, None) => (x[c] + 2.0).min(xb),
                    };
                }
                prev[c] = Some((x[c], v));
                next[c] = xn;
            }
            if done {
                return Ok(([x[0].exp(), x[1].exp(), x[2].exp()], op));
            }
            if need_min && it == 0 {
                // Can the pad reach the target at all (no absorption)?
                let (rmax, _) = eval([xa; 3])?;
                for c in 0..3 {
                    if trinf[c] > rmax[c] + 5e-4 {
                        return Err(DatasheetError::Unreachable(format!(
                            "pad reflectance {:.1} % in the {} channel (brightness {brightness} %{}): a non-absorbing sheet with these faces reflects at most {:.1} %; more needs fluorescent whitening",
                            100.0 * trinf[c],
                            channel[c],
                            if ds.tint.is_some() { " with the tint" } else { "" },
                            100.0 * rmax[c]
                        )));
                    }
                }
            }
            x = next;
        }
        Ok(([x[0].exp(), x[1].exp(), x[2].exp()], last_op))
    };

    // The body for targets (opacity, pad reflectance) at front roughness m:
    // Illinois on ln sigma_s; a sigma_s at which the pad reflectance cannot
    // be reached counts as too little scattering.
    let solve_body = |m: f64,
                      t_op: f64,
                      trinf: [f64; 3],
                      start: (f64, [f64; 3])|
     -> Result<(f64, [f64; 3]), DatasheetError> {
        let unreachable = std::cell::RefCell::new(None);
        let warm = std::cell::Cell::new(start);
        let op_minus = |x: f64| -> Result<f64, DatasheetError> {
            let (ss0, sa0) = warm.get();
            // Absorption scales with scattering at a fixed pad reflectance (K/S).
            let k = x.exp() / ss0;
            let guess = [sa0[0] * k, sa0[1] * k, sa0[2] * k];
            match solve_absorption(x.exp(), m, guess, trinf) {
                Ok((sa, op)) => {
                    warm.set((x.exp(), sa));
                    Ok(op - t_op)
                }
                Err(DatasheetError::Unreachable(msg)) => {
                    *unreachable.borrow_mut() = Some(msg);
                    Ok(-1000.0)
                }
                Err(e) => Err(e),
            }
        };
        let (l0, l1) = (ln(SIGMA_S_RANGE.0), ln(SIGMA_S_RANGE.1));
        // A first try at the start, a bracket from the range's ends only if needed.
        let x_s = ln(start.0);
        let g_s = op_minus(x_s)?;
        if g_s.abs() < 0.01 {
            return Ok(warm.get());
        }
        let (lo, hi) = if g_s < 0.0 {
            let g_hi = op_minus(l1)?;
            if g_hi == -1000.0 {
                let why = unreachable.borrow().clone().unwrap_or_default();
                return Err(DatasheetError::Impossible(format!(
                    "{why} (even at sigma_s = {} /mm, the most scattering searched)",
                    SIGMA_S_RANGE.1
                )));
            }
            if g_hi < -0.02 {
                return Err(DatasheetError::Impossible(format!(
                    "opacity {t_op:.1} %: at caliper {d} mm even sigma_s = {} /mm (the most scattering searched) gives {:.1} % with this brightness; a thicker sheet or a darker one is needed",
                    SIGMA_S_RANGE.1,
                    t_op + g_hi
                )));
            }
            ((x_s, g_s), (l1, g_hi))
        } else {
            let g_lo = op_minus(l0)?;
            if g_lo > 0.02 {
                return Err(DatasheetError::Impossible(format!(
                    "opacity {t_op:.1} %: at caliper {d} mm even sigma_s = {} /mm gives {:.1} % with this brightness (the faces' own reflection and the absorption that the brightness needs make the sheet that opaque)",
                    SIGMA_S_RANGE.0,
                    t_op + g_lo
                )));
            }
            ((l0, g_lo), (x_s, g_s))
        };
        let err = std::cell::RefCell::new(None);
        let x = illinois(lo, hi, 0.01, |x| match op_minus(x) {
            Ok(v) => v,
            Err(e) => {
                *err.borrow_mut() = Some(e);
                0.0
            }
        });
        if let Some(e) = err.into_inner() {
            return Err(e);
        }
        let g = op_minus(x)?;
        if g.abs() > 0.05 {
            // The search ended at the edge of the reachable range: the least
            // scattering that reaches the brightness is already too opaque.
            return Err(DatasheetError::Impossible(format!(
                "opacity {t_op:.1} % with brightness {brightness} % at caliper {d} mm: the least scattering sheet that reflects that much (sigma_s = {:.3} /mm) already has opacity {:.1} %",
                x.exp(),
                t_op + g.max(0.0)
            )));
        }
        Ok(warm.get())
    };

    // Gloss with a typical body, the body, the gloss again; then a correction
    // for the difference between the fast integrals of the search and the
    // default ones that `measure` uses (the targets are shifted by it and
    // the body solved again from where it was).
    let mut body_now = (300.0, [0.05; 3]);
    if let Some(g) = ds.gloss75 {
        m_f = solve_gloss(body_now.0, body_now.1, g)?;
    }
    let (mut t_op, mut t_rinf) = (ds.opacity, target_rinf);
    for pass in 0..3 {
        body_now = solve_body(m_f, t_op, t_rinf, body_now)?;
        if let (Some(g), 0) = (ds.gloss75, pass) {
            m_f = solve_gloss(body_now.0, body_now.1, g)?;
            body_now = solve_body(m_f, t_op, t_rinf, body_now)?;
        }
        let p = params(d, body_now.0, body_now.1, m_f, dist_f);
        let (rf, of) = body(&p, &q)?;
        let (rd, od) = body(&p, &Quality::default())?;
        if (od - ds.opacity).abs() < 0.05 && (0..3).all(|c| (rd[c] - target_rinf[c]).abs() < 5e-4) {
            break;
        }
        t_op = ds.opacity - (od - of);
        t_rinf = std::array::from_fn(|c| target_rinf[c] - (rd[c] - rf[c]));
    }
    let (ss, sa) = body_now;
    let p = params(d, ss, sa, m_f, dist_f);
    let model = PaperBsdf::new(&p).map_err(|e| DatasheetError::BadInput(e.to_string()))?;
    let sel = Selection::parse("opacity_iso2471,r457,gloss_75_tappi_t480,kubelka_munk").expect("known names");
    let measured = measure_model(&model, Some(&p), Some(ds.grammage), &sel, &Quality::default());
    let mut targets = vec![(
        "opacity_iso2471",
        ds.opacity,
        measured.opacity_iso2471.unwrap_or(f64::NAN),
    )];
    if let Some(b) = ds.brightness {
        targets.push(("r457", b, measured.r457.unwrap_or(f64::NAN)));
    }
    if let Some(g) = ds.gloss75 {
        targets.push((
            "gloss_75_tappi_t480",
            g,
            measured.gloss_75_tappi_t480.unwrap_or(f64::NAN),
        ));
    }
    Ok(DatasheetFit {
        params: p,
        measured,
        targets,
        notes,
    })
}
