//! What the fitter needs of a model: named parameters with search bounds, a
//! way to build the model from a parameter vector (as core's
//! [`ComponentModel`], which also gives the components for the plots) and the
//! parameter file that vector corresponds to.
//!
//! The search works in the unit cube: each parameter has a [`Scale`] that maps
//! `u` in [0, 1] to its value (linear, or logarithmic for quantities that span
//! decades: `sigma_a`, `sigma_s`, roughness). The bounds are those of the
//! supplement's Table 2 made finite where Table 2 says infinity (see each
//! model's documentation for the numbers).

use crate::error::FitError;
pub use paperbsdf_core::models::ComponentModel;

/// How a parameter's value depends on its unit-cube coordinate `u`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Scale {
    /// `lo + u (hi - lo)`.
    Linear,
    /// `lo (hi / lo)^u` (both bounds positive).
    Log,
}

/// One fitted parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamSpec {
    /// Name as in parameter files (RGB channels: `sigma_s[0]` ...).
    pub name: String,
    /// Lower search bound.
    pub lo: f64,
    /// Upper search bound.
    pub hi: f64,
    /// Mapping from the unit cube.
    pub scale: Scale,
    /// The default starting value.
    pub default: f64,
}

impl ParamSpec {
    /// A parameter spec.
    pub fn new(name: impl Into<String>, lo: f64, hi: f64, scale: Scale, default: f64) -> Self {
        ParamSpec {
            name: name.into(),
            lo,
            hi,
            scale,
            default,
        }
    }
    /// The value at unit coordinate `u` (clamped to [0, 1]: the search box).
    pub fn value(&self, u: f64) -> f64 {
        let u = u.clamp(0.0, 1.0);
        match self.scale {
            Scale::Linear => self.lo + u * (self.hi - self.lo),
            Scale::Log => self.lo * (self.hi / self.lo).powf(u),
        }
    }
    /// The unit coordinate of `value` (the inverse of [`ParamSpec::value`], clamped to the box).
    pub fn unit(&self, value: f64) -> f64 {
        let u = match self.scale {
            Scale::Linear => (value - self.lo) / (self.hi - self.lo),
            Scale::Log => (value / self.lo).ln() / (self.hi / self.lo).ln(),
        };
        u.clamp(0.0, 1.0)
    }
}

/// A model family the fitter can search: one instance per discrete choice
/// (e.g. the microfacet distribution of each face).
pub trait FitModel: Send + Sync {
    /// The model's name as given on the command line (`paper`, `lambert-glass`, ...).
    fn model_name(&self) -> &str;
    /// A label of this discrete variant (e.g. `dist_f=ggx, dist_b=beckmann`).
    fn variant(&self) -> String;
    /// The fitted parameters.
    fn specs(&self) -> &[ParamSpec];
    /// Builds the model from parameter values (not unit coordinates).
    fn build(&self, x: &[f64]) -> Result<Box<dyn ComponentModel>, FitError>;
    /// The parameter file of these values (JSON object with the model's keys).
    fn params_json(&self, x: &[f64]) -> serde_json::Value;
    /// The values at unit coordinates `u`.
    fn values(&self, u: &[f64]) -> Vec<f64> {
        self.specs().iter().zip(u).map(|(s, &u)| s.value(u)).collect()
    }
    /// Unit coordinates of the default starting point.
    fn default_unit(&self) -> Vec<f64> {
        self.specs().iter().map(|s| s.unit(s.default)).collect()
    }
}

/// A model with some parameters held at given values: only the parameters
/// listed in `free` are searched (for tests and for fits with known values).
pub struct Subset {
    inner: Box<dyn FitModel>,
    free: Vec<usize>,
    base: Vec<f64>,
    specs: Vec<ParamSpec>,
}

impl Subset {
    /// `inner` with every parameter not named in `free` held at its value in `base`.
    /// Unknown names are an error.
    pub fn new(inner: Box<dyn FitModel>, free: &[&str], base: Vec<f64>) -> Result<Subset, FitError> {
        let mut idx = Vec::new();
        for f in free {
            let i = inner
                .specs()
                .iter()
                .position(|s| s.name == *f)
                .ok_or_else(|| FitError::UnknownParameter {
                    model: inner.model_name().to_string(),
                    name: f.to_string(),
                })?;
            idx.push(i);
        }
        let specs = idx.iter().map(|&i| inner.specs()[i].clone()).collect();
        Ok(Subset {
            inner,
            free: idx,
            base,
            specs,
        })
    }
    fn full(&self, x: &[f64]) -> Vec<f64> {
        let mut v = self.base.clone();
        for (k, &i) in self.free.iter().enumerate() {
            v[i] = x[k];
        }
        v
    }
}

impl FitModel for Subset {
    fn model_name(&self) -> &str {
        self.inner.model_name()
    }
    fn variant(&self) -> String {
        self.inner.variant()
    }
    fn specs(&self) -> &[ParamSpec] {
        &self.specs
    }
    fn build(&self, x: &[f64]) -> Result<Box<dyn ComponentModel>, FitError> {
        self.inner.build(&self.full(x))
    }
    fn params_json(&self, x: &[f64]) -> serde_json::Value {
        self.inner.params_json(&self.full(x))
    }
}

/// Parses `NAME=VALUE` (the `--fix` option).
pub fn parse_fix(s: &str) -> Result<(String, f64), FitError> {
    let (n, v) = s.split_once('=').ok_or_else(|| FitError::FixSyntax(s.to_string()))?;
    let v: f64 = v.trim().parse().map_err(|_| FitError::FixNotNumber {
        arg: s.to_string(),
        value: v.trim().to_string(),
    })?;
    if !v.is_finite() {
        return Err(FitError::FixNotFinite(s.to_string()));
    }
    Ok((n.trim().to_string(), v))
}

/// Holds the parameters named in `fixes` at their values in every candidate;
/// the rest are searched. A name matches a parameter exactly or, for colour
/// parameters, all three channels (`sigma_a` fixes `sigma_a[0]`..`sigma_a[2]`).
/// Errors name an unknown parameter (listing the known ones), a value the model
/// refuses (with the model's reason), or a fit with nothing left free.
pub fn fix_params(cands: Vec<Box<dyn FitModel>>, fixes: &[(String, f64)]) -> Result<Vec<Box<dyn FitModel>>, FitError> {
    if fixes.is_empty() {
        return Ok(cands);
    }
    let mut out: Vec<Box<dyn FitModel>> = Vec::new();
    for c in cands {
        let specs = c.specs().to_vec();
        let mut base: Vec<f64> = specs.iter().map(|s| s.default).collect();
        let mut fixed = vec![false; specs.len()];
        for (name, v) in fixes {
            let mut hit = false;
            for (k, s) in specs.iter().enumerate() {
                if s.name == *name || s.name.strip_prefix(name.as_str()).is_some_and(|r| r.starts_with('[')) {
                    base[k] = *v;
                    fixed[k] = true;
                    hit = true;
                }
            }
            if !hit {
                let mut names: Vec<String> = specs
                    .iter()
                    .map(|s| s.name.split('[').next().unwrap_or("").to_string())
                    .collect();
                names.dedup();
                return Err(FitError::FixUnknown {
                    name: name.clone(),
                    value: *v,
                    model: c.model_name().to_string(),
                    known: names.join(", "),
                });
            }
        }
        if let Err(e) = c.build(&base) {
            return Err(FitError::FixRefused(Box::new(e)));
        }
        let free: Vec<String> = specs
            .iter()
            .zip(&fixed)
            .filter(|(_, f)| !**f)
            .map(|(s, _)| s.name.clone())
            .collect();
        if free.is_empty() {
            return Err(FitError::FixAll);
        }
        let free_refs: Vec<&str> = free.iter().map(|s| s.as_str()).collect();
        out.push(Box::new(Subset::new(c, &free_refs, base)?));
    }
    Ok(out)
}
