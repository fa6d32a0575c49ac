"""Renders the supplement's Figure 1 set-up (scenes/figure1.xml: matte, glossy
and luster paper in front of an illuminated checkerboard) with Mitsuba 3 and
the paperbsdf plugin, to OUT.exr and OUT.png.

    python crates/python/tools/render_figure1.py [--spp 256] [--variant llvm_ad_rgb] [--out docs/mitsuba_figure1]
"""

from __future__ import annotations

import argparse
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _common import REPO, SCENES, setup_mitsuba, write_images  # noqa: E402


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--spp", type=int, default=256, help="samples per pixel (default 256)")
    ap.add_argument("--width", type=int, default=480)
    ap.add_argument("--height", type=int, default=320)
    ap.add_argument("--variant", default="llvm_ad_rgb", help="Mitsuba variant (default llvm_ad_rgb)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default=os.path.join(REPO, "docs", "mitsuba_figure1"),
                    help="output path without extension (writes .exr and .png)")
    a = ap.parse_args()
    for name in ("spp", "width", "height"):
        if getattr(a, name) < 1:
            ap.error(f"--{name} = {getattr(a, name)}: must be at least 1")
    mi = setup_mitsuba(a.variant)
    scene = mi.load_file(os.path.join(SCENES, "figure1.xml"), spp=a.spp, width=a.width, height=a.height)
    # Render in passes of at most 16 spp (bounded memory in the JIT variant), averaged.
    passes = max(1, (a.spp + 15) // 16)
    per = [a.spp // passes + (1 if k < a.spp % passes else 0) for k in range(passes)]
    t0 = time.time()
    acc = None
    for k, s in enumerate(per):
        img = mi.render(scene, seed=a.seed * 1000 + k, spp=s)
        import numpy as np

        arr = np.array(img, dtype=np.float64) * s
        acc = arr if acc is None else acc + arr
        print(f"\rpass {k + 1}/{passes} ({sum(per[:k + 1])} spp, {time.time() - t0:.0f} s)", end="", file=sys.stderr, flush=True)
    print(file=sys.stderr)
    dt = time.time() - t0
    exr, png = write_images(mi, acc / a.spp, a.out)
    n = a.width * a.height * a.spp
    print(f"{a.variant}: {a.width}x{a.height} at {a.spp} spp in {dt:.1f} s ({n / dt:.3g} samples/s); wrote {exr}, {png}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
