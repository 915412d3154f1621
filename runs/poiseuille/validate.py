#!/usr/bin/python3
"""Plane Poiseuille flow: periodic in x, walls at y = 0 and H, driven by a constant pressure
gradient G = -dp/dx as a body force. Exact steady profile u = G/(2 mu) y (H - y); the MAC scheme
with its quadratic wall closure reproduces it to round-off, for explicit and implicit diffusion
and on a tanh-stretched grid."""
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
OUT = job.out_dir("poiseuille")

SCENE = """
[scene]
name = "poiseuille-{tag}"
[time]
dt = {dt}
t_end = {t_end}
[output]
interval = {t_end}
[fluid]
density = 1.0
viscosity = 1.0
diffusion = "{diffusion}"
[fluid.grid]
cells = [8, {ny}]
size = [1.0, 1.0]
y_stretch = {beta}
[fluid.boundary]
left = {{ type = "periodic" }}
right = {{ type = "periodic" }}
bottom = {{ type = "wall" }}
top = {{ type = "wall" }}
[fluid.forcing]
body = [2.0, 0.0]
[fluid.diagnostics]
wall_shear = "bottom"
"""

ny = 16 if ARGS.short else 32
metrics, rows = {}, []
plt.figure(figsize=(5, 4))
# Crank-Nicolson damps the stiffest modes slowly (amplification -> -1 for nu dt / h^2 >> 1), so
# the stretched grid, whose wall cells are small, takes a smaller dt.
for tag, diffusion, beta, dt in [("explicit", "explicit", 0.0, 0.9 / (4 * (64 + ny * ny))),
                                 ("implicit", "implicit", 0.0, 0.01),
                                 ("stretched", "implicit", 1.5, 0.001)]:
    folder, wall, *_ = job.run(f"poiseuille-{tag}", SCENE.format(tag=tag, dt=dt, t_end=3.0, diffusion=diffusion,
                                                             ny=ny, beta=beta))
    d = fluidout.last_state(folder)
    y = d["y_centre"]
    exact = y * (1 - y)  # G/(2 mu) y (H - y) with G = 2, mu = 1, H = 1
    err = np.max(np.abs(d["u_face"] - exact[:, None]))
    metrics[f"max_error_{tag}"] = metric(err, 0.0, err, 1e-10)
    rows.append((tag, ny, dt, err, wall))
    plt.plot(d["u_face"][:, 0], y, "o", ms=3, label=f"{tag} (max err {err:.1e})")
yy = np.linspace(0, 1, 200)
plt.plot(yy * (1 - yy), yy, "k-", lw=0.8, label="exact")
plt.xlabel("u")
plt.ylabel("y")
plt.legend(fontsize=7)
plt.tight_layout()
plt.savefig(os.path.join(OUT, "profile.png"), dpi=120)
finish("poiseuille", metrics, {"runs": [dict(zip(["variant", "ny", "dt", "max_error", "wall_s"], r)) for r in rows]}, short=ARGS.short)
