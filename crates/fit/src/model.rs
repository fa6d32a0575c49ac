//! What the fitter needs of a model: named parameters with search bounds, a
//! way to build an evaluable BSDF from a parameter vector, the parameter file
//! that vector corresponds to, and the model's components for the plots.
//!
//! The search works in the unit cube: each parameter has a [`Scale`] that maps
//! `u` in [0, 1] to its value (linear, or logarithmic for quantities that span
//! decades: `sigma_a`, `sigma_s`, roughness). The bounds are those of the
//! supplement's Table 2 made finite where Table 2 says infinity (see each
//! model's documentation for the numbers).

use paperbsdf_core::{DVec3, Rgb};

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

/// A model built from one parameter vector: its BSDF and its components.
pub trait Evaluable: Send + Sync {
    /// `f(wi, wo)` without cosine (the sum of the components).
    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb;
    /// Names of the components, in plotting order (e.g. `surface`, `single`,
    /// `multiple`, `direct`; `lambert`, `rough glass`).
    fn component_names(&self) -> Vec<&'static str>;
    /// `f` of component `index` of [`Evaluable::component_names`].
    fn eval_component(&self, index: usize, wi: DVec3, wo: DVec3) -> Rgb;
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
    fn build(&self, x: &[f64]) -> Result<Box<dyn Evaluable>, String>;
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
    pub fn new(inner: Box<dyn FitModel>, free: &[&str], base: Vec<f64>) -> Result<Subset, String> {
        let mut idx = Vec::new();
        for f in free {
            let i = inner
                .specs()
                .iter()
                .position(|s| s.name == *f)
                .ok_or_else(|| format!("model `{}` has no parameter `{f}`", inner.model_name()))?;
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
    fn build(&self, x: &[f64]) -> Result<Box<dyn Evaluable>, String> {
        self.inner.build(&self.full(x))
    }
    fn params_json(&self, x: &[f64]) -> serde_json::Value {
        self.inner.params_json(&self.full(x))
    }
}
