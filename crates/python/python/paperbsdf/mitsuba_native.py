"""The Paper BSDF in Dr.Jit: the Mitsuba plugin's ``native`` path.

A port of the Rust model's ``eval``, ``pdf`` and ``sample``
(crates/core/src/paper/eval.rs, sample.rs, face.rs, single.rs, direct.rs) to
Dr.Jit operations, so that Mitsuba traces it into its own kernels: it runs
inside Mitsuba's default *symbolic* loops and calls in the JIT variants
(``llvm_ad_rgb``), and as plain scalar code in ``scalar_rgb``. Nothing is
tabulated anew: the node tables the Rust model builds at construction (read
exactly by :mod:`paperbsdf._paper_state`) are interpolated here with the
same formulas, so the values are the Rust model's up to float32 rounding.

The formulas, by docs/design.md section (and the Rust file that has them):

- 4.1 and 4.3 surface reflection of the lit face (face.rs): Walter's rough
  dielectric lobe ``F(o.h) D G1 G1 / (4 |i.z| |o.z|)`` (GGX; Beckmann with
  Walter's rational ``G1`` in values and the exact Smith ``Lambda`` in the
  visible-normal density, as crates/core/src/microfacet.rs), plus the
  separable lobes of the energy compensation and of a coating
  ``sum_j (sqrt(c_j) E_j(mu_i)) (sqrt(c_j) E_j(mu_o))``; a delta lobe
  (weight ``r_out``) for a face without microfacets;
- 4.4 single scattering (single.rs): ``albedo Att_e Att_x p(t_i.t_o) /
  eta_x^2`` times the depth integrals of Hanrahan & Krueger, with the
  two-lobe Henyey-Greenstein phase function (4.2) between the inside
  directions refracted through the macro normal;
- 4.5 multiple scattering (mod.rs): ``ms_r(e) W_e(mu_i) W_e(mu_o)`` in
  reflection, ``ms_t W_e(mu_i) W_x(mu_o)`` in transmission (the energy
  closing form; the reduced multilayer model's multipole normalisation
  ``c Att Att``, 4.7);
- 4.6 direct transmission (direct.rs): ``Att_dir,e Att_dir,x k(|p_o - p_i|)
  e^{-tau / min(mu_i, mu_o)}`` with the GGX or Gaussian slope kernel, or its
  delta lobe;
- sampling (sample.rs): the lobe chosen by the model's tabulated
  probabilities, then visible normals (Mitsuba's
  ``MicrofacetDistribution``), the phase function refracted out, cosine
  lobes, the kernel; the density is the full mixture, as in Rust.

Every table lookup is the Rust model's linear interpolation in
``t = sqrt(|cos|)`` on the same nodes. Conventions (Mitsuba's ``si.wi`` is
paperbsdf's ``wo``) are those of :mod:`paperbsdf.mitsuba`; this module works
in paperbsdf's: ``wi`` toward the light, ``wo`` toward the viewer, no cosine.
"""

from __future__ import annotations

import math

import numpy as np

from ._paper_state import PaperState

#: Cosine below which a direction lies in the sheet's plane (the Rust model's GRAZING_COS).
GRAZING_COS = 1e-12
#: Optical thickness beyond which the Rust model drops exponentials (TAU_DROP).
TAU_DROP = 40.0
#: Below this argument ``1 - e^{-x}`` is taken from its series (float32 has
#: no expm1): the series' error ``x^4 / 24`` is below float32 rounding there.
_SERIES_X = 1e-3

# paperbsdf's BsdfFlags bits (crates/python/src/lib.rs `Model.flags`).
_R, _T, _DIFFUSE, _GLOSSY, _SPECULAR = 1, 2, 4, 8, 16
# The lobes of the sampler, in the order of the Rust model's LobeProbs.
_SURFACE, _SINGLE, _MULT_R, _MULT_T, _DIRECT = range(5)


class NativePaper:
    """The Paper BSDF of a :class:`PaperState` as Dr.Jit code for the current
    Mitsuba variant (``mi``, ``dr`` its modules)."""

    def __init__(self, mi, dr, state: PaperState):
        self.mi, self.dr, self.s = mi, dr, state
        s = state
        f0, f1 = s.faces
        self.na = f0.att.shape[0]
        self.np_ = s.pr_tab.shape[1]
        self.jit = dr.is_jit_v(mi.Float)
        buf = self._buffer
        self.t_att = buf(np.stack([f0.att, f1.att]))
        self.t_att_dir = buf(np.stack([f0.att_dir, f1.att_dir]))
        self.t_r = buf(np.stack([f0.r, f1.r]))
        self.t_lobe = buf(np.stack([f0.lobe, f1.lobe]))
        self.t_w = buf(s.w_tab)
        self.t_pr = buf(s.pr_tab)
        self.any_lobes = f0.has_lobes or f1.has_lobes
        self.rough = [f.kind == "rough" for f in s.faces]
        # One microfacet family for both faces when they agree (one code path
        # with a per-lane roughness), else both, selected per side.
        dists = {f.dist for f in s.faces if f.kind == "rough"}
        self.dists = sorted(dists)
        # Mitsuba's visible-normal samplers of those families.
        kinds = {"ggx": mi.MicrofacetType.GGX, "beckmann": mi.MicrofacetType.Beckmann}
        self.mf_types = {d: kinds[d] for d in self.dists}
        self.kernel_delta = s.kernel == "delta"
        self.phase_on = s.phase_weight > 0.0

    # --- plumbing ---------------------------------------------------------
    def _buffer(self, a: np.ndarray):
        """A flat table as a Dr.Jit array that `dr.gather` reads (float32 in
        JIT variants); in scalar variants a list of Python floats, the Rust
        model's float64 values unrounded. Built from a list, so Dr.Jit
        copies it into memory of its own (an array made from numpy memory
        may wrap it, and the kernels would then depend on its address's
        alignment; see `paperbsdf.mitsuba._aligned`)."""
        values = [float(v) for v in np.asarray(a, dtype=np.float64).reshape(-1)]
        if self.jit:
            return self.mi.Float(values)
        return values

    def _not(self, m):
        """Logical not of a mask (a Python bool in scalar variants, where `~` is not)."""
        return ~m if self.jit else not m

    def _c3(self, a):
        """A colour constant from 3 numbers."""
        return self.mi.Color3f(*[float(x) for x in a])

    def _gather(self, tp, buf, idx, active=True):
        """`dr.gather` (JIT variants); in scalar variants an index into the
        Python list (Dr.Jit's scalar gather takes no nested types)."""
        if self.jit:
            return self.dr.gather(tp, buf, idx, active)
        if not active:
            return tp(0.0)
        mi = self.mi
        if tp is mi.Float:
            return buf[idx]
        w = 2 if tp is mi.Vector2f else 3
        return tp(*buf[w * idx: w * idx + w])

    def _sel2(self, front, a, b):
        """Per lane: `a` on the front face (side 0), `b` on the back."""
        if isinstance(a, float) and isinstance(b, float) and a == b:
            return self.mi.Float(a)
        return self.dr.select(front, a, b)

    def _pos(self, st, n: int):
        """The node interval `i` and fraction `f` of `st` on an `n`-node table
        (tables.rs `node_at`)."""
        mi, dr = self.mi, self.dr
        x = st * (n - 1)
        i = dr.clip(mi.Int32(x), 0, n - 2)
        return mi.UInt32(i), x - mi.Float(i)

    def _lerp(self, buf, side, pos, n: int, width: int = 1, tp=None, active=True):
        """Linear interpolation of table `buf` (2 sides x `n` nodes x `width`)
        at the place `pos` on side `side` (0 front, 1 back)."""
        i, f = pos
        base = side * n + i
        tp = tp or self.mi.Float
        a = self._gather(tp, buf, base, active)
        b = self._gather(tp, buf, base + 1, active)
        return a * (1.0 - f) + b * f

    # --- Fresnel (crates/core/src/fresnel.rs) -----------------------------
    def _fresnel_cos(self, ci, ct, eta):
        ns, ds = ci - eta * ct, ci + eta * ct
        np_, dp = ct - eta * ci, ct + eta * ci
        ds2, dp2 = ds * ds, dp * dp
        return 0.5 * (ns * ns * dp2 + np_ * np_ * ds2) / (ds2 * dp2)

    def _fresnel_t(self, cos_i, eta: float):
        """`1 - fresnel_dielectric(cos_i, eta)` for light from outside
        (`cos_i >= 0`), without the cancellation of `1 - F` near grazing
        (where F -> 1): `1 - r_s^2 = 4 eta c_i c_t / d_s^2` and likewise for
        `p`, so `T = 2 eta c_i c_t (1 / d_s^2 + 1 / d_p^2)`."""
        dr = self.dr
        if eta == 1.0:
            return self.mi.Float(1.0)
        c = dr.minimum(dr.abs(cos_i), 1.0)
        ct = dr.safe_sqrt(1.0 - (1.0 - c * c) / (eta * eta))
        ds, dp = c + eta * ct, ct + eta * c
        return 2.0 * eta * c * ct * (1.0 / (ds * ds) + 1.0 / (dp * dp))

    def _fresnel(self, cos_i, eta: float):
        """`fresnel_dielectric(cos_i, eta)`: unpolarised reflectance, light
        from outside for `cos_i >= 0`, from inside otherwise."""
        dr = self.dr
        if eta == 1.0:
            return self.mi.Float(0.0)
        out = cos_i >= 0
        eta_it = dr.select(out, eta, 1.0 / eta)
        c = dr.minimum(dr.abs(cos_i), 1.0)
        sin2_t = (1.0 - c * c) / (eta_it * eta_it)
        r = self._fresnel_cos(c, dr.safe_sqrt(1.0 - sin2_t), eta_it)
        return dr.select((sin2_t >= 1.0) | (c == 0.0), 1.0, r)

    # --- the faces (face.rs) ----------------------------------------------
    def _face_table(self, buf, side, front, pos, st, kind: str):
        """`Att` (`kind = "att"`), its collimated part (`"att_dir"`) or the
        outside reflectance (`"r"`) of the face on `side` at the place `pos`
        (`st = sqrt(|cos|)`), with the exact-Fresnel faces and `use_att`."""
        dr = self.dr
        v = self._lerp(buf, side, pos, self.na)
        for k, face in enumerate(self.s.faces):
            on = front if k == 0 else self._not(front)
            if kind != "r" and not face.use_att:
                v = dr.select(on, 1.0, v)
            elif face.exact_smooth:
                mu = st * st
                v = dr.select(on, self._fresnel(mu, face.eta) if kind == "r" else self._fresnel_t(mu, face.eta), v)
        return v

    def _inside_cos(self, mu, inv_n2):
        return self.dr.safe_sqrt(1.0 - (1.0 - mu * mu) * inv_n2)

    def _beckmann_g1_ratio(self, c, alpha):
        dr = self.dr
        s2 = dr.maximum(1.0 - c * c, 0.0)
        a = c / (alpha * dr.maximum(dr.sqrt(s2), 1e-30))
        n = 3.535 * a + 2.181 * a * a
        q = 1.0 + 2.276 * a + 2.577 * a * a
        one = (s2 == 0.0) | (a >= 1.6)
        return dr.select(one, 1.0, n), dr.select(one, 1.0, q), dr.select(s2 == 0.0, math.inf, a)

    def _beckmann_lambda_a(self, a):
        dr = self.dr
        ac = dr.minimum(a, 6.0)
        lam = 0.5 * (dr.erf(ac) - 1.0) + dr.exp(-ac * ac) / (2.0 * ac * math.sqrt(math.pi))
        return dr.select(a >= 6.0, 0.0, lam)

    def _walter(self, dist: str, alpha, eta, inv_eta2, c2, oh2, ci, co, want_pdf: bool):
        """Walter's reflection `F D G1 G1 / (4 ci co)` and (if `want_pdf`) the
        visible-normal density of the reflected direction (microfacet.rs
        `reflection_dg_pdf_c2`, face.rs `fresnel_outside_sq`)."""
        dr = self.dr
        ok = (c2 > 0.0) & (ci > 0.0) & (co > 0.0)
        c2 = dr.minimum(c2, 1.0)
        ci, co = dr.minimum(ci, 1.0), dr.minimum(co, 1.0)
        a2 = alpha * alpha
        if dist == "ggx":
            t = c2 * (a2 - 1.0) + 1.0
            si = dr.sqrt(a2 + (1.0 - a2) * ci * ci)
            so = dr.sqrt(a2 + (1.0 - a2) * co * co)
            dg = a2 / (math.pi * t * t * (ci + si) * (co + so))
            pdf = 0.5 * dg * (ci + si) if want_pdf else None
        else:
            inv_c2 = 1.0 / dr.maximum(c2, 1e-30)
            x = -dr.maximum(1.0 - c2, 0.0) * inv_c2 / a2
            d = dr.exp(x) * inv_c2 * inv_c2
            ni, qi, _ = self._beckmann_g1_ratio(ci, alpha)
            no, qo, ao = self._beckmann_g1_ratio(co, alpha)
            pi_a2 = math.pi * a2
            dg = d * (ni * no) / (pi_a2 * (4.0 * ci * co * qi * qo))
            pdf = d / (pi_a2 * 4.0 * co * (1.0 + self._beckmann_lambda_a(ao))) if want_pdf else None
        c2o = dr.minimum(oh2, 1.0)
        cos_t = dr.safe_sqrt(1.0 - (1.0 - c2o) * inv_eta2)
        fr = dr.select(eta == 1.0, 0.0, self._fresnel_cos(dr.sqrt(c2o), cos_t, eta))
        f = dr.select(ok, fr * dg, 0.0)
        if want_pdf:
            pdf = dr.select(ok, pdf, 0.0)
        return f, pdf

    def _surface(self, wi_l, wo_l, side, front, pos_i, pos_o, want_pdf: bool, active):
        """The lit face's reflection (both directions in its frame, above it):
        `(f, pdf)` of Walter's lobe plus the separable lobes (`pdf` the
        visible-normal density; both zero for a face without microfacets)."""
        mi, dr = self.mi, self.dr
        s = self.s
        f = mi.Float(0.0)
        pdf = mi.Float(0.0)
        if any(self.rough):
            # k = 1 + wi.wo as |wi + wo|^2 / 2 (equal for unit vectors): no
            # cancellation in float32 for the nearly opposite directions of a
            # grazing mirror pair, where 1 + wi.wo is small.
            hv = wi_l + wo_l
            k = 0.5 * dr.dot(hv, hv)
            zs = hv.z
            ok = active & (wi_l.z > 0.0) & (wo_l.z > 0.0) & (k > 0.0)
            kk = dr.select(ok, k, 1.0)
            c2 = zs * zs / (2.0 * kk)
            oh2 = 0.5 * kk
            f0, f1 = s.faces
            par = [(f0.alpha, f0.eta, f0.inv_eta2), (f1.alpha, f1.eta, f1.inv_eta2)]
            for dist in self.dists:
                uses = [fc.kind == "rough" and fc.dist == dist for fc in s.faces]
                # A face of the other family (or without microfacets) lends the
                # parameters of this one: its lanes are masked out below.
                p0 = par[0] if uses[0] else par[1]
                p1 = par[1] if uses[1] else par[0]
                alpha = self._sel2(front, p0[0], p1[0])
                eta = self._sel2(front, p0[1], p1[1])
                inv_eta2 = self._sel2(front, p0[2], p1[2])
                fw, pw = self._walter(dist, alpha, eta, inv_eta2, c2, oh2, wi_l.z, wo_l.z, want_pdf)
                on = ok if all(uses) else (ok & front if uses[0] else ok & self._not(front))
                f = dr.select(on, fw, f)
                if want_pdf:
                    pdf = dr.select(on, pw, pdf)
            if self.any_lobes:
                li = self._lerp(self.t_lobe, side, pos_i, self.na, tp=mi.Vector2f, active=active)
                lo = self._lerp(self.t_lobe, side, pos_o, self.na, tp=mi.Vector2f, active=active)
                f = f + dr.select(ok, li.x * lo.x + li.y * lo.y, 0.0)
        return f, pdf

    # --- eval and pdf (eval.rs) -------------------------------------------
    def _geometry(self, wi, wo, active):
        """What eval and pdf share: sides, table places, inside cosines and
        directions, per-lane face constants."""
        mi, dr = self.mi, self.dr
        s = self.s
        g = {}
        ok = active & (dr.abs(wi.z) >= GRAZING_COS) & (dr.abs(wo.z) >= GRAZING_COS)
        g["ok"] = ok
        fe = wi.z > 0.0  # light at the front face
        fx = wo.z > 0.0
        g["fe"], g["fx"] = fe, fx
        g["e"] = mi.UInt32(dr.select(fe, 0, 1))
        g["x"] = mi.UInt32(dr.select(fx, 0, 1))
        g["reflect"] = fe == fx
        ai, ao = dr.abs(wi.z), dr.abs(wo.z)
        g["ai"], g["ao"] = ai, ao
        sti, sto = dr.sqrt(dr.minimum(ai, 1.0)), dr.sqrt(dr.minimum(ao, 1.0))
        g["sti"], g["sto"] = sti, sto
        g["pi"], g["po"] = self._pos(sti, self.na), self._pos(sto, self.na)
        f0, f1 = s.faces
        inv_n_e = self._sel2(fe, f0.inv_n, f1.inv_n)
        inv_n_x = self._sel2(fx, f0.inv_n, f1.inv_n)
        inv_n2_e = self._sel2(fe, f0.inv_n2, f1.inv_n2)
        inv_n2_x = self._sel2(fx, f0.inv_n2, f1.inv_n2)
        g["inv_n2_e"], g["inv_n2_x"] = inv_n2_e, inv_n2_x
        mu_i = self._inside_cos(ai, inv_n2_e)
        mu_o = self._inside_cos(ao, inv_n2_x)
        g["mu_i"], g["mu_o"] = mu_i, mu_o
        # |p_o - p_i|^2 of the direct kernel, p_i = -(wi.x, wi.y), p_o = (wo.x, wo.y).
        g["r2"] = dr.square(wo.x + wi.x) + dr.square(wo.y + wi.y)
        if self.phase_on:
            t_i = mi.Vector3f(-wi.x * inv_n_e, -wi.y * inv_n_e, dr.select(fe, -mu_i, mu_i))
            t_o = mi.Vector3f(wo.x * inv_n_x, wo.y * inv_n_x, dr.select(fx, mu_o, -mu_o))
            cos = dr.clip(dr.dot(t_i, t_o), -1.0, 1.0)
            (k0, a0, b0), (k1, a1, b1) = s.phase_coef
            q0, q1 = a0 - b0 * cos, a1 - b1 * cos
            d0, d1 = q0 * dr.sqrt(q0), q1 * dr.sqrt(q1)
            g["p_num"], g["p_den"] = k0 * d1 + k1 * d0, d0 * d1
        return g

    def eval_pdf(self, wi, wo, active, want_f: bool = True, want_pdf: bool = True):
        """`(f, pdf)` of the Rust model (`f` an RGB colour without cosine,
        delta lobes excluded; `pdf` the sampler's mixture density of `wi`
        given `wo`); zero where not `active` or at grazing."""
        mi, dr = self.mi, self.dr
        s = self.s
        g = self._geometry(wi, wo, active)
        if not self.jit and not g["ok"]:
            return (mi.Color3f(0.0) if want_f else None), (mi.Float(0.0) if want_pdf else None)
        ok, fe, fx, e, x, reflect = g["ok"], g["fe"], g["fx"], g["e"], g["x"], g["reflect"]
        pi_, po = g["pi"], g["po"]
        mu_i, mu_o = g["mu_i"], g["mu_o"]
        # The lit face's frame: z flipped on the back.
        flip = dr.select(fx, 1.0, -1.0)
        wi_l = mi.Vector3f(wi.x, wi.y, wi.z * flip)
        wo_l = mi.Vector3f(wo.x, wo.y, wo.z * flip)
        surf_f, surf_pdf = self._surface(wi_l, wo_l, x, fx, pi_, po, want_pdf, ok & reflect)
        f = None
        if want_f:
            out = mi.Color3f(dr.select(ok & reflect, surf_f, 0.0))
            if s.energy_bound:
                we = self._lerp(self.t_w, e, pi_, self.na, tp=mi.Color3f, active=ok)
                wx = self._lerp(self.t_w, x, po, self.na, tp=mi.Color3f, active=ok)
                ms_r = dr.select(fe, self._c3(s.ms_r[0]), self._c3(s.ms_r[1]))
                c = dr.select(reflect, ms_r, self._c3(s.ms_t))
                sub = c * we * wx
            else:
                att_e0 = self._face_table(self.t_att, e, fe, pi_, g["sti"], "att")
                att_x0 = self._face_table(self.t_att, x, fx, po, g["sto"], "att")
                c_r = dr.select(fe, self._c3(s.c_r[0]), self._c3(s.c_r[1]))
                c_t = dr.select(fe, self._c3(s.c_t[0]), self._c3(s.c_t[1]))
                sub = dr.select(reflect, c_r, c_t) * (att_e0 * att_x0)
            att_e = self._face_table(self.t_att, e, fe, pi_, g["sti"], "att")
            att_x = self._face_table(self.t_att, x, fx, po, g["sto"], "att")
            att = att_e * att_x
            inner = ok & (att > 0.0) & (mu_i > 0.0) & (mu_o > 0.0)
            tau = self._c3(s.tau)
            if self.phase_on:
                p_num, p_den = g["p_num"], g["p_den"]
                ka = att * p_num * g["inv_n2_x"]
                k = ka / p_den
                alb = self._c3(s.albedo)
                # Reflection: (1 - e^{-tau (1/mu_i + 1/mu_o)}) / (mu_i + mu_o).
                ssum = mu_i + mu_o
                xr = tau * (ssum / (mu_i * mu_o))
                one_m = dr.select(xr < _SERIES_X, xr * (1.0 - xr * (0.5 - xr / 6.0)), 1.0 - dr.exp(-xr))
                thick_r = s.tau_min * ssum > TAU_DROP * mu_i * mu_o
                dep_r = dr.select(thick_r, 1.0, one_m) / ssum
                # Transmission: tau e^{-tau / max(mu)} h(tau |1/mu_i - 1/mu_o|) / (mu_i mu_o).
                a, b = 1.0 / mu_i, 1.0 / mu_o
                xt = tau * dr.abs(a - b)
                h = dr.select(xt < _SERIES_X, 1.0 - xt * (0.5 - xt / 6.0),
                              (1.0 - dr.exp(-xt)) / dr.maximum(xt, _SERIES_X))
                dep_t = tau * dr.exp(-tau * dr.minimum(a, b)) * h / (mu_i * mu_o)
                thick_t = s.tau_min > TAU_DROP * dr.maximum(mu_i, mu_o)
                dep_t = dr.select(thick_t, 0.0, dep_t)
                single = alb * k * dr.select(reflect, dep_r, dep_t)
                sub = sub + dr.select(inner & (p_num > 0.0), single, 0.0)
            if s.direct and not self.kernel_delta:
                mu_min = dr.minimum(mu_i, mu_o)
                kv = self._kernel(g["r2"])
                kv = dr.select(s.tau_min > TAU_DROP * mu_min, 0.0, kv)
                ad_e = self._face_table(self.t_att_dir, e, fe, pi_, g["sti"], "att_dir")
                ad_x = self._face_table(self.t_att_dir, x, fx, po, g["sto"], "att_dir")
                direct = dr.exp(-tau / mu_min) * (ad_e * ad_x * kv)
                sub = sub + dr.select(inner & self._not(reflect) & (kv > 0.0), direct, 0.0)
            f = out + sub * s.kappa
            f = dr.select(ok, f, 0.0)
        pdf = None
        if want_pdf:
            pdf = self._pdf(wi, g, surf_pdf)
        return f, pdf

    def _kernel(self, r2):
        """The direct kernel `k(r)` per unit projected area (direct.rs)."""
        dr = self.dr
        b2 = self.s.kernel_beta ** 2
        if self.s.kernel == "ggx":
            t = r2 + b2
            return b2 / (math.pi * t * t)
        return dr.exp(-r2 / b2) / (math.pi * b2)

    def _probs(self, g):
        """The lobe-selection probabilities for viewer `wo` (eval.rs `lobe_probs`)."""
        mi = self.mi
        i, f = self._pos(g["sto"], self.np_)
        base = (g["x"] * self.np_ + i) * 5
        out = []
        for k in range(5):
            a = self._gather(mi.Float, self.t_pr, base + k, g["ok"])
            b = self._gather(mi.Float, self.t_pr, base + 5 + k, g["ok"])
            out.append(a * (1.0 - f) + b * f)
        return out

    def _pdf(self, wi, g, surf_pdf, pr=None):
        """The sampler's mixture density (eval.rs `pdf_with`)."""
        dr = self.dr
        s = self.s
        pr = pr or self._probs(g)
        reflect = g["reflect"]
        cos_pi = g["ai"] / math.pi
        pdf = dr.select(reflect, pr[_SURFACE] * surf_pdf + pr[_MULT_R] * cos_pi, pr[_MULT_T] * cos_pi)
        if not self.kernel_delta:
            # The kernel's density for wi (ratio 1): k(|p_o - p_i|) |wi.z|.
            pdf = pdf + dr.select(self._not(reflect), pr[_DIRECT] * self._kernel(g["r2"]) * g["ai"], 0.0)
        if self.phase_on:
            ps = g["p_num"] * g["ai"] * g["inv_n2_e"] / (g["p_den"] * s.phase_weight * g["mu_i"])
            pdf = pdf + dr.select(g["mu_i"] > 0.0, pr[_SINGLE] * ps, 0.0)
        return dr.select(g["ok"], pdf, 0.0)

    # --- sample (sample.rs) -----------------------------------------------
    def _r_in_delta(self, k: int, mu_b):
        """Reflectance from inside the base of face `k` without microfacets
        (face.rs `r_in_delta`)."""
        dr, mi = self.dr, self.mi
        face = self.s.faces[k]

        def r_face(mu_c):
            return mi.Float(0.0) if face.kind == "matched" else self._fresnel(-mu_c, face.eta)

        if face.coating is None:
            return r_face(mu_b)
        nu = face.coating
        s2 = (1.0 - mu_b * mu_b) * nu * nu
        mu_c = dr.safe_sqrt(1.0 - s2)
        fs = self._fresnel(mu_c, nu)
        r = r_face(mu_c)
        denom = 1.0 - fs * r
        v = fs + (1.0 - fs) * (1.0 - fs) * r / dr.select(denom > 0.0, denom, 1.0)
        return dr.select((s2 >= 1.0) | (denom <= 0.0), 1.0, v)

    def _direct_delta_weight(self, wi, wo, fe, fx, e, x):
        """Weight of the delta direct lobe (eval.rs `direct_delta_weight`)."""
        dr = self.dr
        s = self.s
        f0, f1 = s.faces
        ai, ao = dr.abs(wi.z), dr.abs(wo.z)
        sti, sto = dr.sqrt(dr.minimum(ai, 1.0)), dr.sqrt(dr.minimum(ao, 1.0))
        mu = self._inside_cos(ai, self._sel2(fe, f0.inv_n2, f1.inv_n2))
        t = (self._face_table(self.t_att, e, fe, self._pos(sti, self.na), sti, "att")
             * self._face_table(self.t_att, x, fx, self._pos(sto, self.na), sto, "att"))
        if s.use_att:
            mu_x = self._inside_cos(ao, self._sel2(fx, f0.inv_n2, f1.inv_n2))
            r = (dr.select(fe, self._r_in_delta(0, mu), self._r_in_delta(1, mu))
                 * dr.select(fx, self._r_in_delta(0, mu_x), self._r_in_delta(1, mu_x)))
        else:
            r = 0.0
        a = dr.exp(-self._c3(s.tau) / dr.maximum(mu, 1e-30))
        w = t * a / (1.0 - r * a * a) * s.kappa
        return dr.select(mu > 0.0, w, 0.0)

    def sample(self, wo, uc, u, active):
        """Draws `wi` for viewer `wo` (sample.rs): returns `(wi, f, pdf,
        bits, delta)` with `f` the model's value at `wi` (for a delta lobe its
        weight over `|wi.z|`), `pdf` the mixture density (a delta lobe's
        probability), `bits` paperbsdf's flag bits of the sampled lobe, and
        `delta` whether it is a delta lobe; `pdf = 0` where nothing was drawn."""
        mi, dr = self.mi, self.dr
        s = self.s
        f0, f1 = s.faces
        ok = active & (dr.abs(wo.z) >= GRAZING_COS)
        if not self.jit and not ok:
            return mi.Vector3f(0.0, 0.0, 1.0), mi.Color3f(0.0), mi.Float(0.0), 0, False
        fx = wo.z > 0.0
        x = mi.UInt32(dr.select(fx, 0, 1))
        sx = dr.select(fx, 1.0, -1.0)
        ao = dr.abs(wo.z)
        sto = dr.sqrt(dr.minimum(ao, 1.0))
        pr = self._probs({"sto": sto, "x": x, "ok": ok})
        # select_lobe (crates/core/src/bsdf.rs): the first lobe whose
        # cumulative probability exceeds uc; past the total, the last present.
        lobe = mi.UInt32(0)
        acc = mi.Float(0.0)
        cum = mi.Float(0.0)
        for k in range(4):
            cum = cum + pr[k]
            past = uc >= cum
            lobe = dr.select(past, mi.UInt32(k + 1), lobe)
            acc = dr.select(past, cum, acc)
        last = mi.UInt32(0)
        for k in range(5):
            last = dr.select(pr[k] > 0.0, mi.UInt32(k), last)
        p_lobe = mi.Float(0.0)
        for k in range(5):
            p_lobe = dr.select(lobe == k, pr[k], p_lobe)
        fallback = p_lobe <= 0.0
        lobe = dr.select(fallback, last, lobe)
        acc_last = mi.Float(0.0)
        for k in range(4):
            acc_last = acc_last + dr.select(last > k, pr[k], 0.0)
        acc = dr.select(fallback, acc_last, acc)
        p_lobe = mi.Float(0.0)
        for k in range(5):
            p_lobe = dr.select(lobe == k, pr[k], p_lobe)
        ok &= p_lobe > 0.0

        # Surface: visible normals of the face on the viewer's side (its frame: z flipped on the back).
        wo_l = mi.Vector3f(wo.x, wo.y, wo.z * sx)
        wi_surf = mi.Vector3f(-wo.x, -wo.y, wo.z)  # the mirror direction (a smooth face's delta)
        rough_x = self._sel_bool(fx, self.rough[0], self.rough[1])
        for dist, mtype in self.mf_types.items():
            uses = [fc.kind == "rough" and fc.dist == dist for fc in s.faces]
            a0 = f0.alpha if uses[0] else f1.alpha
            a1 = f1.alpha if uses[1] else f0.alpha
            md = mi.MicrofacetDistribution(mtype, self._sel2(fx, a0, a1), True)
            h, _ = md.sample(wo_l, u)
            oh = dr.dot(wo_l, h)
            wl = 2.0 * oh * h - wo_l
            wl = dr.select((oh > 0.0) & (wl.z > 0.0), wl, mi.Vector3f(0.0, 0.0, 0.0))
            on = True if all(uses) else (fx if uses[0] else self._not(fx))
            wi_surf = dr.select(on, mi.Vector3f(wl.x, wl.y, wl.z * sx), wi_surf)

        # Single scattering: the phase function around the inside viewer direction, refracted out.
        wi_single = mi.Vector3f(0.0, 0.0, 0.0)
        if self.phase_on:
            inv_n_x = self._sel2(fx, f0.inv_n, f1.inv_n)
            mu_o = self._inside_cos(ao, self._sel2(fx, f0.inv_n2, f1.inv_n2))
            t_o = mi.Vector3f(wo.x * inv_n_x, wo.y * inv_n_x, sx * mu_o)
            ucr = dr.clip((uc - acc) / dr.select(p_lobe > 0.0, p_lobe, 1.0), 0.0, 1.0 - 2.0 ** -24)
            (g0, w0), (g1, _) = s.phase_lobes
            g = dr.select(ucr * s.phase_weight < w0, g0, g1)
            gs = dr.select(dr.abs(g) < 1e-3, 1.0, g)
            sq = (1.0 - gs * gs) / (1.0 + gs - 2.0 * gs * u.x)
            cos = dr.clip((1.0 + gs * gs - sq * sq) / (2.0 * gs), -1.0, 1.0)
            cos = dr.select(dr.abs(g) < 1e-3, 1.0 - 2.0 * u.x, cos)
            sin = dr.safe_sqrt(1.0 - cos * cos)
            sp, cp = dr.sincos(2.0 * math.pi * u.y)
            t_i = dr.normalize(mi.Frame3f(t_o).to_world(mi.Vector3f(sin * cp, sin * sp, cos)))
            # Light propagating down (t_i.z < 0) came in through the front face.
            n = f0.n  # the base's index (both faces refract into the same base)
            wt = mi.Vector2f(-t_i.x * n, -t_i.y * n)
            r2 = dr.squared_norm(wt)
            z = dr.safe_sqrt(1.0 - r2)
            wi_single = mi.Vector3f(wt.x, wt.y, dr.select(t_i.z < 0.0, z, -z))
            wi_single = dr.select((r2 < 1.0) & (t_i.z != 0.0), wi_single, mi.Vector3f(0.0, 0.0, 0.0))

        # Multiple scattering: cosine lobes on the viewer's side (R) or the other (T).
        c = mi.warp.square_to_cosine_hemisphere(u)
        wi_mult = mi.Vector3f(c.x, c.y, dr.select(lobe == _MULT_R, sx, -sx) * c.z)

        # Direct transmission: the kernel around the straight-through direction (or its delta).
        wi_direct = mi.Vector3f(-wo.x, -wo.y, -wo.z)
        if not self.kernel_delta:
            b = s.kernel_beta
            if s.kernel == "ggx":
                rad = b * dr.sqrt(u.x / dr.maximum(1.0 - u.x, 1e-30))
            else:
                rad = b * dr.safe_sqrt(-dr.log(dr.maximum(1.0 - u.x, 1e-30)))
            sp, cp = dr.sincos(2.0 * math.pi * u.y)
            p_i = mi.Vector2f(wo.x - rad * cp, wo.y - rad * sp)
            r2 = dr.squared_norm(p_i)
            wi_k = mi.Vector3f(-p_i.x, -p_i.y, -sx * dr.safe_sqrt(1.0 - r2))
            wi_direct = dr.select(r2 < 1.0, wi_k, mi.Vector3f(0.0, 0.0, 0.0))

        wi = dr.select(lobe == _SURFACE, wi_surf,
                       dr.select(lobe == _SINGLE, wi_single,
                                 dr.select(lobe == _DIRECT, wi_direct, wi_mult)))
        ok &= dr.abs(wi.z) >= GRAZING_COS
        delta_s = (lobe == _SURFACE) & self._not(rough_x)
        delta_d = (lobe == _DIRECT) if self.kernel_delta else False
        delta = delta_s | delta_d
        f, pdf = self.eval_pdf(wi, wo, ok & self._not(delta))
        ok_c = ok & self._not(delta) & (pdf > 0.0) & dr.isfinite(pdf)
        # The delta lobes: weight / |wi.z| as f, the lobe's probability as pdf.
        if any(not r for r in self.rough):
            r_out = self._face_table(self.t_r, x, fx, self._pos(sto, self.na), sto, "r")
            f = dr.select(delta_s, mi.Color3f(r_out / dr.maximum(ao, GRAZING_COS)), f)
        if self.kernel_delta and s.direct:
            fe = self._not(fx)
            dd = self._direct_delta_weight(wi, wo, fe, fx, mi.UInt32(dr.select(fe, 0, 1)), x)
            f = dr.select(delta_d, dd / dr.maximum(dr.abs(wi.z), GRAZING_COS), f)
        ok = ok_c | (ok & delta)
        pdf = dr.select(delta, p_lobe, pdf)
        reflect = wi.z * wo.z > 0.0
        U = mi.UInt32
        kind = dr.select(delta, U(_SPECULAR),
                         dr.select((lobe == _SURFACE) | (lobe == _DIRECT), U(_GLOSSY), U(_DIFFUSE)))
        bits = kind | dr.select(reflect, U(_R), U(_T))
        return wi, dr.select(ok, f, 0.0), dr.select(ok, pdf, 0.0), bits, delta

    def _sel_bool(self, front, a: bool, b: bool):
        if a == b:
            return self.mi.Bool(a)
        return front if a else self._not(front)
