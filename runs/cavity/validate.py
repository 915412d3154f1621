#!/usr/bin/python3
"""Lid-driven cavity (side 1, lid speed 1) at Re = 100 on 128^2 and Re = 1000 on 256^2, run to a
steady state and compared with the centreline tables of Ghia, Ghia & Shin (1982) (ghia1982.csv):
max |u - u_Ghia| along x = 0.5 and max |v - v_Ghia| along y = 0.5 must be <= 0.02.
--short: Re = 100 on 64^2 only, tolerance 0.05 (a coarser grid; set before measuring)."""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import cli  # noqa: E402
import fluidout  # noqa: E402
import job  # noqa: E402
import matplotlib  # noqa: E402
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from metrics import finish, metric  # noqa: E402

ARGS = cli.parser(__doc__).parse_args()
OUT = job.out_dir("cavity")

HERE = os.path.dirname(os.path.abspath(__file__))
ghia = np.genfromtxt(os.path.join(HERE, "ghia1982.csv"), delimiter=",", names=True, skip_header=4)

SCENE = """
[scene]
name = "cavity-re{re}"
[time]
dt = {dt}
t_end = {t_end}
[output]
interval = {interval}
[fluid]
density = 1.0
viscosity = {nu}
diffusion = "{diffusion}"
[fluid.grid]
cells = [{n}, {n}]
size = [1.0, 1.0]
[fluid.boundary]
left = {{ type = "wall" }}
right = {{ type = "wall" }}
bottom = {{ type = "wall" }}
top = {{ type = "wall", velocity = 1.0 }}
[[fluid.probes]]
name = "centre"
at = [0.5, 0.5]
"""

if ARGS.short:
    cases = [(100, 64, 0.008, 20.0, "implicit", 0.05)]
else:
    cases = [(100, 128, 0.004, 30.0, "implicit", 0.02), (1000, 256, 0.0018, 60.0, "explicit", 0.02)]

metrics, runs = {}, []
fig, ax = plt.subplots(1, len(cases), figsize=(5 * len(cases), 4.5), squeeze=False)
for k, (re, n, dt, t_end, diffusion, tol) in enumerate(cases):
    folder, wall, *_ = job.run(f"cavity-re{re}-{n}", SCENE.format(re=re, dt=dt, t_end=t_end, interval=t_end / 6,
                                                            nu=1.0 / re, diffusion=diffusion, n=n))
    d = fluidout.last_state(folder)
    # u on the face column x = 0.5 (n even), with the wall values at y = 0 and 1.
    i = n // 2
    yu = np.concatenate([[0.0], d["y_centre"], [1.0]])
    u = np.concatenate([[0.0], d["u_face"][:, i], [1.0]])
    # v on the face row y = 0.5, with the wall values at x = 0 and 1.
    xv = np.concatenate([[0.0], d["x_centre"], [1.0]])
    v = np.concatenate([[0.0], d["v_face"][n // 2, :], [0.0]])
    du = np.abs(np.interp(ghia["y"], yu, u) - ghia[f"u{re}"])
    dv = np.abs(np.interp(ghia["x"], xv, v) - ghia[f"v{re}"])
    dev = max(du.max(), dv.max())
    metrics[f"re{re}_{n}_max_deviation"] = metric(dev, 0.0, dev, tol)
    # Steadiness: change of the centre probe over the last tenth of the run.
    p = fluidout.probes(folder)
    late = p["time"] >= 0.9 * t_end
    drift = float(np.ptp(p["centre.ux"][late]))
    runs.append({"re": re, "n": n, "dt": dt, "t_end": t_end, "diffusion": diffusion, "wall_s": wall,
                 "max_dev_u": float(du.max()), "max_dev_v": float(dv.max()), "late_probe_drift": drift})
    a = ax[0][k]
    a.plot(u, yu, "b-", lw=1, label="u(0.5, y)")
    a.plot(ghia[f"u{re}"], ghia["y"], "bo", ms=4, mfc="none", label="Ghia u")
    a.plot(xv, v, "r-", lw=1, label="v(x, 0.5)")
    a.plot(ghia["x"], ghia[f"v{re}"], "rs", ms=4, mfc="none", label="Ghia v")
    a.set_title(f"Re = {re}, {n}^2: max deviation {dev:.4f}")
    a.legend(fontsize=7)
plt.tight_layout()
plt.savefig(os.path.join(OUT, "centrelines.png"), dpi=120)
finish("cavity", metrics, {"runs": runs}, short=ARGS.short)
