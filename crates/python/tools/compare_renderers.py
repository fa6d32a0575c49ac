"""Our renderer (`paperbsdf render`) against Mitsuba 3 with the paperbsdf plugin
on the same scene with paper (scenes/compare.toml and scenes/compare.xml: a
glossy sheet lit from the front, a matte sheet lit from behind).

Each renderer renders PASSES independent images (different seeds) of SPP
samples per pixel. A pixel's standard error comes from the spread of its
passes (PASSES - 1 degrees of freedom); an 8x8 block's from its 64 pixels
(independent), so it is known to a few percent. Per block and channel the
two means must agree within 3 combined standard errors + 1% of Mitsuba's
value. Prints the largest deviations and exits 1 on a failure.

    python crates/python/tools/compare_renderers.py [--spp 16] [--passes 8] [--variant llvm_ad_rgb]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _common import SCENES, paperbsdf_cli, setup_mitsuba  # noqa: E402

BLOCK = 8


def render_ours(mi, spp: int, passes: int) -> tuple[np.ndarray, float]:
    """`passes` renders of scenes/compare.toml by `paperbsdf render`, (P, H, W, 3), and the seconds taken."""
    exe = paperbsdf_cli()
    imgs = []
    t = 0.0
    with tempfile.TemporaryDirectory() as d:
        for k in range(passes):
            out = os.path.join(d, f"ours_{k}")
            t0 = time.time()
            subprocess.run([exe, "render", os.path.join(SCENES, "compare.toml"), "--spp", str(spp),
                            "--seed", str(1000 + k), "--out", out], check=True, capture_output=True)
            t += time.time() - t0
            imgs.append(np.array(mi.Bitmap(out + ".exr"), dtype=np.float64)[..., :3])
    return np.stack(imgs), t


def render_mitsuba(mi, spp: int, passes: int) -> tuple[np.ndarray, float]:
    """`passes` renders of scenes/compare.xml by Mitsuba with the plugin, (P, H, W, 3), and the seconds taken."""
    scene = mi.load_file(os.path.join(SCENES, "compare.xml"), spp=spp)
    imgs = []
    t0 = time.time()
    for k in range(passes):
        imgs.append(np.array(mi.render(scene, seed=2000 + k, spp=spp), dtype=np.float64)[..., :3])
    return np.stack(imgs), time.time() - t0


def block_stats(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Block means and their standard errors from passes (P, H, W, 3)."""
    n, h, w, c = p.shape
    mean = p.mean(axis=0)
    var_of_mean = p.var(axis=0, ddof=1) / n
    hb, wb = h // BLOCK, w // BLOCK
    m = mean[: hb * BLOCK, : wb * BLOCK].reshape(hb, BLOCK, wb, BLOCK, c).mean(axis=(1, 3))
    v = var_of_mean[: hb * BLOCK, : wb * BLOCK].reshape(hb, BLOCK, wb, BLOCK, c).sum(axis=(1, 3)) / BLOCK**4
    return m, np.sqrt(v)


def compare(mi, spp: int = 16, passes: int = 8) -> dict:
    """Renders with both and compares per block; returns the statistics."""
    ours, t_ours = render_ours(mi, spp, passes)
    mits, t_mits = render_mitsuba(mi, spp, passes)
    if ours.shape != mits.shape:
        raise ValueError(f"image shapes differ: ours {ours.shape[1:]}, Mitsuba {mits.shape[1:]}")
    m1, s1 = block_stats(ours)
    m2, s2 = block_stats(mits)
    se = np.sqrt(s1**2 + s2**2)
    diff = np.abs(m1 - m2)
    tol = 3.0 * se + 0.01 * np.abs(m2)
    # z where there is noise (blocks of pure background or black have se = 0)
    z = np.where(se > 0, (m1 - m2) / np.where(se > 0, se, 1.0), 0.0)
    return {
        "ours": m1, "mitsuba": m2, "se": se, "z": z, "fail": diff > tol,
        "ratio": diff / tol, "seconds": (t_ours, t_mits),
        "image_means": (ours.mean(), mits.mean()),
    }


def report(r: dict) -> str:
    lines = []
    fail = r["fail"]
    lines.append(f"blocks x channels: {fail.size}, failing: {int(fail.sum())}")
    lines.append(f"image mean: ours {r['image_means'][0]:.5f}, Mitsuba {r['image_means'][1]:.5f}")
    lines.append(f"|z| (difference / combined standard error): max {np.abs(r['z']).max():.2f}, "
                 f"rms {np.sqrt((r['z'] ** 2).mean()):.2f}")
    lines.append(f"largest |difference| / (3 se + 1%): {r['ratio'].max():.3f}")
    idx = np.unravel_index(np.argsort(-r["ratio"], axis=None)[:5], r["ratio"].shape)
    for by, bx, c in zip(*idx):
        lines.append(f"  block ({by}, {bx}) channel {c}: ours {r['ours'][by, bx, c]:.5f}, "
                     f"Mitsuba {r['mitsuba'][by, bx, c]:.5f}, se {r['se'][by, bx, c]:.2e}, z {r['z'][by, bx, c]:+.2f}")
    lines.append(f"render time: ours {r['seconds'][0]:.1f} s, Mitsuba + plugin {r['seconds'][1]:.1f} s")
    return "\n".join(lines)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--spp", type=int, default=16, help="samples per pixel per pass (default 16)")
    ap.add_argument("--passes", type=int, default=8, help="independent passes per renderer (default 8, at least 2)")
    ap.add_argument("--variant", default="llvm_ad_rgb")
    a = ap.parse_args()
    if a.spp < 1 or a.passes < 2:
        ap.error("--spp must be at least 1 and --passes at least 2")
    mi = setup_mitsuba(a.variant)
    r = compare(mi, a.spp, a.passes)
    print(report(r))
    return 1 if r["fail"].any() else 0


if __name__ == "__main__":
    sys.exit(main())
