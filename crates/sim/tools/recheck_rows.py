"""Re-simulate rows of docs/accuracy_slab.md / accuracy_single_slab.md with
more walks and another seed, and score `slab` and `paper` on them, with the
`paperbsdf` command only (simulate, eval): the same RMS log error over
theta_o = -80..80 step 10 and the same offset (1e-3) as the accuracy example,
and the noise floor of the new simulation.

The accuracy tables' rows share one simulation per incident angle, so a
fluctuation of the simulated total moves every theta_o of a row together; a
row's error can then read twice its per-point noise floor at about 2 sigma.
This script tells such a row from a model error.

usage: python3 recheck_rows.py [WALKS] [SEED] [CLI] [FACES:CASE:THETA_I ...]
(defaults: 262144 walks, seed 97, target/release/paperbsdf, and the rows
listed below; FACES is `single` or `multiple`; run from the repository root).
Prints one markdown row per case, angle and kind: paper, slab, noise floor."""
import csv
import json
import math
import os
import subprocess
import sys
import tempfile

E = 1e-3  # the accuracy example's offset in the logarithm


def paper(d, sigma_a, sigma_s, m_f, m_b, dist_f):
    """The accuracy example's synthetic cases (crates/sim/examples/accuracy.rs `paper`)."""
    return {"d": d, "sigma_a": sigma_a, "sigma_s": sigma_s, "g_f": 0.8, "g_b": -0.3, "w_b": 0.2,
            "eta_f": 1.5, "eta_b": 1.5, "m_f": m_f, "m_b": m_b, "dist_f": dist_f, "dist_b": "ggx"}


CASES = {
    "thin-tissue": paper(0.03, 0.3, 40.0, 0.3, 0.3, "ggx"),
    "weak-scatter": paper(0.1, 0.5, 30.0, 0.3, 0.3, "ggx"),
    "thick-board": paper(0.3, 0.5, 200.0, 0.3, 0.3, "ggx"),
    "smooth-front": paper(0.1, 0.5, 150.0, 0.05, 0.3, "beckmann"),
    "very-rough": paper(0.1, 0.5, 150.0, 0.9, 0.9, "ggx"),
}

# The transmission rows above 2% in the tables of 2026-12-03 (slab's error more than 0.01 over the floor first).
ROWS = ["single:preset-luster:60", "single:preset-matte:60", "single:preset-glossy:30", "single:thick-board:30",
        "single:thick-board:60", "single:devA:0", "single:devA:30", "single:devA:75", "single:thin-tissue:75",
        "multiple:preset-glossy:0", "multiple:preset-glossy:75", "multiple:preset-luster:30",
        "multiple:preset-glossy:60", "multiple:thick-board:75", "multiple:very-rough:60",
        "multiple:thin-tissue:60", "multiple:thin-tissue:75"]


def params_of(cli, case):
    if case in CASES:
        return dict(CASES[case])
    if case.startswith("preset-"):
        # the preset's parameters, as the simulator prints them in its header
        out = subprocess.run([cli, "simulate", "--params", case[7:], "--theta-i", "0", "--totals", "--samples", "64"],
                             capture_output=True, text=True, check=True).stdout
        header = out.splitlines()[0]
        return json.loads(header[header.index("params: ") + len("params: "):])
    return json.load(open(os.path.join("data", "reference", case + ".json")))


def read(path):
    rows = {}
    with open(path) as f:
        for r in csv.DictReader(line for line in f if not line.startswith("#")):
            chans = [("f", "stderr")] if "f" in r else [(c, c + "_stderr") for c in "rgb"]
            for i, (v, s) in enumerate(chans):
                rows[(r["kind"], float(r["theta_o_deg"]), i)] = (float(r[v]), float(r.get(s) or 0.0))
    return rows


def main():
    walks = int(sys.argv[1]) if len(sys.argv) > 1 else 262144
    seed = int(sys.argv[2]) if len(sys.argv) > 2 else 97
    cli = sys.argv[3] if len(sys.argv) > 3 else os.path.join("target", "release", "paperbsdf")
    rows = sys.argv[4:] or ROWS
    print(f"walks {walks}, seed {seed}\n")
    print("| faces | case | theta_i, kind | paper | slab | noise floor |\n|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for row in rows:
            faces, case, theta_i = row.split(":")
            p = params_of(cli, case)
            p.pop("name", None)
            p["face_scattering"] = faces
            base = os.path.join(tmp, f"{faces}_{case}_{theta_i}")
            with open(base + ".json", "w") as f:
                json.dump(p, f)
            angles = ["--theta-i", theta_i, "--theta-o", "-80:80:10"]
            subprocess.run([cli, "simulate", "--params", base + ".json", *angles, "--samples", str(walks),
                            "--seed", str(seed), "--out", base + "_sim.csv"], check=True, capture_output=True)
            for m in ("slab", "paper"):
                subprocess.run([cli, "eval", "--model", m, "--params", base + ".json", *angles,
                                "--out", f"{base}_{m}.csv"], check=True)
            sim, slab, pap = read(base + "_sim.csv"), read(base + "_slab.csv"), read(base + "_paper.csv")
            for kind in "RT":
                keys = [k for k in sim if k[0] == kind]
                rms = lambda model: math.sqrt(sum(math.log((model[k][0] + E) / (sim[k][0] + E)) ** 2
                                                  for k in keys) / len(keys))
                floor = math.sqrt(sum((sim[k][1] / (sim[k][0] + E)) ** 2 for k in keys) / len(keys))
                print(f"| {faces} | {case} | {theta_i} {kind} | {rms(pap):.3f} | {rms(slab):.3f} | {floor:.3f} |",
                      flush=True)


if __name__ == "__main__":
    main()
