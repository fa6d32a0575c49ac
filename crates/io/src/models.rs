//! Models by name, built from a parameter source: the registry that the CLI,
//! the fitter and the renderer share. Names (docs/design.md 4.7): `paper`,
//! `reduced-multilayer` and `slab` (same parameters as `paper`; `slab` is the
//! same sheet solved by adding-doubling, `paperbsdf_slab`), `lambert-glass`,
//! `rough-dielectric`; and `measured`, whose "parameters" are a measured
//! RGL `.bsdf` file ([`crate::rgl`]).

use crate::params::{parse_text, read_source_full, Loaded};
use crate::DataError;
use paperbsdf_core::models::{ComponentModel, LambertGlass, LambertGlassParams, ModelKind, UnknownModel};
use paperbsdf_core::paper::{Component, PaperBsdf};
use paperbsdf_core::{Bsdf, DVec3, PaperParams, ParamError, Rgb, RoughDielectric, RoughDielectricParams};

/// A component asked of a model that does not have it (`--component single`
/// of `rough-dielectric`).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("--component {component}: {model} has no such component (it has: {has}, all)")]
pub struct MissingComponent {
    /// The component asked for.
    pub component: Component,
    /// The model, as the message names it (`the model rough-dielectric`).
    pub model: &'static str,
    /// The model's components, comma-separated.
    pub has: String,
}

/// A model loaded from a parameter file.
pub enum LoadedModel {
    /// `paper` or `reduced-multilayer`.
    Paper(Box<PaperBsdf>),
    /// `lambert-glass`.
    LambertGlass(Box<LambertGlass>),
    /// `rough-dielectric`.
    RoughDielectric(RoughDielectric),
    /// `measured`: an RGL `.bsdf` file.
    Measured(Box<crate::MeasuredBsdf>),
    /// `slab`: the sheet solved by adding-doubling.
    Slab(Box<paperbsdf_slab::SlabBsdf>),
}

/// How finely the model `slab` is solved, as its users set it (`--slab-nodes`
/// on the command line, `slab_nodes` in Python and in a scene's paper
/// material): the outside nodes per hemisphere ([`paperbsdf_slab::SlabOptions::nodes`],
/// with half as many in the cone of total internal reflection, as the
/// default 32 and 16). `None` is the default discretisation. Other models
/// have no discretisation: asking one for it is an error, not ignored.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SlabSettings {
    /// Outside nodes per hemisphere, in [`SLAB_NODES_RANGE`]; `None`: 32.
    pub nodes: Option<usize>,
}

/// The node counts [`SlabSettings::nodes`] accepts. Below 2 there is no
/// grid; above 256 a build takes minutes and its tables gigabytes (64
/// nodes: about 4 times the default's build time and 3.5 times its memory, docs/slab.md
/// "Convergence").
pub const SLAB_NODES_RANGE: std::ops::RangeInclusive<usize> = 2..=256;

/// The key of a FIT.json that records the discretisation a `slab` fit was
/// solved with (`paperbsdf fit --refine slab [--slab-nodes N]`): its
/// outside nodes per hemisphere, as [`SlabSettings::nodes`].
pub const SLAB_NODES_KEY: &str = "slab_nodes";

impl SlabSettings {
    /// The settings a FIT.json records (`value`: its [`SLAB_NODES_KEY`],
    /// `None` if absent, the default then), or an error naming `origin`,
    /// the key and the allowed range when it is not a whole number in
    /// [`SLAB_NODES_RANGE`].
    pub fn recorded(value: Option<&serde_json::Value>, origin: &str) -> Result<SlabSettings, DataError> {
        let Some(v) = value else {
            return Ok(SlabSettings::default());
        };
        match v.as_u64().and_then(|n| usize::try_from(n).ok()) {
            Some(n) if SLAB_NODES_RANGE.contains(&n) => Ok(SlabSettings { nodes: Some(n) }),
            _ => Err(DataError::Other {
                file: origin.to_string(),
                message: format!(
                    "`{SLAB_NODES_KEY}`: {v} is not a whole number of nodes per hemisphere in the allowed range [{}, {}]",
                    SLAB_NODES_RANGE.start(),
                    SLAB_NODES_RANGE.end()
                ),
            }),
        }
    }

    /// Whether these are the default settings.
    pub fn is_default(&self) -> bool {
        self.nodes.is_none()
    }

    /// An error naming `flag` unless these are the default settings or
    /// `kind` (called `name` in the message) is `slab`.
    pub fn check_model(&self, kind: ModelKind, name: &str, flag: &str) -> Result<(), DataError> {
        if kind != ModelKind::Slab && !self.is_default() {
            return Err(DataError::Other {
                file: flag.to_string(),
                message: format!("sets the discretisation of the model `slab`; the model `{name}` has none"),
            });
        }
        Ok(())
    }

    /// The solver's options, or an error naming `--slab-nodes` (as `flag`
    /// spells it) and its range.
    pub fn options(&self, flag: &str) -> Result<paperbsdf_slab::SlabOptions, DataError> {
        let mut o = paperbsdf_slab::SlabOptions::default();
        if let Some(n) = self.nodes {
            if !SLAB_NODES_RANGE.contains(&n) {
                return Err(DataError::Other {
                    file: flag.to_string(),
                    message: format!(
                        "{n} is outside the allowed range [{}, {}] of nodes per hemisphere (default 32; 64 converges \
                         the model's values to within 0.2% of twice the nodes on the accuracy cases but one, docs/slab.md \
                         \"Convergence\")",
                        SLAB_NODES_RANGE.start(),
                        SLAB_NODES_RANGE.end()
                    ),
                });
            }
            o.nodes = n;
            o.tir_nodes = (n / 2).max(1);
        }
        Ok(o)
    }
}

/// Loads model `name` with parameters from `source` (file path, inline JSON, a
/// paper preset name or a FIT.json; see [`crate::params`]). The model name is
/// checked first, then that a FIT.json holds a fit of this model and that a
/// preset is used with a slab model.
pub fn load_model(name: &str, source: &str) -> Result<LoadedModel, DataError> {
    load_model_with(name, source, &SlabSettings::default(), "--slab-nodes")
}

/// [`load_model`] with the discretisation of the model `slab` (`settings`;
/// `flag` names them in errors, e.g. `--slab-nodes` or `slab_nodes`).
pub fn load_model_with(
    name: &str,
    source: &str,
    settings: &SlabSettings,
    flag: &str,
) -> Result<LoadedModel, DataError> {
    let kind: ModelKind = name.parse().map_err(|e: UnknownModel| DataError::Other {
        file: "--model".to_string(),
        message: e.to_string(),
    })?;
    settings.check_model(kind, name, flag)?;
    if kind == ModelKind::Measured {
        return Ok(LoadedModel::Measured(Box::new(crate::MeasuredBsdf::load(source)?)));
    }
    let s = read_source_full(source)?;
    let slab = kind.is_slab();
    if let Some(fit) = &s.fit_model {
        if fit != name {
            return Err(DataError::Other {
                file: s.origin,
                message: format!("this is a fit of the model `{fit}`, not `{name}`: use --model {fit}"),
            });
        }
    }
    if s.preset.is_some() && !slab {
        return Err(DataError::Other {
            file: s.origin,
            message: format!(
                "presets are Paper BSDF parameters (models paper, reduced-multilayer), not `{name}` parameters"
            ),
        });
    }
    // A `slab` fit is evaluated with the discretisation it was fitted with,
    // unless `settings` choose another.
    let recorded = SlabSettings::recorded(s.fit_slab_nodes.as_ref(), &s.origin)?;
    if settings.is_default() && !recorded.is_default() {
        let flag = format!("{}: `{SLAB_NODES_KEY}`", s.origin);
        return load_model_text_with(name, &s.text, &s.origin, s.is_toml, &recorded, &flag);
    }
    load_model_text_with(name, &s.text, &s.origin, s.is_toml, settings, flag)
}

/// Builds model `name` from the text of a parameter set (JSON, or TOML when
/// `is_toml`); `origin` names it in errors.
pub fn load_model_text(name: &str, text: &str, origin: &str, is_toml: bool) -> Result<LoadedModel, DataError> {
    load_model_text_with(name, text, origin, is_toml, &SlabSettings::default(), "--slab-nodes")
}

/// [`load_model_text`] with the discretisation of the model `slab`
/// ([`load_model_with`]).
pub fn load_model_text_with(
    name: &str,
    text: &str,
    origin: &str,
    is_toml: bool,
    settings: &SlabSettings,
    flag: &str,
) -> Result<LoadedModel, DataError> {
    fn loaded<T: serde::de::DeserializeOwned>(text: &str, origin: &str, is_toml: bool) -> Result<Loaded<T>, DataError> {
        let value = parse_text(text, origin, is_toml)?;
        Ok(Loaded {
            value,
            origin: origin.to_string(),
            text: text.to_string(),
            is_toml,
        })
    }
    fn build<T, U>(l: &Loaded<T>, f: impl FnOnce(&T) -> Result<U, ParamError>) -> Result<U, DataError> {
        f(&l.value).map_err(|e| l.param_error(e))
    }
    let kind: ModelKind = name.parse().map_err(|e: UnknownModel| DataError::Other {
        file: origin.to_string(),
        message: e.to_string(),
    })?;
    settings.check_model(kind, name, flag)?;
    Ok(match kind {
        ModelKind::Paper => LoadedModel::Paper(Box::new(build(
            &loaded::<PaperParams>(text, origin, is_toml)?,
            PaperBsdf::new,
        )?)),
        ModelKind::ReducedMultilayer => LoadedModel::Paper(Box::new(build(
            &loaded::<PaperParams>(text, origin, is_toml)?,
            PaperBsdf::reduced_multilayer,
        )?)),
        ModelKind::LambertGlass => LoadedModel::LambertGlass(Box::new(build(
            &loaded::<LambertGlassParams>(text, origin, is_toml)?,
            LambertGlass::new,
        )?)),
        ModelKind::RoughDielectric => {
            LoadedModel::RoughDielectric(build(&loaded::<RoughDielectricParams>(text, origin, is_toml)?, |p| {
                p.build()
            })?)
        }
        ModelKind::Slab => {
            let l = loaded::<PaperParams>(text, origin, is_toml)?;
            let options = settings.options(flag)?;
            LoadedModel::Slab(Box::new(
                paperbsdf_slab::SlabBsdf::with_options(&l.value, &options).map_err(|e| match e {
                    paperbsdf_slab::SlabError::Param(p) => l.param_error(p),
                    other => DataError::Other {
                        file: origin.to_string(),
                        message: other.to_string(),
                    },
                })?,
            ))
        }
        ModelKind::Measured => {
            return Err(DataError::Other {
                file: origin.to_string(),
                message: "the model `measured` is read from an RGL .bsdf file, not from parameter text".to_string(),
            })
        }
    })
}

impl LoadedModel {
    /// The model, with its components.
    pub fn model(&self) -> &dyn ComponentModel {
        match self {
            LoadedModel::Paper(m) => m.as_ref(),
            LoadedModel::LambertGlass(m) => m.as_ref(),
            LoadedModel::RoughDielectric(m) => m,
            LoadedModel::Measured(m) => m.as_ref(),
            LoadedModel::Slab(m) => m.as_ref(),
        }
    }

    /// Whether the model's values have three distinct channels (print `r,g,b`).
    pub fn is_rgb(&self) -> bool {
        self.model().is_rgb()
    }

    /// Checks that the model has `component` (`None`: all of them, which
    /// every model has): asking for a component it lacks is an error, not a
    /// silent zero.
    pub fn check_component(&self, component: Option<Component>) -> Result<(), MissingComponent> {
        let has = self.model().components();
        match component {
            Some(c) if !has.contains(&c) => Err(MissingComponent {
                component: c,
                model: match self {
                    LoadedModel::Paper(_) => "this paper model",
                    LoadedModel::LambertGlass(_) => "the model lambert-glass",
                    LoadedModel::RoughDielectric(_) => "the model rough-dielectric",
                    LoadedModel::Measured(_) => "the measured BSDF",
                    LoadedModel::Slab(_) => "the model slab",
                },
                has: has.iter().map(|c| c.name()).collect::<Vec<_>>().join(", "),
            }),
            _ => Ok(()),
        }
    }

    /// `f(wi, wo)` of one component (`surface`, `single`, `multiple`,
    /// `direct`) or, for `None`, of all; see [`LoadedModel::check_component`].
    pub fn eval_component(&self, wi: DVec3, wo: DVec3, component: Option<Component>) -> Result<Rgb, MissingComponent> {
        self.check_component(component)?;
        Ok(match component {
            None => self.model().eval(wi, wo),
            Some(c) => self.model().eval_component(wi, wo, c),
        })
    }

    /// Directional albedo `(reflectance, transmittance)` for light arriving from
    /// direction `w` (pointing toward the light): flux fractions. The rough
    /// dielectric uses the converged quadrature of `boundary` (importance
    /// transport, no eta^2, as Mitsuba's albedo); the slab models integrate
    /// `f(w, wo) |cos wo|` over the outgoing directions with 512 x 512
    /// stratified samples of their own sampling routine
    /// ([`paperbsdf_core::bsdf::albedo_from`]): the physical fractions of the
    /// light arriving from `w` that are reflected and transmitted.
    pub fn albedo(&self, w: DVec3) -> (Rgb, Rgb) {
        match self {
            LoadedModel::RoughDielectric(b) => {
                let (r, t) = paperbsdf_core::boundary::directional_albedo_n(b, w, 256);
                (Rgb::splat(r), Rgb::splat(t))
            }
            _ => {
                let bsdf: &dyn Bsdf = self.model();
                paperbsdf_core::bsdf::albedo_from(bsdf, w, 512)
            }
        }
    }
}
