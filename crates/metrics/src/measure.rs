//! The measurements of a sheet, predicted from a model ([`measure_model`],
//! through the public BSDF interface only) or from the simulator
//! ([`measure_truth`]), with their JSON keys and definitions:
//!
//! - `opacity_iso2471`: ISO 2471 (paper backing), `100 Y(R0) / Y(R_inf)`, `d/0` with gloss trap;
//! - `opacity_tappi_t425`: TAPPI T425 contrast ratio `100 Y(R0) / Y(R0.89)`, `15/d`,
//!   over a Lambertian backing of 89 %;
//! - `r457`: ISO 2470-1 brightness, `100 R_inf` of the **blue channel** (an estimate:
//!   the standard weights the spectrum around 457 nm, which RGB does not resolve);
//! - the five gloss geometries of [`crate::gloss::GEOMETRIES`];
//! - `kubelka_munk`: ISO 9416 `s`, `k` (m^2/kg) from `Y(R0)`, `Y(R_inf)` and the grammage;
//! - `scatter_distance_mm`: [`crate::edge`].

use crate::edge::{self, ScatterDistance};
use crate::gloss::{self, GEOMETRIES};
use crate::instrument::{self, luminance, KubelkaMunk, Quality, Reflectances, GLOSS_TRAP_HALF_ANGLE_DEG};
use crate::pad::{simulate_pad, Backing, PadConfig};
use paperbsdf_core::models::ComponentModel;
use paperbsdf_core::{DVec3, PaperParams, ParamError, Rgb};
use paperbsdf_sim::{simulate_bsdf, simulate_exit_profile, LateralConfig, SimConfig, SimError, Slab};
use serde::Serialize;

/// Every metric name `measure` knows (the JSON keys).
pub const METRIC_NAMES: [&str; 10] = [
    "opacity_iso2471",
    "opacity_tappi_t425",
    "r457",
    "gloss_75_tappi_t480",
    "gloss_20_tappi_t653",
    "gloss_20_astm_d523",
    "gloss_60_astm_d523",
    "gloss_85_astm_d523",
    "kubelka_munk",
    "scatter_distance_mm",
];

/// Why measurements could not be made: an unknown metric, or parameters or a
/// simulation request the simulator refuses.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeasureError {
    /// A metric name that is not one of [`METRIC_NAMES`].
    #[error("unknown metric `{0}`; known metrics: {known}", known = METRIC_NAMES.join(", "))]
    UnknownMetric(String),
    /// An empty list of metrics.
    #[error("no metric named; known metrics: {known}", known = METRIC_NAMES.join(", "))]
    NoMetric,
    /// The sheet's parameters are invalid.
    #[error(transparent)]
    Params(#[from] ParamError),
    /// The simulator refused a run.
    #[error(transparent)]
    Sim(#[from] SimError),
}

/// Which metrics to compute.
#[derive(Clone, Debug, PartialEq)]
pub struct Selection(pub Vec<&'static str>);

impl Selection {
    /// All metrics.
    pub fn all() -> Self {
        Selection(METRIC_NAMES.to_vec())
    }
    /// Parses a comma-separated list of metric names; an unknown name is an
    /// error that lists the known ones.
    pub fn parse(list: &str) -> Result<Self, MeasureError> {
        let mut v = Vec::new();
        for name in list.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            match METRIC_NAMES.iter().find(|&&n| n == name) {
                Some(&n) => v.push(n),
                None => return Err(MeasureError::UnknownMetric(name.to_string())),
            }
        }
        if v.is_empty() {
            return Err(MeasureError::NoMetric);
        }
        Ok(Selection(v))
    }
    /// Whether `name` is selected.
    pub fn has(&self, name: &str) -> bool {
        self.0.contains(&name)
    }
    fn any_gloss(&self) -> bool {
        GEOMETRIES.iter().any(|g| self.has(g.key))
    }
}

/// The predicted measurements (JSON keys as in the module doc). A metric that
/// was not asked for, or cannot be computed for this model, is `None`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Measurements {
    /// `model` or `simulator`.
    pub source: &'static str,
    /// ISO 2471 opacity, %.
    pub opacity_iso2471: Option<f64>,
    /// TAPPI T425 opacity (89 % backing), %.
    pub opacity_tappi_t425: Option<f64>,
    /// ISO brightness estimated from the blue channel, %.
    pub r457: Option<f64>,
    /// 75-degree gloss, GU.
    pub gloss_75_tappi_t480: Option<f64>,
    /// 20-degree gloss (TAPPI), GU.
    pub gloss_20_tappi_t653: Option<f64>,
    /// 20-degree gloss (ASTM), GU.
    pub gloss_20_astm_d523: Option<f64>,
    /// 60-degree gloss (ASTM), GU.
    pub gloss_60_astm_d523: Option<f64>,
    /// 85-degree gloss (ASTM), GU.
    pub gloss_85_astm_d523: Option<f64>,
    /// ISO 9416 coefficients (needs the grammage).
    pub kubelka_munk: Option<KubelkaMunk>,
    /// Scatter distance (5-95 % edge width), mm.
    pub scatter_distance_mm: Option<ScatterDistance>,
    /// The reflectances the opacities and brightness come from, per channel.
    pub reflectances: Option<Reflectances>,
}

impl Measurements {
    fn empty(source: &'static str) -> Self {
        Measurements {
            source,
            opacity_iso2471: None,
            opacity_tappi_t425: None,
            r457: None,
            gloss_75_tappi_t480: None,
            gloss_20_tappi_t653: None,
            gloss_20_astm_d523: None,
            gloss_60_astm_d523: None,
            gloss_85_astm_d523: None,
            kubelka_munk: None,
            scatter_distance_mm: None,
            reflectances: None,
        }
    }

    fn set_gloss(&mut self, key: &str, v: f64) {
        let slot = match key {
            "gloss_75_tappi_t480" => &mut self.gloss_75_tappi_t480,
            "gloss_20_tappi_t653" => &mut self.gloss_20_tappi_t653,
            "gloss_20_astm_d523" => &mut self.gloss_20_astm_d523,
            "gloss_60_astm_d523" => &mut self.gloss_60_astm_d523,
            _ => &mut self.gloss_85_astm_d523,
        };
        *slot = Some(v);
    }

    fn set_reflectances(&mut self, r: Reflectances, grammage: Option<f64>, sel: &Selection) {
        let y = |v: [f64; 3]| luminance(Rgb(v));
        let (r0, rinf) = (y(r.r0), y(r.r_inf));
        // A sheet that reflects nothing has no contrast ratio: its opacity is
        // taken as the limit 100 (1 - Y(T0)), 0 for a clear sheet, 100 for a black one.
        let none = 100.0 * (1.0 - y(r.t0)).clamp(0.0, 1.0);
        if sel.has("opacity_iso2471") {
            self.opacity_iso2471 = Some(if rinf > 0.0 { 100.0 * r0 / rinf } else { none });
        }
        if sel.has("opacity_tappi_t425") {
            let r89 = y(r.r089_15);
            self.opacity_tappi_t425 = Some(if r89 > 0.0 { 100.0 * y(r.r0_15) / r89 } else { none });
        }
        if sel.has("r457") {
            self.r457 = Some(100.0 * r.r_inf[2]);
        }
        if sel.has("kubelka_munk") {
            self.kubelka_munk = grammage.and_then(|g| instrument::kubelka_munk(r0, rinf, g));
        }
        self.reflectances = Some(r);
    }

    /// The measurement under JSON key `name` as a number (the 5-95 % width
    /// with blur for `scatter_distance_mm`, `s` for `kubelka_munk`).
    pub fn value(&self, name: &str) -> Option<f64> {
        match name {
            "opacity_iso2471" => self.opacity_iso2471,
            "opacity_tappi_t425" => self.opacity_tappi_t425,
            "r457" => self.r457,
            "gloss_75_tappi_t480" => self.gloss_75_tappi_t480,
            "gloss_20_tappi_t653" => self.gloss_20_tappi_t653,
            "gloss_20_astm_d523" => self.gloss_20_astm_d523,
            "gloss_60_astm_d523" => self.gloss_60_astm_d523,
            "gloss_85_astm_d523" => self.gloss_85_astm_d523,
            "kubelka_munk" => self.kubelka_munk.map(|k| k.s_m2_per_kg),
            "scatter_distance_mm" => self.scatter_distance_mm.map(|s| s.width_blurred_mm),
            _ => None,
        }
    }
}

/// Grid of the model's edge profile: half width (mm) and points.
const EDGE_GRID: (f64, usize) = (3.0, 1201);

/// The measurements of a model through its public interface: `eval`,
/// `sample` and (for the scatter distance) `eval_component(.., Multiple)`;
/// `params` are the Paper BSDF parameters when the model is a paper slab
/// (needed for the multipole profile of the scatter distance).
pub fn measure_model(
    model: &dyn ComponentModel,
    params: Option<&PaperParams>,
    grammage: Option<f64>,
    sel: &Selection,
    q: &Quality,
) -> Measurements {
    let mut m = Measurements::empty("model");
    if ["opacity_iso2471", "opacity_tappi_t425", "r457", "kubelka_munk"]
        .iter()
        .any(|k| sel.has(k))
    {
        let f = instrument::model_factors(model, q);
        m.set_reflectances(instrument::stack(&f), grammage, sel);
    }
    if sel.any_gloss() {
        for g in &GEOMETRIES {
            if sel.has(g.key) {
                m.set_gloss(g.key, gloss::gloss(model, g));
            }
        }
    }
    if sel.has("scatter_distance_mm") {
        if let Some(p) = params {
            m.scatter_distance_mm =
                edge::model_edge(model, p, EDGE_GRID.0, EDGE_GRID.1).map(|e| ScatterDistance::of(&e));
        }
    }
    m
}

/// How much simulation [`measure_truth`] runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TruthConfig {
    /// Photons per pad simulation and channel.
    pub pad_samples: u64,
    /// Walks per gloss geometry and channel.
    pub gloss_samples: u64,
    /// Walks for the lateral exit profile and channel.
    pub lateral_samples: u64,
    /// Seed.
    pub seed: u64,
    /// Progress bars on standard error.
    pub progress: bool,
}

impl Default for TruthConfig {
    fn default() -> Self {
        TruthConfig {
            pad_samples: 1 << 17,
            gloss_samples: 1 << 15,
            lateral_samples: 1 << 18,
            seed: 1,
            progress: false,
        }
    }
}

/// Number of sheets for an opaque pad: the smallest `n` whose stacked
/// transmittance (from the sheet's `r`, `t`) is below 1e-3, at most 60.
pub fn opaque_sheets(r: f64, t: f64) -> usize {
    let (mut rn, mut tn) = (r, t);
    for n in 1..60 {
        if tn < 1e-3 {
            return n;
        }
        let d = 1.0 - r * rn;
        tn = tn * t / d;
        rn = r + t * t * rn / d;
    }
    60
}

/// The measurements of the physical sheet of `p` from the simulator: pads of
/// sheets simulated exactly ([`crate::pad`]), gloss from `simulate_bsdf` at the
/// nominal angle over the receptor window (plus the Fresnel mirror
/// reflection of a smooth front face, a delta that `f` does not include),
/// scatter distance from the lateral exit profile. Errors name what is wrong.
pub fn measure_truth(
    p: &PaperParams,
    grammage: Option<f64>,
    sel: &Selection,
    cfg: &TruthConfig,
) -> Result<Measurements, MeasureError> {
    let slab = Slab::from_params(p)?;
    let mut m = Measurements::empty("simulator");
    let pc = PadConfig {
        samples: cfg.pad_samples,
        batches: 16,
        seed: cfg.seed,
    };
    if ["opacity_iso2471", "opacity_tappi_t425", "r457", "kubelka_munk"]
        .iter()
        .any(|k| sel.has(k))
    {
        let trap = Some(GLOSS_TRAP_HALF_ANGLE_DEG.to_radians().cos());
        let one = simulate_pad(&slab, 1, Backing::Black, DVec3::Z, trap, &pc);
        let (r1, t1) = (one.reflected.mean, one.transmitted.mean);
        let n = (0..3).map(|c| opaque_sheets(r1.0[c], t1.0[c])).max().unwrap_or(1);
        let pad = if n == 1 {
            one
        } else {
            simulate_pad(&slab, n, Backing::Black, DVec3::Z, trap, &pc)
        };
        let w15 = instrument::polar_dir(15.0, false);
        let b15 = simulate_pad(&slab, 1, Backing::Black, w15, None, &pc);
        let w89 = simulate_pad(&slab, 1, Backing::Lambertian(instrument::TAPPI_BACKING), w15, None, &pc);
        let r = Reflectances {
            r0: one.reflected_trapped.mean.0,
            r_inf: pad.reflected_trapped.mean.0,
            r0_15: b15.reflected.mean.0,
            r089_15: w89.reflected.mean.0,
            t0: one.transmitted.mean.0,
        };
        m.set_reflectances(r, grammage, sel);
    }
    for g in &GEOMETRIES {
        if !sel.has(g.key) {
            continue;
        }
        let v = truth_gloss(&slab, p, g, cfg)?;
        m.set_gloss(g.key, v);
    }
    if sel.has("scatter_distance_mm") {
        let lc = LateralConfig {
            samples: cfg.lateral_samples,
            seed: cfg.seed,
            progress: cfg.progress,
            ..LateralConfig::default()
        };
        let prof = simulate_exit_profile(&slab, DVec3::Z, &lc)?;
        m.scatter_distance_mm = edge::truth_edge(&prof).map(|e| ScatterDistance::of(&e));
    }
    Ok(m)
}

/// Gloss of the simulated sheet: `f` at the nominal source direction over a
/// 5 x 5 Gauss-Legendre grid of the receptor window (the source aperture is
/// not integrated: at the simulator's noise level it changes nothing).
fn truth_gloss(slab: &Slab, p: &PaperParams, g: &gloss::GlossGeometry, cfg: &TruthConfig) -> Result<f64, SimError> {
    let theta = g.angle_deg.to_radians();
    let wi = DVec3::new(theta.sin(), 0.0, theta.cos());
    let (x, w) = paperbsdf_core::quadrature::gauss_legendre_01(5);
    let mut pts = Vec::new();
    match g.receptor {
        gloss::Window::Rect(ia, ib) => {
            let (ha, hb) = (ia.to_radians(), ib.to_radians());
            for i in 0..5 {
                for j in 0..5 {
                    let (a, b) = ((x[i] - 0.5) * ha, (x[j] - 0.5) * hb);
                    pts.push((a, b, w[i] * w[j] * ha * hb * b.cos()));
                }
            }
        }
        gloss::Window::Round(d) => {
            let r = d.to_radians() / 2.0;
            for i in 0..5 {
                for j in 0..8 {
                    let phi = 2.0 * std::f64::consts::PI * (j as f64 + 0.5) / 8.0;
                    let rho = r * x[i];
                    let (a, b) = (rho * phi.cos(), rho * phi.sin());
                    pts.push((a, b, w[i] * r * rho * std::f64::consts::PI / 4.0 * b.cos()));
                }
            }
        }
    }
    let wos: Vec<DVec3> = pts
        .iter()
        .map(|&(a, b, _)| {
            let (sa, ca) = (theta + a).sin_cos();
            let (sb, cb) = b.sin_cos();
            DVec3::new(-cb * sa, sb, cb * ca)
        })
        .collect();
    let sc = SimConfig {
        samples: cfg.gloss_samples,
        seed: cfg.seed,
        progress: cfg.progress,
        ..SimConfig::default()
    };
    let run = simulate_bsdf(slab, wi, &wos, &sc)?;
    let mut flux = Rgb::ZERO;
    for ((_, _, wt), (e, wo)) in pts.iter().zip(run.f.iter().zip(&wos)) {
        flux += e.mean * (wt * wo.z);
    }
    if p.m_f < 1e-4 {
        flux += Rgb::splat(paperbsdf_core::fresnel::fresnel_dielectric(theta.cos(), p.eta_f));
    }
    let glass = paperbsdf_core::fresnel::fresnel_dielectric(theta.cos(), g.glass_index);
    Ok(100.0 * luminance(flux) / glass)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn selection_errors_name_the_known_metrics() {
        let known = METRIC_NAMES.join(", ");
        let e = Selection::parse("r457, opacity").unwrap_err();
        assert_eq!(e, MeasureError::UnknownMetric("opacity".into()));
        assert_eq!(
            e.to_string(),
            format!("unknown metric `opacity`; known metrics: {known}")
        );
        let e = Selection::parse(" , ").unwrap_err();
        assert_eq!(e.to_string(), format!("no metric named; known metrics: {known}"));
        assert_eq!(Selection::parse("r457,gloss_75_tappi_t480").unwrap().0.len(), 2);
    }
}
