"""paperbsdf: the Paper BSDF of Papas, de Mesa and Jensen (EGSR 2014) for Python.

A sheet of paper as a thin slab of scattering medium between two rough
dielectric faces: surface reflection, single and multiple scattering and
transmission (the Rust crates of the paperbsdf workspace, through PyO3).

Conventions (docs/design.md, section 2): directions are unit vectors
in the local frame whose +z is the front face's normal; ``wi`` points toward
the light, ``wo`` toward the viewer; ``eval`` is f(wi, wo) *without* the cosine
factor, RGB. Lengths in millimetres, coefficients in 1/mm.

>>> import numpy as np, paperbsdf
>>> b = paperbsdf.PaperBsdf("matte")                      # a preset, a dict, JSON text or a file
>>> wi = np.array([[0.5, 0.0, np.sqrt(0.75)]]); wo = np.array([[0.0, 0.0, 1.0]])
>>> f = b.eval(wi, wo)                                     # (1, 3)

Every input error raises ``ValueError`` with the message the ``paperbsdf``
command line prints for the same input (file, line, parameter, allowed range).
The Mitsuba 3 plugin is in :mod:`paperbsdf.mitsuba`.
"""

from __future__ import annotations

import json
import os
from typing import Any, Mapping, Optional, Sequence

import numpy as np

from . import _native

__all__ = [
    "Bsdf",
    "PaperBsdf",
    "MODEL_NAMES",
    "FLAG_REFLECTION",
    "FLAG_TRANSMISSION",
    "FLAG_DIFFUSE",
    "FLAG_GLOSSY",
    "FLAG_SPECULAR",
    "presets",
    "preset",
    "load_params",
    "simulate",
    "fit",
]

#: Model names (docs/design.md 4.7): ``paper``, ``reduced-multilayer`` and ``slab``
#: (the same sheet solved numerically) take the Paper BSDF's parameters, ``lambert-glass`` takes ``k_d, k_t, eta, m, dist``,
#: ``rough-dielectric`` takes ``eta, m, dist``.
MODEL_NAMES = tuple(_native.model_names())  # from the Rust registry (ModelKind)

#: Bits of the lobe flags (``Bsdf.flags``, and the flags ``sample_full`` returns).
FLAG_REFLECTION = 1
FLAG_TRANSMISSION = 2
FLAG_DIFFUSE = 4
FLAG_GLOSSY = 8
FLAG_SPECULAR = 16

_PAPER_MODELS = tuple(_native.slab_model_names())


def _params_text(params: Any, model: str, argname: str = "params") -> tuple[str, str, bool]:
    """(text, origin, is_toml) of a parameter source for the native loader.

    ``params`` is a dict of the docs/design.md keys (written one key per line, so
    an error's line number points at the key), a JSON string starting with
    ``{``, a preset name (paper models), or a path to a JSON or TOML file.
    """
    if isinstance(params, Mapping):
        try:
            text = json.dumps(dict(params), indent=1, allow_nan=False)
        except (TypeError, ValueError) as e:
            raise ValueError(f"{argname}: cannot be written as JSON: {e}") from None
        return text, "<dict>", False
    if isinstance(params, os.PathLike):
        params = os.fspath(params)
    if not isinstance(params, str):
        raise ValueError(
            f"{argname}: expected a dict, a JSON string, a preset name or a file path, got {type(params).__name__}"
        )
    s = params.strip()
    if s.startswith("{"):
        return params, "<inline>", False
    if model in _PAPER_MODELS and not os.path.exists(params) and s.lower() in _preset_aliases():
        return _native.preset_json(s), f"<preset {s}>", False
    try:
        return tuple(_native.read_source(params))
    except ValueError as e:
        # The CLI's message ("FILE: No such file or directory (os error 2)"), with the argument's name.
        raise ValueError(f"{argname}: {e}") from None


def _preset_aliases() -> set[str]:
    return set(_native.preset_names()) | {"office", "matte-office", "luster-photo", "glossy-photo"}


def _dirs(x: Any, name: str) -> np.ndarray:
    a = np.asarray(x, dtype=np.float64)
    if a.ndim == 1 and a.shape[0] == 3:
        a = a[None, :]
    if a.ndim != 2:
        raise ValueError(f"{name}: expected an array of shape (N, 3), got shape {a.shape}")
    return np.ascontiguousarray(a)


def _slab_nodes_arg(slab_nodes: Any) -> Optional[int]:
    """``slab_nodes`` checked to be ``None`` or a whole number (the range is
    checked natively, with the CLI's message; a negative number, which the
    native side cannot take, gets it here)."""
    if slab_nodes is None:
        return None
    if isinstance(slab_nodes, bool) or not isinstance(slab_nodes, int):
        raise ValueError(f"slab_nodes: expected a whole number of nodes, got {slab_nodes!r}")
    if slab_nodes < 0:
        lo, hi = _native.slab_nodes_range()
        raise ValueError(f"slab_nodes: {slab_nodes} is outside the allowed range [{lo}, {hi}] of nodes per hemisphere")
    return slab_nodes


class Bsdf:
    """A scattering model by name: ``Bsdf(model, params, slab_nodes=None)``.

    ``model`` is one of :data:`MODEL_NAMES`; ``params`` a dict with the keys
    of docs/design.md section 3, a JSON string, a file path (JSON or TOML), or for
    the paper models a preset name (``matte``, ``luster``, ``glossy``).
    ``slab_nodes``: for the model ``slab`` only, the nodes per hemisphere
    of its discretisation (2 to 256; ``None`` for the default 32; 64
    converges its values to within 0.2% of twice the nodes on the accuracy
    cases but one and builds about 4 times slower; the CLI's ``--slab-nodes``).
    A ``slab`` FIT.json (``fit(..., refine="slab")``) is solved with the nodes
    it records (``slab_nodes``) unless ``slab_nodes`` is given, as in the CLI.
    """

    def __init__(self, model: str, params: Any, slab_nodes: Optional[int] = None):
        if not isinstance(model, str):
            raise ValueError(f"model: expected a name ({', '.join(MODEL_NAMES)}), got {type(model).__name__}")
        slab_nodes = _slab_nodes_arg(slab_nodes)
        path = os.fspath(params) if isinstance(params, (str, os.PathLike)) else None
        if slab_nodes is None and model == "slab" and path is not None and os.path.isfile(path):
            # A slab FIT.json is solved with the nodes it was fitted with
            # (the file read once for both).
            try:
                text, origin, is_toml, slab_nodes = _native.read_source_recorded(path)
            except ValueError as e:
                raise ValueError(f"params: {e}") from None
        else:
            text, origin, is_toml = _params_text(params, model)
        self._native = _native.Model(model, text, origin, is_toml, slab_nodes)
        self._text = text
        self.model = model

    @property
    def is_rgb(self) -> bool:
        """Whether the parameters have three distinct colour channels."""
        return self._native.is_rgb

    @property
    def flags(self) -> int:
        """The model's lobes: an OR of the ``FLAG_*`` bits."""
        return self._native.flags

    @property
    def params(self) -> dict:
        """The parameters as a dict (as given; defaults are not filled in)."""
        if self._text.lstrip().startswith("{"):
            return json.loads(self._text)
        import tomllib  # Python 3.11+; only TOML files reach here

        return tomllib.loads(self._text)

    def eval(self, wi: Any, wo: Any, component: str = "all") -> np.ndarray:
        """f(wi, wo) without the cosine, shape (N, 3), for (N, 3) unit directions.

        ``component`` is ``all`` or one of ``surface``, ``single``, ``multiple``, ``direct``.
        Delta lobes are not included (they are zero for any pair of directions).
        """
        return self._native.eval(_dirs(wi, "wi"), _dirs(wo, "wo"), component)

    def pdf(self, wi: Any, wo: Any) -> np.ndarray:
        """Solid-angle density, shape (N,), with which ``sample(wo, u)`` draws ``wi``."""
        return self._native.pdf(_dirs(wi, "wi"), _dirs(wo, "wo"))

    def eval_pdf(self, wi: Any, wo: Any) -> tuple[np.ndarray, np.ndarray]:
        """``(eval(wi, wo), pdf(wi, wo))`` in one pass."""
        return self._native.eval_pdf(_dirs(wi, "wi"), _dirs(wo, "wo"))

    def sample(self, wo: Any, u: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Draws ``wi`` for each row of ``wo`` (N, 3) from ``u`` (N, 3) in [0, 1).

        Returns ``(wi, weight, pdf)``: (N, 3), (N, 3) = f |cos wi| / pdf, (N,).
        A failed draw (absorbed) has ``wi = 0``, ``weight = 0``, ``pdf = 0``.
        For a delta lobe ``pdf`` is the lobe's discrete probability.
        """
        wi, _f, pdf, _flags, weight = self.sample_full(wo, u)
        return wi, weight, pdf

    def sample_full(self, wo: Any, u: Any) -> tuple[np.ndarray, ...]:
        """As :meth:`sample`, returning ``(wi, f, pdf, flags, weight)``; ``flags``
        (N,) uint8 says which lobe each draw took (``FLAG_*`` bits)."""
        return self._native.sample(_dirs(wo, "wo"), _dirs(u, "u"))

    def albedo(self, theta_i_deg: Any, side: str = "front") -> tuple[np.ndarray, np.ndarray]:
        """Directional albedo for light at polar angles ``theta_i_deg`` (degrees,
        [0, 90]) arriving at the ``side`` face (``front``: from z > 0, ``back``:
        from z < 0). Returns ``(reflectance, transmittance)``, each (N, 3); the
        routine of ``paperbsdf albedo``."""
        t = np.ascontiguousarray(np.atleast_1d(np.asarray(theta_i_deg, dtype=np.float64)))
        if t.ndim != 1:
            raise ValueError(f"theta_i_deg: expected a number or a 1-D array, got shape {t.shape}")
        return self._native.albedo(t, side)

    def __repr__(self) -> str:
        return f"paperbsdf.Bsdf({self.model!r}, rgb={self.is_rgb})"


class PaperBsdf(Bsdf):
    """The Paper BSDF: ``PaperBsdf(params)`` with ``params`` a dict, JSON string,
    file path or preset name (see :class:`Bsdf`)."""

    def __init__(self, params: Any):
        super().__init__("paper", params)


def presets() -> dict[str, dict]:
    """The presets of ``paperbsdf_core::presets`` as ``{name: params dict}``."""
    return {n: json.loads(_native.preset_json(n)) for n in _native.preset_names()}


def preset(name: str) -> dict:
    """The parameters of preset ``name`` (``matte``, ``luster``, ``glossy`` or an alias)."""
    if not isinstance(name, str):
        raise ValueError(f"preset: expected a name, got {type(name).__name__}")
    return json.loads(_native.preset_json(name))


def load_params(source: Any, model: str = "paper") -> dict:
    """Reads and validates the parameters of ``model`` from ``source`` (a file
    path, JSON text, a dict or a preset name) and returns them as a dict.
    Errors name the file, line, parameter and allowed range, as the CLI does."""
    text, origin, is_toml = _params_text(source, model, "source")
    _native.Model(model, text, origin, is_toml)  # validates every range
    if is_toml:
        import tomllib

        return tomllib.loads(text)
    return json.loads(text)


def simulate(
    params: Any,
    wi: Any,
    wo: Any,
    *,
    samples: int = 1 << 16,
    batches: int = 32,
    seed: int = 1,
    rel_stderr: float | None = None,
    max_samples: int = 1 << 26,
) -> dict:
    """Monte Carlo ground truth (``paperbsdf simulate``): the physical slab of
    paper parameters ``params`` lit from the direction ``wi`` (3,), seen from
    each row of ``wo`` (M, 3).

    Returns a dict: ``f`` and ``stderr`` (M, 3) (BSDF without cosine and its
    standard error), ``reflectance``, ``transmittance`` and their ``_stderr``
    (3,), and ``samples`` (walks per channel). ``rel_stderr`` keeps adding walks
    until every positive estimate's standard error is below that fraction.
    """
    text, origin, is_toml = _params_text(params, "paper")
    if is_toml:
        import tomllib

        text = json.dumps(tomllib.loads(text), indent=1)
    return _native.simulate(
        text, origin, _dirs(wi, "wi"), _dirs(wo, "wo"), int(samples), int(batches), int(seed),
        None if rel_stderr is None else float(rel_stderr), int(max_samples),
    )


def fit(
    data: str | os.PathLike | Sequence[str | os.PathLike],
    model: str = "paper",
    *,
    thickness: float | None = None,
    fit_theta_i: Sequence[float] | None = None,
    dists: Sequence[str] = ("ggx", "beckmann"),
    samples: int = 128,
    starts: int = 16,
    max_iter: int = 500,
    seed: int = 1,
    fix: Mapping[str, float] | None = None,
    face_scattering: str = "multiple",
    refine: str | None = None,
    refine_max_iter: int = 40,
    slab_nodes: int | None = None,
) -> dict:
    """Fits ``model`` (``paper``, ``lambert-glass``, ``reduced-multilayer``) to
    measurement files (``paperbsdf fit``): CSV with ``kind,theta_i_deg,theta_o_deg``
    or ``wi_*,wo_*`` columns and ``f`` or ``r,g,b``. ``fit_theta_i`` lists the
    incident angles fitted; points at other angles are extrapolation points.
    ``fix`` holds parameters at values (``{"eta_b": 1.5}``, the CLI's ``--fix``);
    ``face_scattering`` is ``"multiple"`` or ``"single"`` (Walter's faces).
    ``refine="slab"`` refines the fit with the model ``slab`` from its optimum
    (the CLI's ``--refine slab``: a solve per evaluation, minutes; the result's
    ``model`` is ``slab``, the first fit is under ``refinement``), each solve with
    ``slab_nodes`` nodes per hemisphere (the CLI's ``--slab-nodes``; ``None``: 32),
    which the result records as ``slab_nodes``.
    Returns the CLI's fit JSON as a dict (``model``, ``params``, ``rms_log_error``,
    ``extrapolation_rms_log_error``, ``errors``, ...)."""
    if isinstance(data, (str, os.PathLike)):
        data = [data]
    paths = [os.fspath(p) for p in data]
    text = _native.fit(
        paths, model, None if thickness is None else float(thickness),
        None if fit_theta_i is None else [float(t) for t in fit_theta_i],
        [str(d) for d in dists], int(samples), int(starts), int(max_iter), int(seed),
        [(str(k), float(v)) for k, v in (fix or {}).items()], str(face_scattering),
        None if refine is None else str(refine), int(refine_max_iter),
        _slab_nodes_arg(slab_nodes),
    )
    return json.loads(text)
