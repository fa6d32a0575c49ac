"""A Mitsuba 3 BSDF plugin ``"paperbsdf"``: the Paper BSDF (and the project's
other models) in Mitsuba scenes, the way ``roughplastic`` is used.

>>> import mitsuba as mi; mi.set_variant("llvm_ad_rgb")
>>> import paperbsdf.mitsuba; paperbsdf.mitsuba.register()
>>> bsdf = mi.load_dict({"type": "paperbsdf", "preset": "matte"})

Properties (scene XML ``<string name=... value=.../>`` or ``load_dict`` keys):

- ``params``: the parameters, inline JSON or a path to a JSON/TOML file
  (docs/design.md section 3), or
- ``preset``: ``matte``, ``luster`` or ``glossy``;
- ``model``: ``paper`` (default), ``reduced-multilayer``, ``slab`` (the
  same sheet solved numerically, crates/slab), ``lambert-glass`` or
  ``rough-dielectric``;
- ``mode``: ``auto`` (default), ``native`` or ``exact`` (below);
- ``slab_nodes`` (integer, model ``slab`` only): the nodes per hemisphere
  of its discretisation, 2 to 256 (default 32, or what a ``slab`` FIT.json
  given as ``params`` records; 64 converges its values to
  within 0.2% of twice the nodes on the accuracy cases but one, and builds
  about 4 times slower).

Conventions (paperbsdf's: docs/design.md section 2). Mitsuba 3 (radiance transport) gives the BSDF ``si.wi``, the
direction toward the previous path vertex (the viewer's side), and asks for
or samples ``wo``, the direction toward the light; its ``eval`` includes the
cosine ``|cos theta(wo)|`` (Mitsuba's ``diffuse``: ``reflectance / pi *
cos_theta(wo)``). paperbsdf's ``f(wi, wo)`` has ``wi`` toward the light and
no cosine. So the plugin evaluates ``f(wi = wo_mitsuba, wo = si.wi) *
|wo_mitsuba.z|``. Both are in the local frame with +z the front face's
normal; the sheet is two-sided (light and viewer on either side, reflection
and transmission). Delta lobes (a smooth face, m = 0, or an index-matched
one) are returned by ``sample`` as ``DeltaReflection``/``DeltaTransmission``
with ``pdf`` the lobe's probability; ``eval`` and ``pdf`` exclude them.

Two evaluation paths, chosen by the property ``mode``:

- ``native``: the model ported to Dr.Jit (:mod:`paperbsdf.mitsuba_native`,
  on the Rust model's own construction-time tables read by
  :mod:`paperbsdf._paper_state`), traced into Mitsuba's kernels. It runs in
  Mitsuba's default *symbolic* loops and calls in the JIT variants
  (``llvm_ad_rgb``), and also as scalar code in ``scalar_rgb``; its values
  are the Rust model's up to float32 rounding (the tests bound the relative
  difference by 2e-4). For ``paper`` and ``reduced-multilayer`` in the RGB
  variants.
- ``exact``: the Rust model itself. In a scalar variant one call into Rust
  per direction; in a JIT variant one call per wavefront (the GIL
  released, all cores). The only path for ``slab``, ``lambert-glass`` and
  ``rough-dielectric``. In a JIT variant a wavefront must exist as data
  before it can go to native code, which needs Dr.Jit's *evaluated* loops
  and calls: creating an ``exact`` plugin in a JIT variant switches
  ``dr.JitFlag.SymbolicLoops``, ``SymbolicCalls`` and
  ``SymbolicConditionals`` off, for the whole process (:func:`register`
  itself leaves them as they are).

``mode = "auto"`` (the default) is ``native`` in the JIT variants and
``exact`` in the scalar ones, where every Dr.Jit operation of the port is a
Python call and one Rust call per direction is some 15 times faster
(README, "Speed of the plugin"); the other models are always ``exact``.
Neither path is differentiable: gradients through the model are zero (the
native path's tables are constants, its parameters not exposed).
"""

from __future__ import annotations

import json
import re
import warnings

import numpy as np

import paperbsdf as _pb

PLUGIN_NAME = "paperbsdf"
_PROPERTIES = ("params", "preset", "model", "mode", "slab_nodes")
_MODES = ("auto", "native", "exact")
#: The models the native path ports (the Paper BSDF's closed forms); `slab`,
#: the same sheet solved numerically, and the others run on the exact path.
_NATIVE_MODELS = ("paper", "reduced-multilayer")

_registered_variants: set = set()


def _np(x) -> np.ndarray:
    """A Dr.Jit value (scalar or array) as a 1-D float64 numpy array."""
    return np.atleast_1d(np.asarray(x, dtype=np.float64)).reshape(-1)


def _vec_np(v, n: int) -> np.ndarray:
    """(n, 3) float64 from a Mitsuba Vector3f (scalar or wavefront)."""
    out = np.empty((n, 3))
    out[:, 0] = _np(v.x) if n else 0.0
    out[:, 1] = _np(v.y) if n else 0.0
    out[:, 2] = _np(v.z) if n else 0.0
    return out


def _size(*vals) -> int:
    import drjit as dr

    return max(dr.width(v) for v in vals)


def _mask_np(active, n: int) -> np.ndarray:
    a = np.asarray(active, dtype=bool).reshape(-1)
    if a.size == 1 and n != 1:
        a = np.full(n, bool(a[0]))
    return a


def _valid_dirs(*ws: np.ndarray) -> np.ndarray:
    """Rows where every direction is finite and of unit length (to 1e-3:
    Mitsuba's single-precision directions)."""
    ok = np.ones(ws[0].shape[0], dtype=bool)
    for w in ws:
        with np.errstate(invalid="ignore"):
            ok &= np.all(np.isfinite(w), axis=1) & (np.abs(np.linalg.norm(w, axis=1) - 1.0) < 1e-3)
    return ok


def _unitise(w: np.ndarray, ok: np.ndarray) -> np.ndarray:
    w = np.where(ok[:, None], w, np.array([0.0, 0.0, 1.0]))
    return w / np.linalg.norm(w, axis=1)[:, None]


def _aligned(a: np.ndarray, dtype) -> np.ndarray:
    """A contiguous copy of `a` as `dtype` starting on a 64-byte boundary.
    Dr.Jit wraps numpy memory without copying and writes the pointer's
    alignment into the LLVM kernels that read it, so arrays at varying
    alignments make kernels that miss the kernel cache (and are compiled
    again, ~0.25 s each); aligned arrays keep every kernel cached."""
    a = np.asarray(a)
    item = np.dtype(dtype).itemsize
    buf = np.empty(a.size + 64 // item, dtype=dtype)
    off = (-buf.ctypes.data % 64) // item
    out = buf[off: off + a.size]
    out[...] = a.reshape(-1)
    return out


def register() -> None:
    """Registers the BSDF plugin ``"paperbsdf"`` for the current Mitsuba
    variant (call after ``mi.set_variant``; again after switching variants).
    Dr.Jit's flags are left as they are (see the module doc for the
    ``exact`` path, which switches them when such a plugin is created)."""
    import drjit as dr
    import mitsuba as mi

    variant = mi.variant()
    if variant is None:
        raise ValueError("paperbsdf.mitsuba.register(): set a Mitsuba variant first (mi.set_variant)")
    cls = _make_class(mi, dr)
    mi.register_bsdf(PLUGIN_NAME, lambda props: cls(props))
    _registered_variants.add(variant)
    _wrap_loaders(mi)


def use_evaluated_mode() -> None:
    """Switches Dr.Jit to evaluated loops, calls and conditionals, which the
    ``exact`` path needs in a JIT variant (module doc)."""
    import drjit as dr

    dr.set_flag(dr.JitFlag.SymbolicLoops, False)
    dr.set_flag(dr.JitFlag.SymbolicCalls, False)
    dr.set_flag(dr.JitFlag.SymbolicConditionals, False)


_VALUE_ERROR = re.compile(r"^ValueError: (.*)$", re.M)


def _wrap_loaders(mi) -> None:
    """Makes ``mi.load_dict``, ``mi.load_string`` and ``mi.load_file`` raise
    the plugin's ``ValueError`` (a bad property or parameter) as a
    ``ValueError``: Mitsuba's scene parser turns an exception raised by a
    Python plugin's constructor into a ``RuntimeError`` carrying its
    traceback. The message keeps Mitsuba's location ("At dictionary node ...")
    and the plugin's message. Every other error passes through unchanged.
    (These loader functions are the same for every variant, so this is done
    once.)"""
    for name in ("load_dict", "load_string", "load_file"):
        orig = getattr(mi, name)
        if getattr(orig, "_paperbsdf_wrapper", False):
            continue

        def wrapper(*args, __orig=orig, **kwargs):
            try:
                return __orig(*args, **kwargs)
            except RuntimeError as e:
                text = str(e)
                found = _VALUE_ERROR.findall(text) if f'plugin of type "{PLUGIN_NAME}"' in text else []
                if not found:
                    raise
                where = text.split(": failed to instantiate", 1)[0]
                raise ValueError(f"{where}: {PLUGIN_NAME}: {found[-1]}") from None

        wrapper._paperbsdf_wrapper = True
        wrapper.__doc__ = getattr(orig, "__doc__", None)
        wrapper.__name__ = name
        setattr(mi, name, wrapper)


def _make_class(mi, dr):
    jit = dr.is_jit_v(mi.Float)
    rgb = "_rgb" in mi.variant()
    F = mi.BSDFFlags

    def to_float(a: np.ndarray):
        return mi.Float(_aligned(a, np.float32)) if jit else float(a[0])

    def to_vec(a: np.ndarray):
        return mi.Vector3f(to_float(a[:, 0]), to_float(a[:, 1]), to_float(a[:, 2]))

    def to_spec(a: np.ndarray):
        return mi.Spectrum(to_float(a[:, 0]), to_float(a[:, 1]), to_float(a[:, 2]))

    def to_uint(a: np.ndarray):
        return mi.UInt32(_aligned(a, np.uint32)) if jit else int(a[0])

    class PaperBsdfPlugin(mi.BSDF):
        """The paperbsdf model as a Mitsuba BSDF (see the module doc)."""

        def __init__(self, props):
            mi.BSDF.__init__(self, props)
            names = [str(k) for k in props.keys()]
            for k in names:
                if k not in _PROPERTIES:
                    raise ValueError(
                        f"paperbsdf plugin: unknown property `{k}`; known properties: {', '.join(_PROPERTIES)}"
                    )
            model = props["model"] if "model" in props else "paper"
            has_params, has_preset = "params" in props, "preset" in props
            if has_params and has_preset:
                raise ValueError("paperbsdf plugin: give either `params` or `preset`, not both")
            if has_preset:
                name = props["preset"]
                if model not in _pb._PAPER_MODELS:
                    raise ValueError(f"paperbsdf plugin: `preset` needs model paper or reduced-multilayer, not `{model}`")
                params = _pb.preset(name)  # ValueError naming the preset and the known ones
            elif has_params:
                params = props["params"]
                if not isinstance(params, str):
                    raise ValueError("paperbsdf plugin: property `params` must be a string (inline JSON or a file path)")
            else:
                raise ValueError("paperbsdf plugin: give the property `params` (inline JSON or a file) or `preset`")
            mode = props["mode"] if "mode" in props else "auto"
            if mode not in _MODES:
                raise ValueError(f"paperbsdf plugin: mode `{mode}` is unknown; known modes: {', '.join(_MODES)}")
            slab_nodes = props["slab_nodes"] if "slab_nodes" in props else None
            self.model = _pb.Bsdf(model, params, slab_nodes=slab_nodes)
            self._source = params if isinstance(params, str) else json.dumps(params)
            native_ok = model in _NATIVE_MODELS and rgb and self.model._native.paper_state is not None
            if mode == "native" and not native_ok:
                raise ValueError(
                    f"paperbsdf plugin: mode `native` covers the models {', '.join(_NATIVE_MODELS)} in RGB "
                    f"variants, not model `{model}` in `{mi.variant()}`; use mode `exact`"
                )
            self._native = None
            # auto: native in the JIT variants; in a scalar variant the exact
            # path's one Rust call per direction is faster (module doc).
            if native_ok and (mode == "native" or (mode == "auto" and jit)):
                from . import mitsuba_native
                from ._paper_state import PaperStateError, paper_state

                try:
                    self._native = mitsuba_native.NativePaper(mi, dr, paper_state(self.model._native.paper_state))
                except PaperStateError as e:
                    # The core crate's layout changed under this reader: say so,
                    # and (for auto) keep rendering on the exact path.
                    if mode == "native":
                        raise
                    warnings.warn(f"paperbsdf plugin: native path unavailable ({e}); using the exact path")
            if self._native is None and jit:
                use_evaluated_mode()
            self.mode = "native" if self._native is not None else "exact"
            # Lobes: each kind (diffuse, glossy, delta) that the model has, in
            # reflection and in transmission, on both sides.
            sides = F.FrontSide | F.BackSide
            comps = []
            fl = self.model.flags
            kinds = []
            if fl & _pb.FLAG_GLOSSY:
                kinds.append((_pb.FLAG_GLOSSY, F.GlossyReflection, F.GlossyTransmission))
            if fl & _pb.FLAG_DIFFUSE:
                kinds.append((_pb.FLAG_DIFFUSE, F.DiffuseReflection, F.DiffuseTransmission))
            if fl & _pb.FLAG_SPECULAR:
                kinds.append((_pb.FLAG_SPECULAR, F.DeltaReflection, F.DeltaTransmission))
            self._lobe_index = {}
            for kind, fr, ft in kinds:
                for side_bit, flag in ((_pb.FLAG_REFLECTION, fr), (_pb.FLAG_TRANSMISSION, ft)):
                    if fl & side_bit:
                        self._lobe_index[side_bit | kind] = (len(comps), int(flag))
                        comps.append(flag | sides)
            self.m_components = comps
            flags = F.Empty
            for c in comps:
                flags = flags | c
            self.m_flags = flags

        # --- helpers -------------------------------------------------------
        def _eval_pdf_np(self, si, wo, active):
            # The exact path in a JIT variant: the wavefront to numpy and Rust.
            dr.eval(si.wi, wo, active)  # one kernel launch for all the inputs
            n = _size(si.wi, wo, active)
            wi_v = _vec_np(si.wi, n)  # toward the viewer: paperbsdf's wo
            wo_l = _vec_np(wo, n)  # toward the light: paperbsdf's wi
            ok = _mask_np(active, n) & _valid_dirs(wi_v, wo_l)
            f, pdf = self.model.eval_pdf(_unitise(wo_l, ok), _unitise(wi_v, ok))
            value = f * np.abs(wo_l[:, 2])[:, None]
            value[~ok] = 0.0
            pdf[~ok] = 0.0
            return value, pdf

        # --- the native path --------------------------------------------------
        def _native_eval_pdf(self, si, wo, active, want_f, want_pdf):
            # Mitsuba's wo (toward the light) is paperbsdf's wi; si.wi is its wo.
            f, pdf = self._native.eval_pdf(wo, si.wi, active, want_f, want_pdf)
            if want_f:
                f = f * dr.abs(wo.z)
            return f, pdf

        def _native_sample(self, si, sample1, sample2, active):
            wi, f, pdf, bits, _delta = self._native.sample(si.wi, sample1, sample2, active)
            U = mi.UInt32
            comp, stype = U(0), U(0)
            for b, (idx, flag) in self._lobe_index.items():
                hit = bits == b
                comp = dr.select(hit, U(idx), comp)
                stype = dr.select(hit, U(flag), stype)
            ok = pdf > 0.0
            bs = dr.zeros(mi.BSDFSample3f)
            bs.wo = wi
            bs.pdf = pdf
            bs.eta = mi.Float(1.0)  # air on both sides of the sheet
            bs.sampled_component = comp
            bs.sampled_type = dr.select(ok, stype, U(0))
            weight = dr.select(ok, f * (dr.abs(wi.z) / dr.select(ok, pdf, 1.0)), 0.0)
            return bs, weight

        # --- the exact path in a scalar variant: one direction per call ----
        def _scalar_eval_pdf(self, si, wo, active):
            if not active:
                return mi.Color3f(0.0), 0.0
            # paperbsdf's wi is Mitsuba's wo (toward the light), its wo is si.wi.
            (r, g, b), pdf = self.model._native.eval_pdf_one((wo.x, wo.y, wo.z), (si.wi.x, si.wi.y, si.wi.z))
            c = abs(wo.z)
            return mi.Color3f(r * c, g * c, b * c), pdf

        def _scalar_sample(self, si, sample1, sample2, active):
            bs = mi.BSDFSample3f()
            bs.eta = 1.0  # air on both sides of the sheet
            if not active:
                return bs, mi.Color3f(0.0)
            wi, pdf, bits, (r, g, b) = self.model._native.sample_one(
                (si.wi.x, si.wi.y, si.wi.z), (sample1, sample2.x, sample2.y))
            if pdf <= 0.0:
                return bs, mi.Color3f(0.0)
            idx, flag = self._lobe_index.get(bits, (0, 0))
            bs.wo = mi.Vector3f(*wi)
            bs.pdf = pdf
            bs.sampled_component = idx
            bs.sampled_type = flag
            return bs, mi.Color3f(r, g, b)

        # --- the BSDF interface ---------------------------------------------
        def eval(self, ctx, si, wo, active=True):
            if self._native is not None:
                return self._native_eval_pdf(si, wo, active, True, False)[0]
            if not jit:
                return self._scalar_eval_pdf(si, wo, active)[0]
            value, _ = self._eval_pdf_np(si, wo, active)
            return to_spec(value)

        def pdf(self, ctx, si, wo, active=True):
            if self._native is not None:
                return self._native_eval_pdf(si, wo, active, False, True)[1]
            if not jit:
                return self._scalar_eval_pdf(si, wo, active)[1]
            _, pdf = self._eval_pdf_np(si, wo, active)
            return to_float(pdf)

        def eval_pdf(self, ctx, si, wo, active=True):
            if self._native is not None:
                return self._native_eval_pdf(si, wo, active, True, True)
            if not jit:
                return self._scalar_eval_pdf(si, wo, active)
            value, pdf = self._eval_pdf_np(si, wo, active)
            return to_spec(value), to_float(pdf)

        def sample(self, ctx, si, sample1, sample2, active=True):
            if self._native is not None:
                return self._native_sample(si, sample1, sample2, active)
            if not jit:
                return self._scalar_sample(si, sample1, sample2, active)
            dr.eval(si.wi, sample1, sample2, active)
            n = _size(si.wi, sample1, sample2.x, active)
            wi_v = _vec_np(si.wi, n)
            u = np.empty((n, 3))
            u[:, 0] = _np(sample1)
            u[:, 1] = _np(sample2.x)
            u[:, 2] = _np(sample2.y)
            ok = _mask_np(active, n) & _valid_dirs(wi_v) & np.all((u >= 0.0) & (u < 1.0), axis=1)
            u[~ok] = 0.5
            wi, _f, pdf, flags, weight = self.model.sample_full(_unitise(wi_v, ok), u)
            ok &= pdf > 0.0
            weight[~ok] = 0.0
            pdf[~ok] = 0.0
            comp = np.zeros(n, dtype=np.uint32)
            stype = np.zeros(n, dtype=np.uint32)
            for bits, (idx, flag) in self._lobe_index.items():
                sel = flags == bits
                comp[sel] = idx
                stype[sel] = flag
            stype[~ok] = 0
            bs = mi.BSDFSample3f()
            bs.wo = to_vec(wi)
            bs.pdf = to_float(pdf)
            bs.eta = to_float(np.ones(n))  # air on both sides of the sheet
            bs.sampled_component = to_uint(comp)
            bs.sampled_type = to_uint(stype)
            return bs, to_spec(weight)

        def traverse(self, callback):
            pass

        def parameters_changed(self, keys):
            pass

        def to_string(self):
            return f"PaperBsdfPlugin[model={self.model.model!r}, mode={self.mode!r}, params={self._source!r}]"

    return PaperBsdfPlugin
