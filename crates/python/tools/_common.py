"""Helpers shared by the scripts in tools/: Mitsuba set-up and atomic image output."""

from __future__ import annotations

import glob
import os
import subprocess
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
CRATE = os.path.dirname(HERE)
REPO = os.path.dirname(os.path.dirname(CRATE))
SCENES = os.path.join(CRATE, "scenes")


def find_libllvm() -> str | None:
    """Path of a libLLVM shared library for Dr.Jit's LLVM backend: $DRJIT_LIBLLVM_PATH,
    else Debian's libllvm19 (or another version) under /usr/lib."""
    p = os.environ.get("DRJIT_LIBLLVM_PATH")
    if p and os.path.exists(p):
        return p
    for pat in ("/usr/lib/x86_64-linux-gnu/libLLVM-19.so*", "/usr/lib/llvm-19/lib/libLLVM*.so*",
                "/usr/lib/x86_64-linux-gnu/libLLVM*.so*", "/usr/lib/*/libLLVM*.so*"):
        hits = sorted(glob.glob(pat))
        if hits:
            return hits[0]
    return None


def setup_mitsuba(variant: str):
    """Imports Mitsuba, selects `variant` and registers the paperbsdf plugin.
    For an LLVM variant, points Dr.Jit at libLLVM first (DRJIT_LIBLLVM_PATH)."""
    if variant.startswith("llvm") and "DRJIT_LIBLLVM_PATH" not in os.environ:
        lib = find_libllvm()
        if lib:
            os.environ["DRJIT_LIBLLVM_PATH"] = lib
    import mitsuba as mi

    mi.set_variant(variant)
    import paperbsdf.mitsuba

    paperbsdf.mitsuba.register()
    return mi


def write_images(mi, img, out_base: str, exposure: float = 1.0) -> tuple[str, str]:
    """Writes `img` (a Mitsuba image tensor or Bitmap, linear RGB) as out_base.exr
    and a tone-mapped sRGB out_base.png (clamp to [0, 1] after `exposure`), each
    through a temporary file renamed into place."""
    import numpy as np

    arr = np.array(img, dtype=np.float32)[..., :3]
    d = os.path.dirname(os.path.abspath(out_base))
    os.makedirs(d, exist_ok=True)
    paths = []
    for ext in (".exr", ".png"):
        fd, tmp = tempfile.mkstemp(suffix=ext, dir=d)
        os.close(fd)
        if ext == ".exr":
            mi.Bitmap(arr).write(tmp)
        else:
            ldr = np.clip(arr * exposure, 0.0, 1.0)
            bmp = mi.Bitmap(ldr).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.UInt8, srgb_gamma=True)
            bmp.write(tmp)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp creates 0600
        os.replace(tmp, out_base + ext)
        paths.append(out_base + ext)
    return paths[0], paths[1]


def paperbsdf_cli() -> str:
    """The `paperbsdf` command: $PAPERBSDF_CLI, else the workspace's release
    build, brought up to date by cargo (a no-op when nothing changed)."""
    p = os.environ.get("PAPERBSDF_CLI")
    if p:
        return p
    subprocess.run(["cargo", "build", "--release", "-q", "-p", "paperbsdf-cli"], cwd=REPO, check=True)
    return os.path.join(REPO, "target", "release", "paperbsdf")
