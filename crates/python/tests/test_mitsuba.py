"""The Mitsuba 3 plugin: conventions, chi-square, furnace, errors.

- the direction mapping (Mitsuba's si.wi is paperbsdf's wo, Mitsuba's wo is
  paperbsdf's wi) and the cosine: plugin eval must equal f(wo_m, si.wi) *
  |cos wo_m| at pairs with very unequal polar angles, so that a swap of the
  directions or a cosine of the wrong one fails by a factor of 5 or more;
- sample returns a direction toward the light whose side and weight agree
  with eval/pdf, and pdf equals the plugin's pdf for that direction;
- Mitsuba's own chi-square test (mitsuba.chi2 with its BSDF adapter) of the
  matte, luster and glossy presets from both sides (llvm_ad_rgb, the default
  native path in Mitsuba's symbolic mode; it does not run in scalar_rgb);
- a white furnace: a sphere of non-absorbing paper in a uniform environment of
  radiance 1 renders to 1;
- bad properties raise ValueError from mi.load_dict.

The interface tests run on both paths (``mode`` native and exact); the
chi-square and furnace tests on the default (native) path.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import paperbsdf
from conftest import mitsuba

UNEQUAL_PAIRS = [  # (theta_light, theta_viewer) in degrees, azimuth difference
    (80.0, 10.0, 0.7), (10.0, 80.0, 2.0), (75.0, -5.0, 3.0), (5.0, -70.0, 1.0), (60.0, 85.0, 0.2),
]


def sph(theta_deg, phi):
    t = np.radians(theta_deg)
    z = np.cos(t)
    return np.array([np.sin(abs(t)) * np.cos(phi), np.sin(abs(t)) * np.sin(phi), z])


def pairs():
    """(light, viewer) pairs in reflection and transmission, from both sides."""
    out = []
    for tl, tv, dphi in UNEQUAL_PAIRS:
        light = sph(tl, 0.0)
        viewer = sph(tv, dphi)
        out.append((light, viewer))  # light and viewer above: reflection (or T if tv < 0)
        out.append((light * [1, 1, -1], viewer))  # light below: transmission to the viewer above
        out.append((light * [1, 1, -1], viewer * [1, 1, -1]))  # both below
    return out


@pytest.fixture
def restore_flags():
    """Restores Dr.Jit's symbolic flags after a test (an ``exact`` plugin in a
    JIT variant switches them off for the process)."""
    import drjit as dr

    flags = (dr.JitFlag.SymbolicLoops, dr.JitFlag.SymbolicCalls, dr.JitFlag.SymbolicConditionals)
    saved = [dr.flag(f) for f in flags]
    yield
    for f, v in zip(flags, saved):
        dr.set_flag(f, v)


@pytest.mark.parametrize("mode", ["native", "exact"])
@pytest.mark.parametrize("variant", ["scalar_rgb", "llvm_ad_rgb"])
def test_eval_mapping_and_cosine(variant, mode, restore_flags):
    mi = mitsuba(variant)
    for preset in ("matte", "glossy"):
        plugin = mi.load_dict({"type": "paperbsdf", "preset": preset, "mode": mode})
        assert plugin.mode == mode
        ref = paperbsdf.PaperBsdf(preset)
        for light, viewer in pairs():
            si = mi.SurfaceInteraction3f()
            si.wi = mi.Vector3f(*[float(x) for x in viewer])
            ctx = mi.BSDFContext()
            wo_m = mi.Vector3f(*[float(x) for x in light])
            v = np.array(plugin.eval(ctx, si, wo_m), dtype=np.float64).reshape(-1)[:3]
            p = float(np.array(plugin.pdf(ctx, si, wo_m)).reshape(-1)[0])
            f = ref.eval(light, viewer)[0]
            expect = f * abs(light[2])
            # float32 directions and values: 1e-4 relative
            np.testing.assert_allclose(v, expect, rtol=1e-4, atol=1e-7)
            np.testing.assert_allclose(p, ref.pdf(light, viewer)[0], rtol=1e-4)
            # what a swapped mapping would give differs by far more than that
            wrong = f * abs(viewer[2])
            assert np.all(np.abs(wrong - expect) > 0.5 * np.abs(expect))
            v2, p2 = plugin.eval_pdf(ctx, si, wo_m)
            np.testing.assert_allclose(np.array(v2).reshape(-1)[:3], v, rtol=1e-6)
            assert abs(float(np.array(p2).reshape(-1)[0]) - p) <= 1e-6 * p


@pytest.mark.parametrize("mode", ["native", "exact"])
def test_sample_side_and_weight_scalar(mode):
    mi = mitsuba("scalar_rgb")
    plugin = mi.load_dict({"type": "paperbsdf", "preset": "matte", "mode": mode})
    ctx = mi.BSDFContext()
    rng = np.random.default_rng(5)
    n_r = n_t = 0
    for k in range(400):
        viewer = sph(rng.uniform(0, 89), rng.uniform(0, 6.28)) * [1, 1, rng.choice([-1, 1])]
        si = mi.SurfaceInteraction3f()
        si.wi = mi.Vector3f(*[float(x) for x in viewer])
        u = rng.random(3) * 0.999
        bs, w = plugin.sample(ctx, si, float(u[0]), mi.Point2f(float(u[1]), float(u[2])))
        if bs.pdf == 0:
            continue
        wo = np.array([bs.wo.x, bs.wo.y, bs.wo.z])
        same = wo[2] * viewer[2] > 0
        n_r += same
        n_t += not same
        stype = mi.BSDFFlags(int(bs.sampled_type))
        assert mi.has_flag(stype, mi.BSDFFlags.Reflection) == bool(same)
        assert mi.has_flag(stype, mi.BSDFFlags.Transmission) == (not same)
        comp = plugin.component_count()
        assert 0 <= bs.sampled_component < comp
        assert mi.has_flag(plugin.flags(bs.sampled_component), stype)
        val, pdf = plugin.eval_pdf(ctx, si, bs.wo)
        assert abs(pdf - bs.pdf) <= 1e-4 * pdf
        np.testing.assert_allclose(np.array(w), np.array(val) / pdf, rtol=2e-4)
    assert n_r > 50 and n_t > 10


@pytest.mark.parametrize("mode", ["native", "exact"])
def test_sample_wavefront_llvm(mode, restore_flags):
    mi = mitsuba("llvm_ad_rgb")
    import drjit as dr

    plugin = mi.load_dict({"type": "paperbsdf", "preset": "luster", "mode": mode})
    assert plugin.mode == mode
    n = 10000
    rng = np.random.default_rng(9)
    v = rng.normal(size=(n, 3))
    v /= np.linalg.norm(v, axis=1)[:, None]
    si = dr.zeros(mi.SurfaceInteraction3f, n)
    si.wi = mi.Vector3f(v[:, 0].astype(np.float32), v[:, 1].astype(np.float32), v[:, 2].astype(np.float32))
    u = rng.random((n, 3)).astype(np.float32)
    active = mi.Bool(rng.random(n) < 0.8)
    ctx = mi.BSDFContext()
    bs, w = plugin.sample(ctx, si, mi.Float(u[:, 0]), mi.Point2f(u[:, 1], u[:, 2]), active)
    pdf = np.array(bs.pdf)
    act = np.array(active)
    assert np.all(pdf[~act] == 0) and np.all(np.array(w)[:, ~act] == 0) if np.array(w).shape[0] == 3 else True
    ok = pdf > 0
    assert ok.sum() > 0.7 * act.sum()
    val, p = plugin.eval_pdf(ctx, si, bs.wo, mi.Bool(ok))
    val = np.array(val)
    val = val if val.shape[0] == n else val.T
    np.testing.assert_allclose(np.array(p)[ok], pdf[ok], rtol=1e-4)
    wv = np.array(w)
    wv = wv if wv.shape[0] == n else wv.T
    np.testing.assert_allclose(wv[ok], val[ok] / pdf[ok, None], rtol=5e-4, atol=1e-6)


@pytest.mark.parametrize("preset", ["matte", "luster", "glossy"])
@pytest.mark.parametrize("side", [1.0, -1.0])
def test_chi2(preset, side):
    mitsuba("llvm_ad_rgb")
    import drjit as dr

    assert dr.flag(dr.JitFlag.SymbolicLoops) and dr.flag(dr.JitFlag.SymbolicCalls)  # Mitsuba's default mode
    from mitsuba.chi2 import BSDFAdapter, ChiSquareTest, SphericalDomain

    for theta in (20.0, 70.0):
        t = np.radians(theta)
        wi = [float(np.sin(t) * np.cos(0.4)), float(np.sin(t) * np.sin(0.4)), float(side * np.cos(t))]
        sample_func, pdf_func = BSDFAdapter("paperbsdf", f'<string name="preset" value="{preset}"/>', wi=wi)
        test = ChiSquareTest(domain=SphericalDomain(), sample_func=sample_func, pdf_func=pdf_func,
                             sample_dim=3, sample_count=400_000, res=101, ires=8, seed=3)
        assert test.run(), f"{preset}, side {side}, theta {theta}: {test.messages}"


def furnace_scene(mi, shape: dict, origin, target, fov: float, size: int, spp: int) -> dict:
    return {
        "type": "scene",
        # Paths keep weight close to one between lossless surfaces; no Russian
        # roulette before depth 400 so that nothing is cut short by chance.
        "integrator": {"type": "path", "max_depth": 400, "rr_depth": 400},
        "sensor": {"type": "perspective", "fov": fov,
                   "to_world": mi.ScalarTransform4f().look_at(origin=origin, target=target, up=[0, 0, 1]),
                   "film": {"type": "hdrfilm", "width": size, "height": size, "rfilter": {"type": "box"},
                            "pixel_format": "rgb"},
                   "sampler": {"type": "independent", "sample_count": spp}},
        "env": {"type": "constant", "radiance": {"type": "rgb", "value": 1.0}},
        "object": shape,
    }


@pytest.mark.parametrize("side", [1.0, -1.0])
def test_flat_sheet_furnace_is_the_albedo(side):
    """A flat sheet in a uniform environment of radiance 1: every camera ray
    meets the sheet once and then leaves to the environment, so a pixel is the
    model's directional albedo (R + T)(wo) for its view direction (here 40
    degrees from the normal, +-1 degree over the image), from either side."""
    mi = mitsuba("llvm_ad_rgb")
    t = np.radians(40.0)
    origin = [0.0, -10 * np.sin(t), side * 10 * np.cos(t)]
    shape = {"type": "rectangle", "to_world": mi.ScalarTransform4f().scale([3, 3, 1]),
             "bsdf": {"type": "paperbsdf", "preset": "matte"}}
    scene = mi.load_dict(furnace_scene(mi, shape, origin, [0, 0, 0], 2.0, 32, 64))
    img = np.array(mi.render(scene, seed=5), dtype=np.float64)[..., :3]
    r, tr = paperbsdf.PaperBsdf("matte").albedo([39.0, 40.0, 41.0], side="front" if side > 0 else "back")
    expect = (r + tr).mean(axis=0)
    mean = img.reshape(-1, 3).mean(axis=0)
    se = img.reshape(-1, 3).std(axis=0, ddof=1) / np.sqrt(img.shape[0] * img.shape[1])
    print(f"flat sheet furnace, side {side}: {mean} vs albedo {expect} (se {se})")
    assert np.all(expect < 0.99)  # the model loses energy, so this is not the trivial 1
    # 4 standard errors of the render, plus 2e-3 for the albedo's 512 x 512
    # quadrature and its spread over the +-1 degree of the view
    assert np.all(np.abs(mean - expect) < 4 * se + 2e-3 * expect), (mean, expect, se)


def test_furnace_sphere_renders_one():
    """A sphere of non-absorbing paper (default faces) in a uniform environment
    of radiance 1 renders to 1 (white furnace), if the model conserves energy.
    The test first measures that with the model's own albedo: while the
    analytic model loses energy for sigma_a = 0 (R + T < 1, the faces and the
    diffusion closed forms; issue 14's energy-conserving faces), the furnace
    cannot be 1 and the test is an expected failure that says by how much."""
    mi = mitsuba("llvm_ad_rgb")
    params = dict(paperbsdf.preset("matte"), sigma_a=0.0, name="white")
    model = paperbsdf.PaperBsdf(params)
    th = [0.0, 30.0, 60.0, 80.0, 89.0]
    a = [r + t for r, t in (model.albedo(th, side=s) for s in ("front", "back"))]
    worst = max(float(np.abs(x - 1.0).max()) for x in a)
    scene = mi.load_dict(furnace_scene(
        mi, {"type": "sphere", "radius": 1.0, "bsdf": {"type": "paperbsdf", "params": json.dumps(params)}},
        [0, -4, 0], [0, 0, 0], 20.0, 16, 32))
    assert scene.shapes()[0].bsdf().mode == "native"
    img = np.array(mi.render(scene, seed=4), dtype=np.float64)[..., :3]
    per_pixel = img.mean(axis=2)
    print(f"furnace: image mean {img.mean():.5f}, pixels {per_pixel.min():.4f} .. {per_pixel.max():.4f};"
          f" model albedo R + T off 1 by up to {worst:.4f}")
    if worst > 0.005:
        pytest.xfail(f"the model's R + T for sigma_a = 0 is off 1 by up to {worst:.3f} "
                     f"(furnace image mean {img.mean():.4f}): energy-conserving faces are issue 14")
    assert abs(per_pixel.mean() - 1.0) < 0.01


def test_load_dict_errors():
    mi = mitsuba("scalar_rgb")

    def err(d, match):
        with pytest.raises(ValueError, match=match):
            mi.load_dict(dict({"type": "paperbsdf"}, **d))

    p = paperbsdf.preset("matte")
    err({"preset": "shiny"}, r"preset `shiny` is unknown")
    err({"params": json.dumps(dict(p, gf=0.8))}, r"unknown field `gf`")
    err({"params": json.dumps(dict(p, m_b=3.0))}, r"m_b")
    err({"params": "/nonexistent/paper.json"}, r"params: /nonexistent/paper.json: No such file")
    err({"preset": "matte", "roughness": 0.3}, r"unknown property `roughness`")
    err({"preset": "matte", "params": "{}"}, r"either `params` or `preset`")
    err({}, r"give the property `params`")
    err({"model": "plastic", "params": json.dumps(p)}, r"unknown model `plastic`")
    err({"preset": "matte", "slab_nodes": 64}, r"slab_nodes.*`paper` has none")
    err({"model": "slab", "params": json.dumps(p), "slab_nodes": 300}, r"slab_nodes: 300 .*\[2, 256\]")
    # A valid `slab_nodes` reaches the model: the plugin's values are those of
    # the Python model with the same nodes, not the default's.
    plugin = mi.load_dict({"type": "paperbsdf", "model": "slab", "params": json.dumps(p), "slab_nodes": 16})
    wi, wo = np.array([[0.5, 0.0, np.sqrt(0.75)]]), np.array([[-0.9, 0.0, np.sqrt(0.19)]])
    assert plugin.model.eval(wi, wo)[0, 0] == paperbsdf.Bsdf("slab", p, slab_nodes=16).eval(wi, wo)[0, 0]
    assert plugin.model.eval(wi, wo)[0, 0] != paperbsdf.Bsdf("slab", p).eval(wi, wo)[0, 0]


@pytest.mark.parametrize("mode", ["native", "exact"])
def test_delta_lobes_are_delta_components(mode):
    """A smooth sheet (m = 0 on both faces): the plugin declares delta lobes,
    sample returns DeltaReflection (the mirror direction) and DeltaTransmission
    (straight through) with weight = the model's, and eval/pdf exclude them."""
    mi = mitsuba("scalar_rgb")
    p = dict(paperbsdf.preset("matte"), m_f=0.0, m_b=0.0, d=0.03, sigma_s=20.0)
    plugin = mi.load_dict({"type": "paperbsdf", "params": json.dumps(p), "mode": mode})
    F = mi.BSDFFlags
    assert mi.has_flag(plugin.flags(), F.DeltaReflection) and mi.has_flag(plugin.flags(), F.DeltaTransmission)
    ref = paperbsdf.PaperBsdf(p)
    ctx = mi.BSDFContext()
    viewer = [0.3, 0.1, float(np.sqrt(1 - 0.1))]
    si = mi.SurfaceInteraction3f()
    si.wi = mi.Vector3f(*viewer)
    seen = set()
    rng = np.random.default_rng(2)
    for _ in range(300):
        u = rng.random(3) * 0.999
        bs, w = plugin.sample(ctx, si, float(u[0]), mi.Point2f(float(u[1]), float(u[2])))
        t = mi.BSDFFlags(int(bs.sampled_type))
        wo = np.array([bs.wo.x, bs.wo.y, bs.wo.z])
        if mi.has_flag(t, F.DeltaReflection):
            seen.add("R")
            np.testing.assert_allclose(wo, [-0.3, -0.1, viewer[2]], atol=1e-6)
        elif mi.has_flag(t, F.DeltaTransmission):
            seen.add("T")
            np.testing.assert_allclose(wo, [-0.3, -0.1, -viewer[2]], atol=1e-6)
        else:
            continue
        _, _, pdf, _, weight = ref.sample_full(np.array([viewer]), u[None, :])
        np.testing.assert_allclose(bs.pdf, pdf[0], rtol=1e-5)
        np.testing.assert_allclose(np.array(w), weight[0], rtol=1e-5)
        # eval and pdf see no delta lobe: at the delta direction they are the
        # model's non-delta lobes only
        f_ns = ref.eval(wo, np.array(viewer))[0] * abs(wo[2])
        np.testing.assert_allclose(np.array(plugin.eval(ctx, si, bs.wo)), f_ns, rtol=1e-4)
        np.testing.assert_allclose(plugin.pdf(ctx, si, bs.wo), ref.pdf(wo, np.array(viewer))[0], rtol=1e-4)
    assert seen == {"R", "T"}
