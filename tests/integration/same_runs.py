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
import json
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from compare_outputs import compare_dirs  # noqa: E402


def run(mpiexec, programs, bin_dir, scene, out, cwd):
    cmd = list(mpiexec)
    for k, p in enumerate(programs):
        if k:
            cmd.append(":")
        cmd += ["-n", "1", os.path.join(bin_dir, p), scene, "--out-dir", out, "--overwrite"]
    r = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=300)
    if r.returncode != 0:
        sys.exit(f"same_runs: the run of {scene} failed (exit {r.returncode}):\n{r.stderr[-2000:]}")


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

    diff, compared = compare_dirs(first, second)
    if diff:
        sys.exit(f"same_runs: {diff}")
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
