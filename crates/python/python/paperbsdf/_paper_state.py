"""The Paper BSDF's construction-time tables, read from the Rust model.

``paperbsdf_core::PaperBsdf`` builds, once per parameter set, the node
tables that its ``eval``, ``pdf`` and ``sample`` interpolate (docs/design.md
section 4; crates/core/src/paper/mod.rs, face.rs, tables.rs): per face the
transmittance ``Att`` and its collimated part, the reflectance, the separable
reflection lobes of the energy compensation and of a coating; the
multiple-scattering tables ``W_e`` and constants; the lobe-selection
probabilities; the phase function and the direct kernel. Its fields are
private to the core crate, and the native module exposes them as the text of
the model's ``Debug`` representation (``Model.paper_state``), in which Rust
prints every ``f64`` in its shortest round-trip form: the values read here
are the model's, bit for bit.

:func:`paper_state` parses that text (a small reader of Rust's ``Debug``
syntax) and returns the quantities :mod:`paperbsdf.mitsuba_native` needs, as
float64 numpy arrays and Python scalars. Any field it does not find raises
:class:`PaperStateError`: a change of the core crate's layout fails loudly,
never silently (and the Python tests compare the Dr.Jit evaluation built on
these tables with the Rust model's).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

_TOKEN = re.compile(
    r"\s*(?:(?P<num>-?(?:inf|NaN|\d+(?:\.\d*)?(?:[eE][-+]?\d+)?))|(?P<id>[A-Za-z_][A-Za-z0-9_]*)|(?P<p>[{}()\[\]:,]))"
)


class PaperStateError(ValueError):
    """The model's state text does not have the layout this reader knows."""


@dataclass
class _Tuple:
    """A tuple struct or enum variant with fields, ``Name(a, b)``."""

    name: str
    items: list


class _Reader:
    def __init__(self, text: str):
        self.toks = []
        pos = 0
        text = text.rstrip()
        while pos < len(text):
            m = _TOKEN.match(text, pos)
            if not m or m.end() == pos:
                raise PaperStateError(f"unexpected text at {pos}: {text[pos:pos + 40]!r}")
            pos = m.end()
            if m.group("num") is not None:
                self.toks.append(("num", m.group("num")))
            elif m.group("id") is not None:
                self.toks.append(("id", m.group("id")))
            else:
                self.toks.append(("p", m.group("p")))
        self.i = 0

    def peek(self):
        return self.toks[self.i] if self.i < len(self.toks) else ("eof", "")

    def take(self, p=None):
        t = self.peek()
        if p is not None and t != ("p", p):
            raise PaperStateError(f"expected `{p}`, found `{t[1]}`")
        self.i += 1
        return t

    def items(self, close: str) -> list:
        out = []
        while self.peek() != ("p", close):
            out.append(self.value())
            if self.peek() == ("p", ","):
                self.take(",")
        self.take(close)
        return out

    def value(self):
        kind, s = self.take()
        if kind == "num":
            return float(s)
        if kind == "p" and s == "[":
            return self.items("]")
        if kind == "p" and s == "(":
            return tuple(self.items(")"))
        if kind != "id":
            raise PaperStateError(f"unexpected `{s}`")
        nxt = self.peek()
        if nxt == ("p", "{"):
            self.take("{")
            fields = {"__type__": s}
            while self.peek() != ("p", "}"):
                _, name = self.take()
                self.take(":")
                fields[name] = self.value()
                if self.peek() == ("p", ","):
                    self.take(",")
            self.take("}")
            return fields
        if nxt == ("p", "("):
            self.take("(")
            return _Tuple(s, self.items(")"))
        if s in ("true", "false"):
            return s == "true"
        return s  # a unit variant (`None`, `Ggx`, `IndexMatched`, ...)


def parse_debug(text: str):
    """Parses Rust ``Debug`` text into dicts (structs, with ``__type__``),
    lists, tuples, :class:`_Tuple` (tuple structs, enum variants), floats,
    bools and strings (unit variants)."""
    r = _Reader(text)
    v = r.value()
    if r.peek()[0] != "eof":
        raise PaperStateError("trailing text after the model's state")
    return v


def _field(d, name: str):
    if not isinstance(d, dict) or name not in d:
        raise PaperStateError(f"field `{name}` not found in {d.get('__type__', '?') if isinstance(d, dict) else d!r}")
    return d[name]


def _inner(v, name: str):
    """The single item of tuple struct ``name(...)`` (``Rgb``, ``PerSide``, ``LobeProbs``)."""
    if not isinstance(v, _Tuple) or v.name != name or len(v.items) != 1:
        raise PaperStateError(f"expected `{name}(..)`, found {v!r:.60}")
    return v.items[0]


def _rgb(v) -> np.ndarray:
    a = np.asarray(_inner(v, "Rgb"), dtype=np.float64)
    if a.shape != (3,):
        raise PaperStateError("an Rgb of 3 channels expected")
    return a


def _per_side(v) -> list:
    s = _inner(v, "PerSide")
    if len(s) != 2:
        raise PaperStateError("PerSide of 2 sides expected")
    return s


@dataclass
class FaceState:
    """One face (crates/core/src/paper/face.rs ``Face``)."""

    kind: str  # "rough", "smooth" or "matched"
    dist: str  # "ggx" or "beckmann" (of a rough face)
    alpha: float
    eta: float  # the rough interface's relative index
    use_att: bool
    exact_smooth: bool
    att: np.ndarray  # (NA,)
    att_dir: np.ndarray  # (NA,)
    r: np.ndarray  # (NA,) reflectance from outside, every lobe
    lobe: np.ndarray  # (NA, 2): sqrt(c_j) E_j of the separable lobes
    has_lobes: bool
    coating: float | None  # nu = eta_b / eta_f, or None
    n: float  # index of the base
    inv_n: float
    inv_n2: float
    inv_eta2: float


@dataclass
class PaperState:
    """The tables and constants of a ``PaperBsdf`` (see the module doc)."""

    faces: list  # [front, back] FaceState
    phase_lobes: list  # [(g, w)] x 2, absent lobes (0, 0)
    phase_coef: list  # [(k, a, b)] x 2: HgLobes::ratio's coefficients
    phase_weight: float
    albedo: np.ndarray  # (3,)
    tau: np.ndarray  # (3,)
    tau_min: float
    w_tab: np.ndarray  # (2, NA, 3)
    ms_r: np.ndarray  # (2, 3)
    ms_t: np.ndarray  # (3,)
    c_r: np.ndarray  # (2, 3)
    c_t: np.ndarray  # (2, 3)
    kappa: float
    pr_tab: np.ndarray  # (2, NP, 5)
    kernel: str  # "delta", "ggx" or "gauss"
    kernel_beta: float
    use_att: bool
    energy_bound: bool
    direct: bool


def _face(d) -> FaceState:
    bd = _field(d, "bd")
    iface = _field(bd, "interface")
    if isinstance(iface, _Tuple) and iface.name == "Rough":
        mf = iface.items[0]
        kind, dist, alpha = "rough", str(_field(mf, "dist")).lower(), float(_field(mf, "alpha"))
    elif iface == "Smooth":
        kind, dist, alpha = "smooth", "ggx", 0.0
    elif iface == "IndexMatched":
        kind, dist, alpha = "matched", "ggx", 0.0
    else:
        raise PaperStateError(f"unknown interface {iface!r}")
    if dist not in ("ggx", "beckmann"):
        raise PaperStateError(f"unknown distribution {dist!r}")
    coating = _field(d, "coating")
    if isinstance(coating, _Tuple) and coating.name == "Some":
        coating = float(coating.items[0])
    elif coating == "None":
        coating = None
    else:
        raise PaperStateError(f"coating: {coating!r}")
    lobe = np.asarray(_field(d, "lobe_tab"), dtype=np.float64)
    att = np.asarray(_field(d, "att_tab"), dtype=np.float64)
    na = att.shape[0]
    for name in ("att_dir_tab", "r_tab"):
        if np.asarray(_field(d, name)).shape != (na,):
            raise PaperStateError(f"{name}: expected {na} nodes")
    if lobe.shape != (na, 2):
        raise PaperStateError("lobe_tab: expected (NA, 2)")
    return FaceState(
        kind=kind,
        dist=dist,
        alpha=alpha,
        eta=float(_field(bd, "eta")),
        use_att=bool(_field(d, "use_att")),
        exact_smooth=bool(_field(d, "exact_smooth")),
        att=att,
        att_dir=np.asarray(_field(d, "att_dir_tab"), dtype=np.float64),
        r=np.asarray(_field(d, "r_tab"), dtype=np.float64),
        lobe=lobe,
        has_lobes=len(_field(d, "lobes")) > 0,
        coating=coating,
        n=float(_field(d, "n")),
        inv_n=float(_field(d, "inv_n")),
        inv_n2=float(_field(d, "inv_n2")),
        inv_eta2=float(_field(d, "inv_eta2")),
    )


def paper_state(text: str) -> PaperState:
    """The :class:`PaperState` of a model's ``paper_state`` text."""
    d = parse_debug(text)
    if not isinstance(d, dict) or d.get("__type__") != "PaperBsdf":
        raise PaperStateError("not the state of a PaperBsdf")
    faces = [_face(f) for f in _per_side(_field(d, "faces"))]
    ph = _field(d, "phase")
    kern = _field(_field(d, "kernel"), "shape")
    if kern == "Delta":
        kernel, beta = "delta", 0.0
    elif isinstance(kern, _Tuple) and kern.name in ("Ggx", "Gauss"):
        kernel, beta = kern.name.lower(), float(kern.items[0])
    else:
        raise PaperStateError(f"kernel shape {kern!r}")
    opts = _field(d, "opts")
    pr = np.asarray([[_inner(p, "LobeProbs") for p in side] for side in _per_side(_field(d, "pr_tab"))],
                    dtype=np.float64)
    if pr.ndim != 3 or pr.shape[0] != 2 or pr.shape[2] != 5:
        raise PaperStateError("pr_tab: expected (2, NP, 5)")
    return PaperState(
        faces=faces,
        phase_lobes=[tuple(map(float, x)) for x in _field(ph, "lobes")],
        phase_coef=[tuple(map(float, x)) for x in _field(ph, "coef")],
        phase_weight=float(_field(ph, "weight")),
        albedo=_rgb(_field(d, "albedo")),
        tau=_rgb(_field(d, "tau")),
        tau_min=float(_field(d, "tau_min")),
        w_tab=np.asarray([[_rgb(c) for c in side] for side in _per_side(_field(d, "w_tab"))]),
        ms_r=np.asarray([_rgb(c) for c in _per_side(_field(d, "ms_r"))]),
        ms_t=_rgb(_field(d, "ms_t")),
        c_r=np.asarray([_rgb(c) for c in _per_side(_field(d, "c_r"))]),
        c_t=np.asarray([_rgb(c) for c in _per_side(_field(d, "c_t"))]),
        kappa=float(_field(d, "kappa")),
        pr_tab=pr,
        kernel=kernel,
        kernel_beta=beta,
        use_att=bool(_field(opts, "use_att")),
        energy_bound=bool(_field(opts, "energy_bound")),
        direct=bool(_field(opts, "direct")),
    )
