#!/usr/bin/python3
"""Picture of the default scene (coarse Turek-Hron FSI2): the vorticity at the last output step
with the cylinder and the deformed bar, and the history of point A's vertical displacement.

usage: plot.py [OUT_DIR]   (./fsi run calls it after the run)
"""
import argparse
import os

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.tri as mtri  # noqa: E402
import numpy as np  # noqa: E402


def main(out):
    with h5py.File(os.path.join(out, "fluid.h5"), "r") as f, \
            h5py.File(os.path.join(out, "solid.h5"), "r") as s:
        steps = sorted((k for k in f.keys() if k.startswith("step_") and k in s),
                       key=lambda k: int(k.split("_")[1]))
        last = steps[-1]
        xf, yf = f["grid/x_face"][:], f["grid/y_face"][:]
        w = f[last]["vorticity"][:]
        t = float(s[last].attrs.get("time", float("nan")))
        fig = plt.figure(figsize=(11, 5.2))
        ax = fig.add_axes([0.08, 0.45, 0.88, 0.5])
        lim = np.percentile(np.abs(w), 98)
        ax.pcolormesh(xf, yf, w, cmap="RdBu_r", vmin=-lim, vmax=lim, shading="flat")
        for name in (k for k in s.keys() if k.startswith("body_")):
            tri = s[name]["triangles"][:]
            x = s[last][name]["position"][:]
            tr = mtri.Triangulation(x[:, 0], x[:, 1], tri)
            ax.tripcolor(tr, np.ones(len(tri)), cmap="Greys", vmin=0, vmax=1.6)
            ax.triplot(tr, color="0.15", lw=0.2)
        ax.set_aspect("equal")
        ax.set_xlim(xf[0], 1.5)
        ax.set_ylim(yf[0], yf[-1])
        ax.set_title(f"Turek-Hron FSI2 (coarse): vorticity, cylinder and bar, t = {t:.3g} s")
    p = np.genfromtxt(os.path.join(out, "solid_probes.csv"), delimiter=",", names=True,
                      deletechars="")
    ax2 = fig.add_axes([0.08, 0.08, 0.88, 0.27])
    ax2.plot(p["time"], p["A.uy"], lw=0.8)
    for y in (1.23e-3 - 80.6e-3, 1.23e-3 + 80.6e-3):
        ax2.axhline(y, color="k", ls=":", lw=0.8)
    ax2.set_xlabel("t [s]")
    ax2.set_ylabel("u_y(A) [m]")
    ax2.set_title("point A (dotted: Turek & Hron mean ± amplitude)", fontsize=9)
    png = os.path.join(out, "picture.png")
    fig.savefig(png, dpi=120)
    print("picture:", png)


if __name__ == "__main__":
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("out", nargs="?", default=".", help="the run's output folder")
    main(p.parse_args().out)
