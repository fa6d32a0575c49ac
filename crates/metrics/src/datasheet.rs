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
pub const M_F_RANGE: (f64, f64) = (0.003, 1.2);
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
        let mut err = None;
        let x = illinois(
            (-ln(M_F_RANGE.1), glo - target),
            (-ln(M_F_RANGE.0), ghi - target),
            0.01,
            |x| match g_at((-x).exp()) {
                Ok(v) => v - target,
                Err(e) => {
                    err = Some(e);
                    0.0
                }
            },
        );
        match err {
            Some(e) => Err(e),
            None => Ok((-x).exp()),
        }
    };

    // For a sigma_s, the sigma_a of each channel that gives target_rinf; returns them and the opacity.
    let solve_absorption = |ss: f64, m: f64, warm: [f64; 3]| -> Result<([f64; 3], f64), DatasheetError> {
        let eval = |sa: [f64; 3]| body(&params(d, ss, sa, m, dist_f), &q);
        let (rmax, _) = eval([SIGMA_A_RANGE.0; 3])?;
        for c in 0..3 {
            if target_rinf[c] > rmax[c] + 5e-4 {
                return Err(DatasheetError::Impossible(format!(
                    "pad reflectance {:.1} % in the {} channel (brightness {brightness} %{}): a non-absorbing sheet with these faces reflects at most {:.1} %; more needs fluorescent whitening (or faces that lose less light)",
                    100.0 * target_rinf[c],
                    ["red", "green", "blue"][c],
                    if ds.tint.is_some() { " with the tint" } else { "" },
                    100.0 * rmax[c]
                )));
            }
        }
        // Illinois on each channel at once, in u = ln sigma_a (R_inf decreases with u: use -R).
        let mut lo = [(ln(SIGMA_A_RANGE.0), 0.0); 3];
        let mut hi = [(ln(SIGMA_A_RANGE.1), 0.0); 3];
        let (rlo, _) = (rmax, 0.0);
        let (rhi, _) = eval([SIGMA_A_RANGE.1; 3])?;
        for c in 0..3 {
            lo[c].1 = target_rinf[c] - rlo[c];
            hi[c].1 = target_rinf[c] - rhi[c];
            // Warm start: tighten the bracket around the previous solution if it brackets.
            let _ = warm;
        }
        let mut x = [0.0; 3];
        let mut side = [0i32; 3];
        let mut done = [false; 3];
        for c in 0..3 {
            if hi[c].1 <= 0.0 {
                // Even the most absorbing sheet is brighter than asked (target below the faces' reflection).
                return Err(DatasheetError::Impossible(format!(
                    "pad reflectance {:.1} % in the {} channel is below what the faces alone reflect ({:.1} %)",
                    100.0 * target_rinf[c],
                    ["red", "green", "blue"][c],
                    100.0 * rhi[c]
                )));
            }
        }
        let mut last = (rmax, 0.0);
        for _ in 0..60 {
            for c in 0..3 {
                if !done[c] {
                    x[c] = if hi[c].1 != lo[c].1 {
                        (lo[c].0 * hi[c].1 - hi[c].0 * lo[c].1) / (hi[c].1 - lo[c].1)
                    } else {
                        0.5 * (lo[c].0 + hi[c].0)
                    };
                }
            }
            let sa = [x[0].exp(), x[1].exp(), x[2].exp()];
            last = eval(sa)?;
            let mut all = true;
            for c in 0..3 {
                let v = target_rinf[c] - last.0[c];
                if v.abs() < 2e-5 || (hi[c].0 - lo[c].0).abs() < 1e-10 {
                    done[c] = true;
                    continue;
                }
                done[c] = false;
                all = false;
                if v < 0.0 {
                    lo[c] = (x[c], v);
                    if side[c] == -1 {
                        hi[c].1 *= 0.5;
                    }
                    side[c] = -1;
                } else {
                    hi[c] = (x[c], v);
                    if side[c] == 1 {
                        lo[c].1 *= 0.5;
                    }
                    side[c] = 1;
                }
            }
            if all {
                return Ok((sa, last.1));
            }
        }
        Ok(([x[0].exp(), x[1].exp(), x[2].exp()], last.1))
    };

    // Round 1: gloss with a typical body; then the body; then the gloss again.
    let mut ss = 300.0;
    let mut sa = [0.1; 3];
    if let Some(g) = ds.gloss75 {
        m_f = solve_gloss(ss, sa, g)?;
    }
    let target_op = ds.opacity;
    for round in 0..2 {
        let (l0, l1) = (ln(SIGMA_S_RANGE.0), ln(SIGMA_S_RANGE.1));
        let (_, op_lo) = solve_absorption(l0.exp(), m_f, sa)?;
        let (_, op_hi) = solve_absorption(l1.exp(), m_f, sa)?;
        if target_op > op_hi + 0.02 {
            return Err(DatasheetError::Impossible(format!(
                "opacity {target_op} %: at caliper {d} mm even sigma_s = {} /mm (the most scattering searched) gives {op_hi:.1} % with this brightness; a thicker sheet or a darker one is needed",
                SIGMA_S_RANGE.1
            )));
        }
        if target_op < op_lo - 0.02 {
            return Err(DatasheetError::Impossible(format!(
                "opacity {target_op} %: at caliper {d} mm even sigma_s = {} /mm gives {op_lo:.1} % with this brightness (the faces' own reflection and the absorption that the brightness needs make the sheet that opaque)",
                SIGMA_S_RANGE.0
            )));
        }
        let err = std::cell::RefCell::new(None);
        let lss = illinois(
            (l0, op_lo - target_op),
            (l1, op_hi - target_op),
            0.01,
            |x| match solve_absorption(x.exp(), m_f, sa) {
                Ok((_, op)) => op - target_op,
                Err(e) => {
                    *err.borrow_mut() = Some(e);
                    0.0
                }
            },
        );
        if let Some(e) = err.into_inner() {
            return Err(e);
        }
        ss = lss.exp();
        sa = solve_absorption(ss, m_f, sa)?.0;
        match ds.gloss75 {
            Some(g) if round == 0 => m_f = solve_gloss(ss, sa, g)?,
            _ => break,
        }
    }
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
