"""The native module's views for the Mitsuba plugin: the Paper BSDF's state
text and its reader (paperbsdf._paper_state), and the one-direction calls of
the plugin's exact path in scalar variants (Model.eval_pdf_one, sample_one)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import paperbsdf
from paperbsdf._paper_state import PaperStateError, _Tuple, paper_state, parse_debug


def test_debug_reader_syntax():
    v = parse_debug("Foo { a: 1.0, b: [1e-6, -inf, 3], c: Some(2.5), d: None, "
                    "e: Rough(Microfacet { dist: Ggx, alpha: 0.1 }), f: (1.0, -2.5e3), g: true, h: [] }")
    assert v["__type__"] == "Foo" and v["a"] == 1.0
    assert v["b"][0] == 1e-6 and v["b"][1] == -math.inf and v["b"][2] == 3.0
    assert isinstance(v["c"], _Tuple) and v["c"].name == "Some" and v["c"].items == [2.5]
    assert v["d"] == "None" and v["g"] is True and v["h"] == []
    assert v["e"].name == "Rough" and v["e"].items[0]["alpha"] == 0.1
    assert v["f"] == (1.0, -2500.0)
    with pytest.raises(PaperStateError):
        parse_debug("Foo { a: 1.0 } trailing")
    with pytest.raises(PaperStateError):
        parse_debug("Foo { a: @ }")


def test_state_of_the_presets():
    for name in ("matte", "luster", "glossy"):
        p = paperbsdf.preset(name)
        s = paper_state(paperbsdf.PaperBsdf(name)._native.paper_state)
        f, b = s.faces
        assert f.att.shape == (65,) and f.lobe.shape == (65, 2) and s.pr_tab.shape == (2, 33, 5)
        assert s.w_tab.shape == (2, 65, 3)
        assert (f.kind, f.dist, f.alpha) == ("rough", p["dist_f"], p["m_f"])
        assert (b.kind, b.dist, b.alpha) == ("rough", p["dist_b"], p["m_b"])
        assert f.n == b.n == p["eta_b"]
        # A coating on the front face when its index differs from the base's.
        if p["eta_f"] != p["eta_b"]:
            assert f.coating == pytest.approx(p["eta_b"] / p["eta_f"])
        else:
            assert f.coating is None
        assert b.coating is None
        # Energy-compensated faces have separable lobes; the lobe probabilities sum to 1.
        assert f.has_lobes and b.has_lobes
        np.testing.assert_allclose(s.pr_tab.sum(axis=2), 1.0, atol=1e-12)
        assert s.use_att and s.energy_bound and s.direct and s.kappa == 1.0
        assert 0.0 < f.att[-1] <= 1.0 and 0.0 <= f.att_dir[-1] <= f.att[-1]


def test_state_kinds_and_options():
    base = paperbsdf.preset("luster")
    s = paper_state(paperbsdf.PaperBsdf(dict(base, m_f=0.0, eta_b=1.5, eta_f=1.0, face_scattering="single"))
                    ._native.paper_state)
    assert s.faces[0].kind == "matched" and s.faces[0].coating == pytest.approx(1.5)
    assert not s.faces[1].has_lobes  # Walter's faces: no compensation lobes
    s = paper_state(paperbsdf.PaperBsdf(dict(base, m_f=0.0, m_b=0.0))._native.paper_state)
    assert [f.kind for f in s.faces] == ["smooth", "smooth"] and s.kernel == "delta"
    assert s.faces[1].exact_smooth
    s = paper_state(paperbsdf.Bsdf("reduced-multilayer", base)._native.paper_state)
    assert not s.use_att and not s.energy_bound
    assert paperbsdf.Bsdf("rough-dielectric", {"eta": 1.5, "m": 0.3, "dist": "ggx"})._native.paper_state is None


def test_state_reader_fails_loudly_on_a_changed_layout():
    text = paperbsdf.PaperBsdf("matte")._native.paper_state
    for old, new in (("att_tab:", "att_table:"), ("pr_tab:", "probs:"), ("Rgb(", "Colour(")):
        with pytest.raises(PaperStateError):
            paper_state(text.replace(old, new))


def test_one_direction_calls():
    m = paperbsdf.PaperBsdf("glossy")._native
    rng = np.random.default_rng(4)
    for _ in range(50):
        wi, wo = rng.normal(size=3), rng.normal(size=3)
        wi /= np.linalg.norm(wi)
        wo /= np.linalg.norm(wo)
        f, p = m.eval_pdf_one(tuple(wi), tuple(wo))
        np.testing.assert_array_equal(f, m.eval(wi[None], wo[None])[0])
        assert p == m.pdf(wi[None], wo[None])[0]
        u = rng.random(3)
        w1, p1, fl1, wt1 = m.sample_one(tuple(wo), tuple(u))
        w2, _f2, p2, fl2, wt2 = m.sample(wo[None], u[None])
        np.testing.assert_array_equal(w1, w2[0])
        assert p1 == p2[0] and fl1 == fl2[0]
        np.testing.assert_array_equal(wt1, wt2[0])
    zero = ((0.0, 0.0, 0.0), 0.0)
    assert m.eval_pdf_one((0.0, 0.0, 2.0), (0.0, 0.0, 1.0)) == zero  # not a unit vector
    assert m.eval_pdf_one((math.nan, 0.0, 1.0), (0.0, 0.0, 1.0)) == zero
    none = ((0.0, 0.0, 0.0), 0.0, 0, (0.0, 0.0, 0.0))
    assert m.sample_one((0.0, 0.0, 1.0), (1.0, 0.5, 0.5)) == none  # u outside [0, 1)
    assert m.sample_one((0.0, 0.0, 1.5), (0.5, 0.5, 0.5)) == none
