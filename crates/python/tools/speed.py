"""Speed of Mitsuba 3 with the paperbsdf plugin against Mitsuba with its built-in
`roughplastic`, on the comparison scene (scenes/compare.xml; for `roughplastic`
its two paper sheets get a rough plastic of the same index and roughness),
in samples per second (pixels x spp / wall-clock seconds of mi.render, after
one warm-up render of the same size that compiles and caches the JIT kernels).

Each measurement runs in its own Python process. In llvm_ad_rgb the plugin
needs Dr.Jit's evaluated loops and calls; `roughplastic` is measured both
with Mitsuba's default (symbolic, one fused kernel) and evaluated loops.

    python crates/python/tools/speed.py [--spp-scalar 8] [--spp-llvm 256]
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _common import SCENES, setup_mitsuba  # noqa: E402

ROUGHPLASTIC = ('<bsdf type="roughplastic"><string name="distribution" value="ggx"/>'
                '<float name="alpha" value="0.15"/><float name="int_ior" value="1.5"/>'
                '<rgb name="diffuse_reflectance" value="0.8"/></bsdf>')


def scene_text(bsdf: str) -> str:
    with open(os.path.join(SCENES, "compare.xml"), encoding="utf-8") as f:
        text = f.read()
    if bsdf == "roughplastic":
        text, n = re.subn(r'<bsdf type="paperbsdf">.*?</bsdf>', ROUGHPLASTIC, text, flags=re.S)
        assert n == 2, n
    return text


def measure(variant: str, bsdf: str, loops: str, spp: int) -> dict:
    mi = setup_mitsuba(variant)  # registers the plugin (switches a JIT variant to evaluated loops)
    import drjit as dr

    if variant.startswith("llvm"):
        sym = loops == "symbolic"
        dr.set_flag(dr.JitFlag.SymbolicLoops, sym)
        dr.set_flag(dr.JitFlag.SymbolicCalls, sym)
        dr.set_flag(dr.JitFlag.SymbolicConditionals, sym)
    scene = mi.load_string(scene_text(bsdf), spp=spp)
    w, h = scene.sensors()[0].film().size()
    # Warm-up render of the same size (compiles and caches the JIT kernels).
    dr.eval(mi.render(scene, seed=99, spp=spp))
    dr.sync_thread()
    t0 = time.time()
    img = mi.render(scene, seed=1, spp=spp)
    dr.eval(img)
    dr.sync_thread()  # LLVM kernels run asynchronously
    dt = time.time() - t0
    return {"variant": variant, "bsdf": bsdf, "loops": loops, "spp": spp, "seconds": dt,
            "samples_per_s": w * h * spp / dt}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--spp-scalar", type=int, default=8)
    ap.add_argument("--spp-llvm", type=int, default=256)
    ap.add_argument("--one", nargs=4, metavar=("VARIANT", "BSDF", "LOOPS", "SPP"), help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.one:
        print(json.dumps(measure(a.one[0], a.one[1], a.one[2], int(a.one[3]))))
        return 0
    runs = [("scalar_rgb", "paperbsdf", "-", a.spp_scalar), ("scalar_rgb", "roughplastic", "-", a.spp_scalar),
            ("llvm_ad_rgb", "paperbsdf", "evaluated", a.spp_llvm),
            ("llvm_ad_rgb", "roughplastic", "evaluated", a.spp_llvm),
            ("llvm_ad_rgb", "roughplastic", "symbolic", a.spp_llvm)]
    res = []
    for v, b, l, s in runs:
        p = subprocess.run([sys.executable, __file__, "--one", v, b, l, str(s)], capture_output=True, text=True)
        if p.returncode != 0:
            print(f"{v} {b} {l}: failed\n{p.stderr[-2000:]}", file=sys.stderr)
            continue
        r = json.loads(p.stdout.strip().splitlines()[-1])
        res.append(r)
        print(f"{v:12s} {b:13s} loops={l:9s} {s:4d} spp: {r['samples_per_s'] / 1e6:8.4f} M samples/s ({r['seconds']:.2f} s)",
              flush=True)
    by = {(r["variant"], r["bsdf"], r["loops"]): r["samples_per_s"] for r in res}
    for v, l in (("scalar_rgb", "-"), ("llvm_ad_rgb", "evaluated"), ("llvm_ad_rgb", "symbolic")):
        pb = by.get((v, "paperbsdf", "evaluated" if v.startswith("llvm") else "-"))
        rp = by.get((v, "roughplastic", l))
        if pb and rp:
            print(f"plugin / roughplastic ({v}, roughplastic loops={l}): {pb / rp:.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
