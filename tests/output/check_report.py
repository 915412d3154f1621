#!/usr/bin/python3
"""./fsi report on synthetic outputs: a case with per-run entries, one without (and without
timings), a benchmark JSON; the page must name them as such, list the missing benchmarks and
not-run cases, state the machine and commit, and its plots must be real pictures. A case's own
study (OUT/<case>/cost.png) is shown in its section, and for a case without a summary in a
section of its own.

usage: check_report.py WORK_DIR
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from check_picture import ROOT, png_problems  # noqa: E402

CASE = {"case": "synthetic-grid", "short": True, "pass": True, "wall_s": 3.0, "cpu_s": 2.5,
        "metrics": {"space_order": {"value": 1.98, "reference": 2.0, "error": 0.0,
                                    "tolerance": 0.0, "pass": True}},
        "jobs": [{"name": f"g{n}", "wall_s": 1.0, "cpu_s": 0.8} for n in (16, 32, 64)],
        "reference_source": "an exact solution (synthetic)",
        "per_run": [{"run": f"g{n}", "quantity": "L2 error", "grid": f"{n}x{n}", "dt": 0.1 / n,
                     "error": 1.0 / n ** 2, "reference": 0.0, "wall_s": n / 16.0,
                     "cpu_s": n / 20.0} for n in (16, 32, 64)]}
BARE = {"case": "synthetic-bare", "short": False, "pass": False, "wall_s": 0.0, "cpu_s": None,
        "metrics": {"value": {"value": 1.5, "reference": 1.0, "error": 0.5, "tolerance": 0.1,
                              "pass": False}}, "jobs": []}
FLUID = {"grids": [{"name": "cavity 64x64", "nx": 64, "ny": 64, "diffusion": "explicit",
                    "steps": 10, "ms_per_step": {"predictor": 0.2, "boundaries": 0.01,
                                                 "poisson": 0.15, "projection": 0.05,
                                                 "total": 0.45},
                    "ns_per_cell_step": 100.0, "poisson_floor_ms": 0.14,
                    "step_to_floor_ratio": 3.2, "poisson_to_floor_ratio": 1.07}]}


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("work")
    out = os.path.join(os.path.abspath(p.parse_args().work), "out")
    shutil.rmtree(out, ignore_errors=True)
    for name, s in [("synthetic-grid", CASE), ("synthetic-bare", BARE)]:
        os.makedirs(os.path.join(out, name))
        with open(os.path.join(out, name, "summary.json"), "w") as f:
            json.dump(s, f)
    # The cases' own studies: one beside a summary, one without (turek-hron-fsi has none here).
    os.makedirs(os.path.join(out, "turek-hron-fsi"))
    for name in ("synthetic-grid", "turek-hron-fsi"):
        plt.imsave(os.path.join(out, name, "cost.png"),
                   np.random.default_rng(len(name)).random((320, 480, 3)))
    os.makedirs(os.path.join(out, "bench"))
    with open(os.path.join(out, "bench", "fluid.json"), "w") as f:
        json.dump(FLUID, f)
    r = subprocess.run(["/usr/bin/python3", os.path.join(ROOT, "runs", "report.py"), "--out", out],
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    print(r.stdout)
    bad = [] if r.returncode == 0 else [f"report.py exited {r.returncode}"]
    page = os.path.join(out, "report", "index.html")
    text = open(page).read() if os.path.exists(page) else ""
    if not text:
        bad.append(f"no page {page}")
    expect = [r"Machine: \d+ cores, ", r"commit <code>[0-9a-f]{40}", r"synthetic-grid",
              r"<td>3 runs</td>", r"synthetic-bare.*no per-run entries", r"<td>no timings</td>",
              r"Missing \(no out/bench.*solid.*coupled", r"not run: no out/taylor-green/summary\.json",
              r"an exact solution \(synthetic\)", r"space_order 1\.98", r"OpenFOAM", r"CalculiX",
              r"class=fail>FAIL", r"not run: no out/turek-hron-fsi/summary\.json",
              r"turek-hron-fsi \(no summary; its own study\)"]
    for rx in expect:
        if not re.search(rx, text, re.S):
            bad.append(f"the page does not match /{rx}/")
    for png in ["synthetic-grid_error_cpu.png", "bench_fluid.png", "synthetic-grid_study_cost.png",
                "turek-hron-fsi_study_cost.png"]:
        if f"src='{png}'" not in text:
            bad.append(f"the page does not show {png}")
        bad += png_problems(os.path.join(out, "report", png))
    if os.path.exists(os.path.join(out, "report", "synthetic-bare_error_cpu.png")):
        bad.append("a plot was drawn for a case without per-run entries")
    for b in bad:
        print("FAIL:", b)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
