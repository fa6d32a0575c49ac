"""The scenes: our renderer against Mitsuba 3 + plugin with paper in the scene
(tools/compare_renderers.py, per 8x8 block within 3 standard errors + 1%;
the plugin on its default, native path in Mitsuba's symbolic loops),
and the Figure 1 example scene renders."""

from __future__ import annotations

import os

import numpy as np

from conftest import mitsuba
import _common
import compare_renderers


def test_our_renderer_agrees_with_mitsuba_and_plugin():
    mi = mitsuba("llvm_ad_rgb")
    import drjit as dr

    # The comparison runs the plugin's default path in llvm_ad_rgb: native, in symbolic loops.
    scene = mi.load_file(os.path.join(_common.SCENES, "compare.xml"), spp=1)
    modes = [getattr(s.bsdf(), "mode", None) for s in scene.shapes()]
    assert modes.count("native") == 2, modes
    assert dr.flag(dr.JitFlag.SymbolicLoops) and dr.flag(dr.JitFlag.SymbolicCalls)
    r = compare_renderers.compare(mi, spp=16, passes=8)
    print(compare_renderers.report(r))
    # The scene must show what it is meant to: lit sheets well above the dim background.
    assert r["mitsuba"].max() > 0.3
    assert not r["fail"].any(), compare_renderers.report(r)


def test_figure1_scene_renders(tmp_path):
    mi = mitsuba("llvm_ad_rgb")
    scene = mi.load_file(os.path.join(_common.SCENES, "figure1.xml"), spp=4, width=60, height=40)
    img = np.array(mi.render(scene, seed=1), dtype=np.float64)[..., :3]
    assert img.shape == (40, 60, 3) and np.all(np.isfinite(img))
    exr, png = _common.write_images(mi, img, str(tmp_path / "fig1"))
    assert os.path.getsize(exr) > 0 and os.path.getsize(png) > 0
    # the sheets (lower middle of the frame) are lit: brighter than the dark board
    assert img[25:35, 10:50].mean() > 0.05
