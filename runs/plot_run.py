#!/usr/bin/python3
"""Generic post-processing of a run folder: one PNG of every probe CSV's columns against time.

usage: plot_run.py [OUT_DIR]   (./fsi run calls it when the scene's folder has no plot.py)
"""
import argparse
import glob
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def main(out):
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
    if made:
        print("plots:", ", ".join(os.path.relpath(p) for p in made))
    else:
        print("no probe files to plot in", out)


if __name__ == "__main__":
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("out", nargs="?", default=".", help="the run's output folder")
    main(p.parse_args().out)
