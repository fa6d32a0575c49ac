"""Speed of Mitsuba 3 with the paperbsdf plugin against Mitsuba with its built-in
`roughplastic`, on the comparison scene (scenes/compare.xml; for `roughplastic`
its two paper sheets get a rough plastic of the same index and roughness),
in samples per second (pixels x spp / wall-clock seconds of mi.render, after
one warm-up render of the same size that compiles and caches the JIT kernels).

Each measurement runs in its own Python process. The plugin runs on its
native (Dr.Jit) path, which works in Mitsuba's default symbolic loops and
calls, and is compared with `roughplastic` in the same mode: the honest
comparison. For reference, llvm_ad_rgb also has the plugin's exact path
(`mode = "exact"`: one call into Rust per wavefront, which needs Dr.Jit's
evaluated loops) against `roughplastic` in evaluated loops.

    python crates/python/tools/speed.py [--spp-scalar 8] [--spp-llvm 256] [--repeat 3]

With --repeat N each configuration is measured N times (the runs
interleaved) and the best is kept: on a shared machine the best is the
least disturbed.
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
    """The scene with `bsdf`: `roughplastic`, `paperbsdf-native` or `paperbsdf-exact`."""
    with open(os.path.join(SCENES, "compare.xml"), encoding="utf-8") as f:
        text = f.read()
    if bsdf == "roughplastic":
        text, n = re.subn(r'<bsdf type="paperbsdf">.*?</bsdf>', ROUGHPLASTIC, text, flags=re.S)
    else:
        mode = bsdf.split("-", 1)[1]
        text, n = re.subn(r'<bsdf type="paperbsdf">', f'<bsdf type="paperbsdf"><string name="mode" value="{mode}"/>',
                          text)
    assert n == 2, n
    return text


def measure(variant: str, bsdf: str, loops: str, spp: int) -> dict:
    mi = setup_mitsuba(variant)  # registers the plugin (Dr.Jit's flags unchanged)
    import drjit as dr

    if variant.startswith("llvm"):
        sym = loops == "symbolic"
        dr.set_flag(dr.JitFlag.SymbolicLoops, sym)
        dr.set_flag(dr.JitFlag.SymbolicCalls, sym)
        dr.set_flag(dr.JitFlag.SymbolicConditionals, sym)
    scene = mi.load_string(scene_text(bsdf), spp=spp)
    if variant.startswith("llvm"):
        # The exact path switches to evaluated loops when created; nothing else may.
        assert dr.flag(dr.JitFlag.SymbolicLoops) == (loops == "symbolic"), (bsdf, loops)
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


RUNS = [  # (variant, bsdf, loops); spp from the arguments
    ("scalar_rgb", "paperbsdf-native", "-"), ("scalar_rgb", "paperbsdf-exact", "-"),
    ("scalar_rgb", "roughplastic", "-"),
    ("llvm_ad_rgb", "paperbsdf-native", "symbolic"), ("llvm_ad_rgb", "roughplastic", "symbolic"),
    ("llvm_ad_rgb", "paperbsdf-exact", "evaluated"), ("llvm_ad_rgb", "roughplastic", "evaluated"),
]
RATIOS = [  # (variant, plugin bsdf, loops of both)
    ("scalar_rgb", "paperbsdf-native", "-"),
    ("scalar_rgb", "paperbsdf-exact", "-"),
    ("llvm_ad_rgb", "paperbsdf-native", "symbolic"),
    ("llvm_ad_rgb", "paperbsdf-exact", "evaluated"),
]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--spp-scalar", type=int, default=8)
    ap.add_argument("--spp-llvm", type=int, default=256)
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--only", choices=["scalar_rgb", "llvm_ad_rgb"], help="measure one variant")
    ap.add_argument("--one", nargs=4, metavar=("VARIANT", "BSDF", "LOOPS", "SPP"), help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.one:
        print(json.dumps(measure(a.one[0], a.one[1], a.one[2], int(a.one[3]))))
        return 0
    best: dict = {}
    for _ in range(a.repeat):
        for v, b, l in RUNS:
            if a.only and v != a.only:
                continue
            s = a.spp_scalar if v == "scalar_rgb" else a.spp_llvm
            p = subprocess.run([sys.executable, __file__, "--one", v, b, l, str(s)], capture_output=True, text=True)
            if p.returncode != 0:
                print(f"{v} {b} {l}: failed\n{p.stderr[-2000:]}", file=sys.stderr)
                continue
            r = json.loads(p.stdout.strip().splitlines()[-1])
            print(f"{v:12s} {b:17s} loops={l:9s} {s:4d} spp: {r['samples_per_s'] / 1e6:8.4f} M samples/s"
                  f" ({r['seconds']:.2f} s)", flush=True)
            key = (v, b, l)
            best[key] = max(best.get(key, 0.0), r["samples_per_s"])
    if a.repeat > 1:
        print(f"best of {a.repeat}:")
        for (v, b, l), sps in best.items():
            print(f"{v:12s} {b:17s} loops={l:9s}: {sps / 1e6:8.4f} M samples/s")
    for v, b, l in RATIOS:
        pb, rp = best.get((v, b, l)), best.get((v, "roughplastic", l))
        if pb and rp:
            print(f"plugin ({b}) / roughplastic, {v}, loops={l}: {pb / rp:.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
