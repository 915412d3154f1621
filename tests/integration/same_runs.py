#!/usr/bin/python3
"""Run one coupled job twice, the second with the solvers' work ahead of their input switched off
([test] work_ahead = false), and check that the two runs wrote the same results bit for bit.

  same_runs.py --cwd DIR --scene SCENE --programs fluid,solid,coupler --bin BIN -- MPIEXEC...

The second scene is SCENE with the [test] table appended, written beside it (so that its relative
mesh paths still hold). Compared: every CSV file of the first run's output folder, byte for byte,
and every numeric dataset of its .h5 files, value for value (NaN equal to NaN). Exits 1 naming the
first difference, or when a run fails or a folder holds nothing to compare.
"""
import argparse
import glob
import json
import os
import subprocess
import sys

import h5py
import numpy as np


def run(mpiexec, programs, bin_dir, scene, out, cwd):
    cmd = list(mpiexec)
    for k, p in enumerate(programs):
        if k:
            cmd.append(":")
        cmd += ["-n", "1", os.path.join(bin_dir, p), scene, "--out-dir", out, "--overwrite"]
    r = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=300)
    if r.returncode != 0:
        sys.exit(f"same_runs: the run of {scene} failed (exit {r.returncode}):\n{r.stderr[-2000:]}")


def h5_datasets(path):
    out = {}
    with h5py.File(path, "r") as f:
        f.visititems(lambda name, obj: out.__setitem__(name, obj[()])
                     if isinstance(obj, h5py.Dataset) and obj.dtype.kind in "fiu" else None)
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cwd", required=True)
    ap.add_argument("--scene", required=True)
    ap.add_argument("--programs", required=True)
    ap.add_argument("--bin", required=True)
    ap.add_argument("mpiexec", nargs="+")
    a = ap.parse_args()
    os.makedirs(a.cwd, exist_ok=True)
    plain = os.path.splitext(a.scene)[0] + "_no_work_ahead.toml"
    with open(a.scene) as f, open(plain, "w") as g:
        g.write(f.read() + "\n[test]\nwork_ahead = false\n")
    programs = a.programs.split(",")
    first, second = os.path.join(a.cwd, "ahead"), os.path.join(a.cwd, "plain")
    run(a.mpiexec, programs, a.bin, a.scene, first, a.cwd)
    run(a.mpiexec, programs, a.bin, plain, second, a.cwd)

    compared = 0
    for path in sorted(glob.glob(os.path.join(first, "*.csv"))):
        other = os.path.join(second, os.path.basename(path))
        if open(path, "rb").read() != open(other, "rb").read():
            sys.exit(f"same_runs: {os.path.basename(path)} differs")
        compared += 1
    for path in sorted(glob.glob(os.path.join(first, "*.h5"))):
        d1 = h5_datasets(path)
        d2 = h5_datasets(os.path.join(second, os.path.basename(path)))
        if sorted(d1) != sorted(d2):
            sys.exit(f"same_runs: {os.path.basename(path)} holds other datasets")
        for name, v in d1.items():
            if not np.array_equal(v, d2[name], equal_nan=v.dtype.kind == "f"):
                sys.exit(f"same_runs: {os.path.basename(path)}:{name} differs")
            compared += 1
    if compared == 0:
        sys.exit("same_runs: nothing to compare")
    with open(os.path.join(first, "summary.json")) as f:
        summary = json.load(f)
    for p in programs:
        if p != "coupler" and not summary[p].get("ahead_seconds", 0) > 0:
            sys.exit(f"same_runs: the {p} did no work ahead in the first run: nothing was tested")
    with open(os.path.join(second, "summary.json")) as f:
        summary = json.load(f)
    for p in programs:
        if p != "coupler" and summary[p].get("ahead_seconds", 0) != 0:
            sys.exit(f"same_runs: the {p} worked ahead although [test] work_ahead = false")
    print(f"same_runs: {compared} files and datasets identical with and without the work ahead")


if __name__ == "__main__":
    main()
