#!/usr/bin/python3
"""Generic post-processing of a run folder: picture.png (the last output step's fluid field, the
bodies' meshes, the fibers and the probes' histories, chosen from what the run wrote: see
runs/lib/picture.py) and one PNG of every CSV's columns against time.

usage: plot_run.py [OUT_DIR] [--no-csv]   (./fsi run calls it when the scene's folder has no plot.py)
"""
import argparse
import glob
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "lib"))
import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import picture  # noqa: E402


def csv_plots(out):
    made = []
    for csv in sorted(glob.glob(os.path.join(out, "*.csv"))):
        with open(csv) as f:
            header = f.readline().strip().split(",")
        data = np.loadtxt(csv, delimiter=",", skiprows=1, ndmin=2)
        if data.size == 0 or len(header) < 2:
            continue
        n = len(header) - 1
        fig, axes = plt.subplots(n, 1, figsize=(7, 1.8 * n + 0.8), sharex=True, squeeze=False)
        for k in range(n):
            ax = axes[k, 0]
            ax.plot(data[:, 0], data[:, k + 1], lw=1)
            ax.set_ylabel(header[k + 1])
            ax.grid(alpha=0.3)
        axes[-1, 0].set_xlabel(header[0])
        fig.suptitle(os.path.basename(csv))
        fig.tight_layout()
        png = os.path.splitext(csv)[0] + ".png"
        fig.savefig(png, dpi=110)
        plt.close(fig)
        made.append(png)
    return made


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("out", nargs="?", default=".", help="the run's output folder")
    p.add_argument("--no-csv", action="store_true", help="only picture.png, no plot per CSV file")
    a = p.parse_args()
    if not os.path.isdir(a.out):
        raise SystemExit(f"plot_run.py: no output folder {a.out}")
    try:
        png, shows = picture.picture(a.out)
        print(f"picture: {os.path.relpath(png)} ({shows})")
    except picture.NoFields as e:
        print(f"no picture: {e} (set [output] interval for field output)")
    made = [] if a.no_csv else csv_plots(a.out)
    if made:
        print("plots:", ", ".join(os.path.relpath(p) for p in made))


if __name__ == "__main__":
    main()
