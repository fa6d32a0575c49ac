//! # paperbsdf-python: the native part of the `paperbsdf` Python package
//!
//! PyO3 bindings of the project's crates, with numpy arrays: the models by
//! name (`paperbsdf-io`'s registry, so errors carry the CLI's messages),
//! vectorised `eval`, `pdf`, `sample` and `albedo` in the conventions of
//! docs/design.md section 2 (`f` without cosine, `wi` toward the light, `wo` toward
//! the viewer, local frame with `+z` the front face's normal), the fitter
//! (`paperbsdf-fit`) and the ground-truth simulator (`paperbsdf-sim`).
//!
//! The Python package (`python/paperbsdf`) wraps this module: it turns dicts
//! into parameter text and any array-like into contiguous float64 arrays; this
//! module checks shapes, ranges and unit lengths and raises `ValueError`
//! naming the argument and row. Long work runs without the GIL (`Python::detach`)
//! and on all cores (rayon).

use numpy::ndarray::{Array1, Array2, ArrayView2};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use paperbsdf_core::models::ModelKind;
use paperbsdf_core::paper::Component;
use paperbsdf_core::{BsdfFlags, DVec3, PaperParams, Rgb};
use paperbsdf_io::models::{load_model, load_model_text_with, LoadedModel, SlabSettings};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;

/// Allowed deviation of a direction's length from 1: the CLI's (`paperbsdf_io::dirs`).
const UNIT_TOLERANCE: f64 = paperbsdf_io::dirs::UNIT_TOLERANCE;

/// Rows per rayon task; below this many rows the work stays on one thread.
const CHUNK: usize = 2048;

fn value_error(msg: impl Into<String>) -> PyErr {
    PyValueError::new_err(msg.into())
}

/// Checks that `a` has shape (N, 3) and returns N.
fn check_n3(name: &str, a: &PyReadonlyArray2<'_, f64>) -> PyResult<usize> {
    let s = a.shape();
    if s[1] != 3 {
        return Err(value_error(format!(
            "{name}: expected an array of shape (N, 3), got shape ({}, {})",
            s[0], s[1]
        )));
    }
    Ok(s[0])
}

/// Reads (N, 3) unit directions; each must be finite and of unit length to
/// [`UNIT_TOLERANCE`] (as `paperbsdf eval --dirs`), and is normalised.
fn directions(name: &str, a: &PyReadonlyArray2<'_, f64>) -> PyResult<Vec<DVec3>> {
    check_n3(name, a)?;
    let v = a.as_array();
    let mut out = Vec::with_capacity(v.nrows());
    for (i, r) in v.rows().into_iter().enumerate() {
        let w = DVec3::new(r[0], r[1], r[2]);
        if !w.is_finite() {
            return Err(value_error(format!(
                "{name}[{i}] = ({}, {}, {}) is not finite",
                r[0], r[1], r[2]
            )));
        }
        let l = w.length();
        if (l - 1.0).abs() > UNIT_TOLERANCE {
            return Err(value_error(format!(
                "{name}[{i}] = ({}, {}, {}) has length {l}, expected a unit vector (tolerance {UNIT_TOLERANCE})",
                r[0], r[1], r[2]
            )));
        }
        out.push(w / l);
    }
    Ok(out)
}

fn same_len(a: (&str, usize), b: (&str, usize)) -> PyResult<()> {
    if a.1 != b.1 {
        return Err(value_error(format!(
            "{} has {} rows but {} has {}: they must have the same number of rows",
            a.0, a.1, b.0, b.1
        )));
    }
    Ok(())
}

/// Rows of an (N, 3) array of random numbers in [0, 1).
fn unit_randoms(name: &str, a: &PyReadonlyArray2<'_, f64>) -> PyResult<Vec<[f64; 3]>> {
    check_n3(name, a)?;
    let v: ArrayView2<f64> = a.as_array();
    let mut out = Vec::with_capacity(v.nrows());
    for (i, r) in v.rows().into_iter().enumerate() {
        for k in 0..3 {
            if !(r[k] >= 0.0 && r[k] < 1.0) {
                return Err(value_error(format!(
                    "{name}[{i}, {k}] = {} is outside the allowed range [0, 1)",
                    r[k]
                )));
            }
        }
        out.push([r[0], r[1], r[2]]);
    }
    Ok(out)
}

fn rgb_array(v: Vec<Rgb>) -> Array2<f64> {
    let n = v.len();
    let flat: Vec<f64> = v.into_iter().flat_map(|c| c.0).collect();
    Array2::from_shape_vec((n, 3), flat).expect("n x 3 values")
}

fn vec_array(v: Vec<DVec3>) -> Array2<f64> {
    let n = v.len();
    let flat: Vec<f64> = v.into_iter().flat_map(|w| [w.x, w.y, w.z]).collect();
    Array2::from_shape_vec((n, 3), flat).expect("n x 3 values")
}

/// Maps `f` over `0..n`, in parallel for large `n`.
fn par_map<T: Send>(n: usize, f: impl Fn(usize) -> T + Sync + Send) -> Vec<T> {
    if n <= CHUNK {
        (0..n).map(f).collect()
    } else {
        (0..n).into_par_iter().with_min_len(CHUNK / 4).map(f).collect()
    }
}

/// An (N, 3) array and an (N,) array returned to Python.
type Arrays21<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<f64>>);
/// Two (N, 3) arrays returned to Python.
type Arrays22<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>);

/// A model loaded by name from the registry of `paperbsdf-io` (`paper`,
/// `reduced-multilayer`, `lambert-glass`, `rough-dielectric`).
#[pyclass(module = "paperbsdf._native", frozen)]
struct Model {
    model: LoadedModel,
    name: String,
}

/// One evaluated component: `None` for all, else one of [`Component`].
fn parse_component(component: &str) -> PyResult<Option<Component>> {
    if component == "all" {
        return Ok(None);
    }
    Component::parse(component).map(Some).ok_or_else(|| {
        value_error(format!(
            "component `{component}`: expected surface, single, multiple, direct or all"
        ))
    })
}

#[pymethods]
impl Model {
    /// `Model(name, text, origin, is_toml, slab_nodes=None)`: the model
    /// `name` from the text of a parameter set (JSON, or TOML when
    /// `is_toml`); `origin` names it in errors. `slab_nodes`: nodes per
    /// hemisphere of the model `slab` (`paperbsdf eval --slab-nodes`;
    /// `None` for the default 32, an error for other models).
    #[new]
    #[pyo3(signature = (name, text, origin, is_toml, slab_nodes = None))]
    fn new(
        py: Python<'_>,
        name: &str,
        text: &str,
        origin: &str,
        is_toml: bool,
        slab_nodes: Option<usize>,
    ) -> PyResult<Self> {
        let settings = SlabSettings { nodes: slab_nodes };
        let model = py
            .detach(|| load_model_text_with(name, text, origin, is_toml, &settings, "slab_nodes"))
            .map_err(|e| value_error(e.to_string()))?;
        Ok(Model {
            model,
            name: name.to_string(),
        })
    }

    /// `Model.from_source(name, source)`: parameters from a file path (JSON or
    /// TOML) or inline JSON, exactly as `paperbsdf eval --params SOURCE`.
    #[staticmethod]
    fn from_source(py: Python<'_>, name: &str, source: &str) -> PyResult<Self> {
        let model = py
            .detach(|| load_model(name, source))
            .map_err(|e| value_error(e.to_string()))?;
        Ok(Model {
            model,
            name: name.to_string(),
        })
    }

    /// The model's name.
    #[getter]
    fn name(&self) -> &str {
        &self.name
    }

    /// Whether the parameters are RGB (three distinct channels).
    #[getter]
    fn is_rgb(&self) -> bool {
        self.model.is_rgb()
    }

    /// The lobes of the model, as the bits of `paperbsdf_core::BsdfFlags`
    /// (1 reflection, 2 transmission, 4 diffuse, 8 glossy, 16 specular).
    #[getter]
    fn flags(&self) -> u8 {
        self.model.model().flags().0
    }

    /// `f(wi, wo)` without cosine, (N, 3) RGB, for (N, 3) unit directions.
    #[pyo3(signature = (wi, wo, component = "all"))]
    fn eval<'py>(
        &self,
        py: Python<'py>,
        wi: PyReadonlyArray2<'py, f64>,
        wo: PyReadonlyArray2<'py, f64>,
        component: &str,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let c = parse_component(component)?;
        let wi = directions("wi", &wi)?;
        let wo = directions("wo", &wo)?;
        same_len(("wi", wi.len()), ("wo", wo.len()))?;
        let m = self.model.model();
        let out = py.detach(|| {
            par_map(wi.len(), |k| match c {
                None => m.eval(wi[k], wo[k]),
                Some(c) => m.eval_component(wi[k], wo[k], c),
            })
        });
        Ok(rgb_array(out).into_pyarray(py))
    }

    /// Solid-angle density with which `sample(wo, ..)` draws `wi`, (N,).
    fn pdf<'py>(
        &self,
        py: Python<'py>,
        wi: PyReadonlyArray2<'py, f64>,
        wo: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let wi = directions("wi", &wi)?;
        let wo = directions("wo", &wo)?;
        same_len(("wi", wi.len()), ("wo", wo.len()))?;
        let m = self.model.model();
        let out = py.detach(|| par_map(wi.len(), |k| m.pdf(wi[k], wo[k])));
        Ok(Array1::from(out).into_pyarray(py))
    }

    /// `f(wi, wo)` (N, 3) and `pdf(wi, wo)` (N,) in one pass.
    fn eval_pdf<'py>(
        &self,
        py: Python<'py>,
        wi: PyReadonlyArray2<'py, f64>,
        wo: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Arrays21<'py>> {
        let wi = directions("wi", &wi)?;
        let wo = directions("wo", &wo)?;
        same_len(("wi", wi.len()), ("wo", wo.len()))?;
        let m = self.model.model();
        let out = py.detach(|| par_map(wi.len(), |k| (m.eval(wi[k], wo[k]), m.pdf(wi[k], wo[k]))));
        let (f, p): (Vec<Rgb>, Vec<f64>) = out.into_iter().unzip();
        Ok((rgb_array(f).into_pyarray(py), Array1::from(p).into_pyarray(py)))
    }

    /// Draws `wi` for each row of `wo` from `u` ((N, 3) in [0, 1): lobe choice,
    /// then the two numbers of the direction). Returns `(wi, f, pdf, flags,
    /// weight)`: (N, 3), (N, 3), (N,), (N,) uint8, (N, 3). A failed draw has
    /// `wi = 0`, `f = 0`, `pdf = 0`, `flags = 0`, `weight = 0`. For a delta
    /// lobe (flag 16) `pdf` is the lobe's discrete probability and `f` its
    /// weight over `|cos wi|`.
    #[allow(clippy::type_complexity)]
    fn sample<'py>(
        &self,
        py: Python<'py>,
        wo: PyReadonlyArray2<'py, f64>,
        u: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<(
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<u8>>,
        Bound<'py, PyArray2<f64>>,
    )> {
        let wo = directions("wo", &wo)?;
        let u = unit_randoms("u", &u)?;
        same_len(("wo", wo.len()), ("u", u.len()))?;
        let m = self.model.model();
        let out = py.detach(|| {
            par_map(wo.len(), |k| {
                let [uc, u1, u2] = u[k];
                match m.sample(wo[k], uc, [u1, u2]) {
                    Some(s) if s.pdf > 0.0 && s.f.is_finite() => (s.wi, s.f, s.pdf, s.flags.0, s.weight()),
                    _ => (DVec3::ZERO, Rgb::ZERO, 0.0, 0, Rgb::ZERO),
                }
            })
        });
        let n = out.len();
        let (mut wi, mut f, mut pdf, mut flags, mut weight) = (
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
        );
        for (a, b, c, d, e) in out {
            wi.push(a);
            f.push(b);
            pdf.push(c);
            flags.push(d);
            weight.push(e);
        }
        Ok((
            vec_array(wi).into_pyarray(py),
            rgb_array(f).into_pyarray(py),
            Array1::from(pdf).into_pyarray(py),
            Array1::from(flags).into_pyarray(py),
            rgb_array(weight).into_pyarray(py),
        ))
    }

    /// One direction pair without numpy, for the Mitsuba plugin's scalar
    /// variants (one call per direction): `((r, g, b), pdf)` of `f(wi, wo)`
    /// and `pdf(wi, wo)`. Directions that are not finite or not of unit
    /// length (to 1e-3: Mitsuba's single precision) give zeros; the others
    /// are normalised.
    fn eval_pdf_one(&self, wi: (f64, f64, f64), wo: (f64, f64, f64)) -> ((f64, f64, f64), f64) {
        let (Some(wi), Some(wo)) = (plugin_dir(wi), plugin_dir(wo)) else {
            return ((0.0, 0.0, 0.0), 0.0);
        };
        let m = self.model.model();
        let f = m.eval(wi, wo);
        (rgb_tuple(f), m.pdf(wi, wo))
    }

    /// One draw without numpy (see [`Model::eval_pdf_one`]): for viewer `wo`
    /// and numbers `u` in [0, 1), `(wi, pdf, flags, weight)` as in
    /// [`Model::sample`]; a failed draw or an invalid input gives zeros.
    #[allow(clippy::type_complexity)]
    fn sample_one(&self, wo: (f64, f64, f64), u: (f64, f64, f64)) -> ((f64, f64, f64), f64, u8, (f64, f64, f64)) {
        const NONE: ((f64, f64, f64), f64, u8, (f64, f64, f64)) = ((0.0, 0.0, 0.0), 0.0, 0, (0.0, 0.0, 0.0));
        let Some(wo) = plugin_dir(wo) else { return NONE };
        let (uc, u1, u2) = u;
        if ![uc, u1, u2].iter().all(|x| (0.0..1.0).contains(x)) {
            return NONE;
        }
        match self.model.model().sample(wo, uc, [u1, u2]) {
            Some(s) if s.pdf > 0.0 && s.f.is_finite() => (s.wi.into(), s.pdf, s.flags.0, rgb_tuple(s.weight())),
            _ => NONE,
        }
    }

    /// The Paper BSDF's construction-time state (its faces' node tables, the
    /// multiple-scattering tables, the phase function, the lobe-selection
    /// table, the direct kernel) as the text of its `Debug` representation,
    /// for `paper` and `reduced-multilayer`; `None` for the other models.
    ///
    /// `paperbsdf.mitsuba_native` reads the tables from it to evaluate the
    /// model in Dr.Jit. `paperbsdf_core::PaperBsdf` keeps these fields
    /// private, and `Debug` is its one complete view of them from this crate;
    /// Rust's `Debug` prints every `f64` in its shortest round-trip form, so
    /// the values are exact. (A layout change in core makes the reader raise,
    /// and the Python tests compare the Dr.Jit evaluation with this model's.)
    #[getter]
    fn paper_state(&self) -> Option<String> {
        match &self.model {
            LoadedModel::Paper(m) => Some(format!("{m:?}")),
            _ => None,
        }
    }

    /// Directional albedo for light at polar angles `theta_i_deg` (degrees, in
    /// [0, 90]) in the x-z plane arriving at the `side` face (`front`: from
    /// z > 0, `back`: from z < 0); the routine of `paperbsdf albedo`. Returns
    /// `(reflectance, transmittance)`, each (N, 3).
    #[pyo3(signature = (theta_i_deg, side = "front"))]
    fn albedo<'py>(
        &self,
        py: Python<'py>,
        theta_i_deg: PyReadonlyArray1<'py, f64>,
        side: &str,
    ) -> PyResult<Arrays22<'py>> {
        let sign = match side {
            "front" => 1.0,
            "back" => -1.0,
            s => {
                return Err(value_error(format!(
                    "side `{s}`: expected `front` (light from z > 0) or `back` (light from z < 0)"
                )))
            }
        };
        let th: Vec<f64> = theta_i_deg.as_array().to_vec();
        for (i, t) in th.iter().enumerate() {
            if !(t.is_finite() && (0.0..=90.0).contains(t)) {
                return Err(value_error(format!(
                    "theta_i_deg[{i}] = {t} is outside the allowed range [0, 90] degrees"
                )));
            }
        }
        let model = &self.model;
        let out: Vec<(Rgb, Rgb)> = py.detach(|| {
            th.par_iter()
                .map(|t| {
                    let r = t.to_radians();
                    model.albedo(DVec3::new(r.sin(), 0.0, sign * r.cos()))
                })
                .collect()
        });
        let (r, t): (Vec<Rgb>, Vec<Rgb>) = out.into_iter().unzip();
        Ok((rgb_array(r).into_pyarray(py), rgb_array(t).into_pyarray(py)))
    }
}

/// A Mitsuba direction for the one-direction calls: normalised if finite
/// and of unit length to 1e-3 (single precision), else `None`.
fn plugin_dir((x, y, z): (f64, f64, f64)) -> Option<DVec3> {
    let w = DVec3::new(x, y, z);
    let l = w.length();
    (w.is_finite() && (l - 1.0).abs() < 1e-3).then(|| w / l)
}

fn rgb_tuple(c: Rgb) -> (f64, f64, f64) {
    (c.0[0], c.0[1], c.0[2])
}

/// The names of the models built from parameters, from the one registry
/// (`paperbsdf_core::models::ModelKind`, in its order; `measured` files are
/// not a parameter model of this package).
#[pyfunction]
fn model_names() -> Vec<&'static str> {
    ModelKind::ALL
        .into_iter()
        .filter(|&k| k != ModelKind::Measured)
        .map(ModelKind::name)
        .collect()
}

/// The names of the slab models, whose parameters are the Paper BSDF's (and
/// the presets are such parameters): `ModelKind::is_slab`.
#[pyfunction]
fn slab_model_names() -> Vec<&'static str> {
    ModelKind::ALL
        .into_iter()
        .filter(|k| k.is_slab())
        .map(ModelKind::name)
        .collect()
}

/// The names of the presets of `paperbsdf_core::presets`.
#[pyfunction]
fn preset_names() -> Vec<&'static str> {
    paperbsdf_core::presets::PRESET_NAMES.to_vec()
}

/// The JSON text of preset `name` (also accepted: the aliases of
/// `paperbsdf_core::presets::preset`); an unknown name is a `ValueError`.
#[pyfunction]
fn preset_json(name: &str) -> PyResult<String> {
    match paperbsdf_core::presets::preset(name) {
        Some(p) => serde_json::to_string_pretty(&p).map_err(|e| value_error(e.to_string())),
        None => Err(value_error(format!(
            "preset `{name}` is unknown; known presets: {}",
            paperbsdf_core::presets::PRESET_NAMES.join(", ")
        ))),
    }
}

/// The JSON text of validated parameters of model `name` read from `source`
/// (a file path or inline JSON), as `paperbsdf eval --params SOURCE` reads them.
#[pyfunction]
fn params_json(name: &str, source: &str) -> PyResult<String> {
    // Building the model validates every range and names the file and line.
    load_model(name, source).map_err(|e| value_error(e.to_string()))?;
    let (text, origin, is_toml) = paperbsdf_io::params::read_source(source).map_err(|e| value_error(e.to_string()))?;
    let v: serde_json::Value =
        paperbsdf_io::params::parse_text(&text, &origin, is_toml).map_err(|e| value_error(e.to_string()))?;
    serde_json::to_string_pretty(&v).map_err(|e| value_error(e.to_string()))
}

/// Monte Carlo ground truth (`paperbsdf simulate`): the physical slab of
/// paper parameters `text` (JSON) lit from `wi`, seen from each row of `wo`.
/// Returns a dict with `f`, `stderr` ((M, 3), without cosine), `reflectance`,
/// `reflectance_stderr`, `transmittance`, `transmittance_stderr` ((3,)) and
/// `samples` (walks per channel).
#[pyfunction]
#[pyo3(signature = (text, origin, wi, wo, samples, batches, seed, rel_stderr, max_samples))]
#[allow(clippy::too_many_arguments)]
fn simulate<'py>(
    py: Python<'py>,
    text: &str,
    origin: &str,
    wi: PyReadonlyArray2<'py, f64>,
    wo: PyReadonlyArray2<'py, f64>,
    samples: u64,
    batches: u32,
    seed: u64,
    rel_stderr: Option<f64>,
    max_samples: u64,
) -> PyResult<Bound<'py, PyDict>> {
    let loaded =
        paperbsdf_io::params::parse_text::<PaperParams>(text, origin, false).map_err(|e| value_error(e.to_string()))?;
    let l = paperbsdf_io::Loaded {
        value: loaded,
        origin: origin.to_string(),
        text: text.to_string(),
        is_toml: false,
    };
    l.value
        .validate()
        .map_err(|e| value_error(l.param_error(e).to_string()))?;
    let wi = directions("wi", &wi)?;
    if wi.len() != 1 {
        return Err(value_error(format!(
            "wi: expected one direction, shape (3,) or (1, 3), got {} rows",
            wi.len()
        )));
    }
    let wo = directions("wo", &wo)?;
    if samples == 0 {
        return Err(value_error("samples = 0: need at least one walk"));
    }
    if batches < 2 {
        return Err(value_error(format!(
            "batches = {batches}: need at least 2 batches for a standard error"
        )));
    }
    if let Some(x) = rel_stderr {
        if !(x > 0.0 && x < 1.0) {
            return Err(value_error(format!(
                "rel_stderr = {x} is outside the allowed range (0, 1)"
            )));
        }
    }
    let slab = paperbsdf_sim::Slab::from_params(&l.value).map_err(|e| value_error(l.param_error(e).to_string()))?;
    let cfg = paperbsdf_sim::SimConfig {
        samples: samples.max(batches as u64),
        batches,
        seed,
        rel_stderr,
        max_samples,
        progress: false,
        by_order: false,
        max_collisions_per_walk: paperbsdf_sim::walk::MAX_COLLISIONS_PER_WALK as u64,
    };
    let run = py
        .detach(|| paperbsdf_sim::simulate_bsdf(&slab, wi[0], &wo, &cfg))
        .map_err(|e| value_error(e.to_string()))?;
    let d = PyDict::new(py);
    let means: Vec<Rgb> = run.f.iter().map(|e| e.mean).collect();
    let errs: Vec<Rgb> = run.f.iter().map(|e| e.stderr).collect();
    d.set_item("f", rgb_array(means).into_pyarray(py))?;
    d.set_item("stderr", rgb_array(errs).into_pyarray(py))?;
    let arr3 = |c: Rgb| Array1::from(c.0.to_vec()).into_pyarray(py);
    d.set_item("reflectance", arr3(run.reflectance.mean))?;
    d.set_item("reflectance_stderr", arr3(run.reflectance.stderr))?;
    d.set_item("transmittance", arr3(run.transmittance.mean))?;
    d.set_item("transmittance_stderr", arr3(run.transmittance.stderr))?;
    d.set_item("samples", run.samples)?;
    Ok(d)
}

/// Fits model `model` to the measurement files `data` (`paperbsdf fit`);
/// returns the JSON text of the fit (the CLI's `--out` file). `fix` holds
/// parameters (`--fix NAME=VALUE`), `face_scattering` is `multiple` or
/// `single`, `refine` = `slab` refines the fit with the model `slab`
/// (`--refine slab`, at most `refine_max_iter` iterations, each solve with
/// `slab_nodes` nodes per hemisphere: `--slab-nodes`).
#[pyfunction]
#[pyo3(signature = (data, model, thickness, fit_theta_i, dists, samples, starts, max_iter, seed,
                    fix = Vec::new(), face_scattering = "multiple", refine = None, refine_max_iter = 40,
                    slab_nodes = None))]
#[allow(clippy::too_many_arguments)]
fn fit(
    py: Python<'_>,
    data: Vec<String>,
    model: &str,
    thickness: Option<f64>,
    fit_theta_i: Option<Vec<f64>>,
    dists: Vec<String>,
    samples: usize,
    starts: usize,
    max_iter: usize,
    seed: u64,
    fix: Vec<(String, f64)>,
    face_scattering: &str,
    refine: Option<String>,
    refine_max_iter: usize,
    slab_nodes: Option<usize>,
) -> PyResult<String> {
    if samples == 0 || starts == 0 || max_iter == 0 || refine_max_iter == 0 {
        return Err(value_error(
            "samples, starts, max_iter and refine_max_iter must be at least 1",
        ));
    }
    let faces: paperbsdf_core::FaceScattering = face_scattering
        .parse()
        .map_err(|e: paperbsdf_core::ParamError| value_error(e.to_string()))?;
    match refine.as_deref() {
        None | Some("slab") => {}
        Some(other) => {
            return Err(value_error(format!(
                "refine: `{other}` is not a model that refines a fit (expected \"slab\" or None)"
            )))
        }
    }
    if refine.is_some() {
        paperbsdf_fit::models::refinable(model).map_err(|e| value_error(e.to_string()))?;
    } else if slab_nodes.is_some() {
        return Err(value_error(
            "slab_nodes: sets the discretisation of the refinement with slab; give it with refine=\"slab\"",
        ));
    }
    let slab_options = SlabSettings { nodes: slab_nodes }
        .options("slab_nodes")
        .map_err(|e| value_error(e.to_string()))?;
    for (name, v) in &fix {
        if !v.is_finite() {
            return Err(value_error(format!("fix: {name} = {v}: the value must be finite")));
        }
    }
    let dists = dists
        .iter()
        .map(|s| {
            paperbsdf_core::Distribution::parse(s)
                .ok_or_else(|| value_error(format!("dists: unknown distribution `{s}` (expected ggx or beckmann)")))
        })
        .collect::<PyResult<Vec<_>>>()?;
    let model = model.to_string();
    // PyErr is created lazily (no GIL needed) and is Send: built here, raised after.
    let fit_error = |e: paperbsdf_fit::FitError| value_error(e.to_string());
    py.detach(move || -> PyResult<String> {
        let ds = paperbsdf_fit::dataset::load_dataset(&data, thickness).map_err(fit_error)?;
        let cands =
            paperbsdf_fit::models::candidates_with_faces(&model, ds.thickness, ds.channels == 3, Some(&dists), faces)
                .map_err(fit_error)?;
        let cands = paperbsdf_fit::fix_params(cands, &fix).map_err(fit_error)?;
        let opts = paperbsdf_fit::FitOptions {
            global_samples: samples,
            local_starts: starts,
            lm: paperbsdf_fit::optimize::LmSettings {
                max_iter,
                ..Default::default()
            },
            fit_theta_i: fit_theta_i.clone(),
            seed,
            progress: false,
            ..Default::default()
        };
        let out = paperbsdf_fit::fit(&ds.points, ds.channels, &cands, &opts).map_err(fit_error)?;
        let json = if refine.is_some() {
            let ropts = paperbsdf_fit::RefineOptions {
                lm: paperbsdf_fit::optimize::LmSettings {
                    max_iter: refine_max_iter,
                    parallel_jacobian: true,
                    ..Default::default()
                },
                fit_theta_i: fit_theta_i.clone(),
                slab: slab_options,
                ..Default::default()
            };
            paperbsdf_fit::refine_with_slab(&ds.points, ds.channels, &cands, &out, &ropts)
                .map_err(fit_error)?
                .to_json(&ds.origins, fit_theta_i.as_deref())
        } else {
            out.to_json(&ds.origins, fit_theta_i.as_deref())
        };
        serde_json::to_string(&json).map_err(|e| value_error(e.to_string()))
    })
}

/// `(text, origin, is_toml)` of a parameter source (a file path, or inline
/// JSON starting with `{`), read as the CLI reads `--params`; a file that
/// cannot be read is a `ValueError` with the CLI's message.
#[pyfunction]
fn read_source(source: &str) -> PyResult<(String, String, bool)> {
    paperbsdf_io::params::read_source(source).map_err(|e| value_error(e.to_string()))
}

/// The allowed nodes per hemisphere of the model `slab`, `(lowest,
/// highest)` (`paperbsdf_io::models::SLAB_NODES_RANGE`).
#[pyfunction]
fn slab_nodes_range() -> (usize, usize) {
    let r = paperbsdf_io::models::SLAB_NODES_RANGE;
    (*r.start(), *r.end())
}

/// [`read_source`] with the nodes per hemisphere a `slab` FIT.json was
/// solved with (its `slab_nodes`; `None` if absent or if `source` is not a
/// FIT.json): `(text, origin, is_toml, nodes)` from one read of the file,
/// or a `ValueError` naming the file when it cannot be read or the value is
/// not allowed.
#[pyfunction]
fn read_source_recorded(source: &str) -> PyResult<(String, String, bool, Option<usize>)> {
    let s = paperbsdf_io::read_source_full(source).map_err(|e| value_error(e.to_string()))?;
    let nodes = SlabSettings::recorded(s.fit_slab_nodes.as_ref(), &s.origin)
        .map(|r| r.nodes)
        .map_err(|e| value_error(e.to_string()))?;
    Ok((s.text, s.origin, s.is_toml, nodes))
}

/// Whether a flags value (bits of `BsdfFlags`) has a delta lobe.
#[pyfunction]
fn flags_is_specular(flags: u8) -> bool {
    BsdfFlags(flags).is_specular()
}

/// The native module `paperbsdf._native`.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Model>()?;
    m.add_function(wrap_pyfunction!(model_names, m)?)?;
    m.add_function(wrap_pyfunction!(slab_model_names, m)?)?;
    m.add_function(wrap_pyfunction!(preset_names, m)?)?;
    m.add_function(wrap_pyfunction!(preset_json, m)?)?;
    m.add_function(wrap_pyfunction!(params_json, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(fit, m)?)?;
    m.add_function(wrap_pyfunction!(read_source_recorded, m)?)?;
    m.add_function(wrap_pyfunction!(slab_nodes_range, m)?)?;
    m.add_function(wrap_pyfunction!(flags_is_specular, m)?)?;
    m.add_function(wrap_pyfunction!(read_source, m)?)?;
    Ok(())
}
