#!/usr/bin/python3
"""Run scenes with the fluid on 1 rank and on P ranks and check that the outputs agree to
round-off.

  ranks.py --bin BIN --work DIR --ranks P[,Q...] [--programs fluid,solid,coupler] [--t-end T]
           [--tolerance 1e-12] -- MPIEXEC... SCENE.toml...

Every scene runs as `MPIEXEC -n 1 BIN/fluid SCENE [: -n 1 BIN/solid SCENE ...]` and with `-n P`
for the fluid (with --t-end, a copy of the scene with that t_end, written beside it so that its
relative mesh paths hold, and removed after). Compared: every floating-point dataset of every .h5 file and every column of every
CSV file of the output folder, each as its largest difference relative to its largest
magnitude; the run fails when one exceeds the tolerance, or when a run fails. Prints the largest
relative difference per dataset name.
"""
import argparse
import glob
import os
import re
import subprocess
import sys

import h5py
import numpy as np


def run(mpiexec, bin_dir, programs, ranks, scene, out):
    cmd = list(mpiexec)
    for k, p in enumerate(programs):
        if k:
            cmd.append(":")
        n = ranks if p == "fluid" else 1
        cmd += ["-n", str(n), os.path.join(bin_dir, p), scene, "--out-dir", out, "--overwrite"]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    if r.returncode != 0:
        sys.exit(f"ranks: {scene} on {ranks} rank(s) failed (exit {r.returncode}):\n{r.stderr[-2000:]}")


def datasets(path):
    out = {}
    with h5py.File(path, "r") as f:
        f.visititems(lambda name, obj: out.__setitem__(name, obj[()])
                     if isinstance(obj, h5py.Dataset) and obj.dtype.kind == "f" else None)
    return out


def relative(a, b):
    if a.shape != b.shape:
        return np.inf
    scale = np.max(np.abs(a)) if a.size else 0.0
    d = np.max(np.abs(a - b)) if a.size else 0.0
    return 0.0 if d == 0 else d / max(scale, 1e-300)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--ranks", required=True, help="P, or several: 2,3 (each against one rank)")
    ap.add_argument("--programs", default="fluid")
    ap.add_argument("--t-end", type=float)
    ap.add_argument("--tolerance", type=float, default=1e-12)
    ap.add_argument("rest", nargs=argparse.REMAINDER)
    a = ap.parse_args()
    rest = a.rest[1:] if a.rest and a.rest[0] == "--" else a.rest
    scenes = [x for x in rest if x.endswith(".toml")]
    mpiexec = [x for x in rest if not x.endswith(".toml")]
    if not scenes or not mpiexec:
        sys.exit("ranks: give the mpiexec command and at least one scene after --")
    programs = a.programs.split(",")
    worst_all, failures = 0.0, []
    counts = [int(x) for x in a.ranks.split(",")]
    for scene in scenes:
        name = os.path.splitext(os.path.basename(scene))[0]
        one = os.path.join(a.work, f"{name}-1")
        copy = None
        if a.t_end is not None:
            text, n = re.subn(r"(?m)^t_end\s*=.*$", f"t_end = {a.t_end!r}", open(scene).read(), count=1)
            if n != 1:
                sys.exit(f"ranks: no t_end line in {scene}")
            copy = os.path.splitext(scene)[0] + f"_ranks_{os.getpid()}.toml"
            with open(copy, "w") as f:
                f.write(text)
        try:
            run(mpiexec, a.bin, programs, 1, copy or scene, one)
            for p in counts:
                run(mpiexec, a.bin, programs, p, copy or scene, os.path.join(a.work, f"{name}-{p}"))
        finally:
            if copy:
                os.remove(copy)
        for p in counts:
            many = os.path.join(a.work, f"{name}-{p}")
            kinds = {}
            for h5 in sorted(glob.glob(os.path.join(one, "*.h5"))):
                other = os.path.join(many, os.path.basename(h5))
                d1 = datasets(h5)
                dp = datasets(other) if os.path.exists(other) else {}
                if sorted(d1) != sorted(dp):
                    failures.append(f"{name}: the runs on 1 and {p} ranks wrote different datasets in "
                                    f"{os.path.basename(h5)}")
                    continue
                for key in d1:
                    kind = os.path.basename(h5)[:-3] + ":" + key.split("/")[-1]
                    kinds[kind] = max(kinds.get(kind, 0.0), relative(d1[key], dp[key]))
            for csv in sorted(glob.glob(os.path.join(one, "*.csv"))):
                x = np.loadtxt(csv, delimiter=",", skiprows=1, ndmin=2)
                y = np.loadtxt(os.path.join(many, os.path.basename(csv)), delimiter=",", skiprows=1, ndmin=2)
                kinds[os.path.basename(csv)] = relative(x, y)
            if not kinds:
                failures.append(f"{name}: nothing compared")
            for kind, d in sorted(kinds.items()):
                print(f"{name} on {p} ranks: {kind:32s} largest relative difference {d:.3g}")
                worst_all = max(worst_all, d)
                if not d <= a.tolerance:
                    failures.append(f"{name} on {p} ranks: {kind} differs by {d:.3g} (tolerance {a.tolerance:g})")
    print(f"largest relative difference, 1 against {a.ranks} ranks: {worst_all:.3g}")
    if failures:
        sys.exit("ranks: " + "; ".join(failures))


if __name__ == "__main__":
    main()
