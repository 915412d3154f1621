#!/usr/bin/python3
"""FSI2's error against CPU time, from the alignment studies already run (no run is started).

  cost.py [--out DIR]      (DIR: FSI_OUT, default out/turek-hron-fsi)

Reads the FSI2 shift studies that `validate.py --xy-shift S... [--shift-level L] [--t-end T]`
wrote into DIR (fsi2_shift[-LEVEL][-tT].json) and each run's job_time.json (wall and CPU
seconds of the whole job). For each level and alignment s it takes the row of the longest run
(a window that settled: README, "FSI2 against the cells' alignment"), and computes the errors
of u_y(A)'s amplitude and of the drag and lift amplitudes (raw and after the 10 ms average)
against the 2006 table and the refined FEATFLOW values (reference.csv). The cost axis is the
CPU seconds to the case's t = 12 of the same run, scaled by 12 / t_end for a run taken further
to let its window settle (a t = 12 run of the same alignment may not have reached the
flapping's amplitude). Prints one row per run and the mean over the alignments of each level; writes
cost.json and cost.png (error against CPU seconds, both references) into DIR.
"""
import argparse
import glob
import json
import os
import re
import sys

from case import XY_LEVELS, read_reference  # this folder's

HERE = os.path.dirname(os.path.abspath(__file__))
# Each banded level's cells and the bar's thickness in cells (its elements are half a cell).
LEVELS = {f"XY{n}": (f"{nx}x{ny}", bar[1] // 2) for n, nx, ny, _, bar in XY_LEVELS}
CASE_T_END = 12.0  # the case's end time (validate.py), the cost axis's
QUANTITIES = (("uy", "amplitude", "u_y(A) amp"), ("drag", "amplitude", "drag amp"),
              ("drag_smoothed", "amplitude", "drag amp avg"), ("lift", "amplitude", "lift amp"),
              ("lift_smoothed", "amplitude", "lift amp avg"))


def study_rows(out):
    """{(level, shift): row} with the longest run of each, the row's file and job times added;
    its cost_cpu is that run's CPU time scaled by 12 / t_end: the cost and the errors of one run
    (a shorter run of the same alignment may not have reached the flapping's amplitude)."""
    best = {}
    for path in sorted(glob.glob(os.path.join(out, "fsi2_shift*.json"))):
        m = re.fullmatch(r"fsi2_shift(?:-(XY\d+))?(?:-t([\d.]+))?\.json", os.path.basename(path))
        if not m:
            continue
        level = m.group(1) or "XY82"
        if level not in LEVELS:
            continue
        for row in json.load(open(path)):
            t_end = row.get("t_end", 12.0)
            folder = f"fsi2-{level}" + (f"-shift{row['shift']:g}" if row["shift"] else "") + \
                (f"-t{float(m.group(2)):g}" if m.group(2) else "")
            times = os.path.join(out, folder, "job_time.json")
            if not os.path.exists(times):
                print(f"cost.py: {folder}: no job_time.json, left out", file=sys.stderr)
                continue
            jt = json.load(open(times))
            key = (level, row["shift"])
            if key not in best or t_end > best[key]["t_end"]:
                best[key] = dict(row, t_end=t_end, level=level, folder=folder,
                                 wall=jt["wall_s"], cpu=jt["cpu_s"])
    for r in best.values():
        r["cost_cpu"] = r["cpu"] * CASE_T_END / r["t_end"]
    return best


def errors(row, ref, case):
    """Signed relative errors in % of the QUANTITIES against one reference case."""
    e = {}
    for q, part, label in QUANTITIES:
        value = row["results"].get(q, {}).get(part)
        r = ref[(case, q.replace("_smoothed", ""))][part]
        e[label] = None if value is None else 100 * (value - r) / r
    return e


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=os.environ.get("FSI_OUT", os.path.join(HERE, "..", "..", "out",
                                                                           "turek-hron-fsi")))
    a = ap.parse_args()
    a.out = os.path.abspath(a.out)
    ref = read_reference()
    rows = study_rows(a.out)
    if not rows:
        sys.exit(f"cost.py: no FSI2 shift study with job times in {a.out} (validate.py --xy-shift ...)")
    table = []
    for (level, s), r in sorted(rows.items(), key=lambda kv: (LEVELS[kv[0][0]][1], kv[0][1])):
        table.append({"level": level, "cells": LEVELS[level][0], "bar_cells": LEVELS[level][1],
                      "shift": s, "t_end": r["t_end"], "wall_s": r["wall"], "cpu_s": r["cpu"],
                      "cpu_s_to_12": r["cost_cpu"],
                      "vs_2006": errors(r, ref, "fsi2"), "vs_refined": errors(r, ref, "fsi2-refined")})
    labels = [q[2] for q in QUANTITIES]
    print("FSI2 error (%) against CPU seconds, 2006 table [refined values]")
    print("| level | cells | bar cells | s | t_end | wall s | CPU s | CPU s to t = 12 | " + " | ".join(labels) + " |")
    print("|" + "---|" * (8 + len(labels)))
    def cell(a, b):
        return "-" if a is None else f"{a:+.1f} [{b:+.1f}]"

    def mean_of(values):
        values = [v for v in values if v is not None]
        return sum(values) / len(values) if values else None

    for t in table:
        cols = [cell(t["vs_2006"][k], t["vs_refined"][k]) for k in labels]
        print(f"| {t['level']} | {t['cells']} | {t['bar_cells']} | {t['shift']:g} | {t['t_end']:g} | "
              f"{t['wall_s']:.0f} | {t['cpu_s']:.0f} | {t['cpu_s_to_12']:.0f} | " + " | ".join(cols) + " |")
    means = []
    for level in LEVELS:
        ts = [t for t in table if t["level"] == level]
        if not ts:
            continue
        mean = {"level": level, "alignments": [t["shift"] for t in ts], "bar_cells": LEVELS[level][1],
                "cpu_s_to_12_mean": sum(t["cpu_s_to_12"] for t in ts) / len(ts)}
        for ref_name in ("vs_2006", "vs_refined"):
            mean[ref_name] = {k: mean_of(t[ref_name][k] for t in ts) for k in labels}
        means.append(mean)
        cols = [cell(mean["vs_2006"][k], mean["vs_refined"][k]) for k in labels]
        print(f"| {level} mean over s = {', '.join(f'{s:g}' for s in mean['alignments'])} | | "
              f"{LEVELS[level][1]} | | | | | {mean['cpu_s_to_12_mean']:.0f} | " + " | ".join(cols) + " |")
    json.dump({"runs": table, "level_means": means}, open(os.path.join(a.out, "cost.json"), "w"), indent=1)
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("cost.py: no matplotlib, no cost.png", file=sys.stderr)
        return
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5), sharey=True)
    markers = dict(zip(labels, "osD^v"))
    for ax, ref_name, title in zip(axes, ("vs_2006", "vs_refined"), ("2006 table", "refined FEATFLOW values")):
        for k in labels:
            pts = [(t["cpu_s_to_12"], abs(t[ref_name][k])) for t in table if t[ref_name][k] is not None]
            mpts = [(m["cpu_s_to_12_mean"], abs(m[ref_name][k])) for m in means if m[ref_name][k] is not None]
            line = ax.loglog([p[0] for p in pts], [p[1] for p in pts], markers[k], alpha=0.35, ms=4)[0]
            ax.loglog([p[0] for p in mpts], [p[1] for p in mpts], "-" + markers[k], color=line.get_color(),
                      label=f"{k} (line: mean over the alignments run)")
        ax.axhline(3, color="k", ls=":", lw=0.8)  # the 3 % target
        ax.set_xlabel("CPU seconds of the job to t = 12 (both cores)")
        ax.set_title(f"FSI2 against the {title}", fontsize=9)
        ax.grid(True, which="both", lw=0.3)
    axes[0].set_ylabel("|error| %")
    axes[1].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, "cost.png"), dpi=120)
    print(f"cost.py: {os.path.join(a.out, 'cost.json')}, {os.path.join(a.out, 'cost.png')}")


if __name__ == "__main__":
    main()
