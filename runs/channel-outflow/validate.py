#!/usr/bin/python3
"""Channel with a convective (Orlanski-type) outlet and a stretched upwind sponge.
1. Parabolic inflow (mean 1) between no-slip walls, Re = 100: the outflow must stay parabolic;
   metric: max |u - u_parabola| / u_max on the last physical face column x = L.
2. A Gaussian vortex (peak swirl 0.5, radius 0.2) carried by a uniform stream U = 1 between free-
   slip walls (whose exact base flow is the uniform stream) through the outlet: the perturbation
   kinetic energy (1/2) int |u - U|^2 in the physical domain x <= L, at its largest once the
   vortex core has left (t >= 2.5: the centre crosses x = L at t = 1.5, plus 4 radii), over its
   initial value, measures the reflection; must be < 1 %.
--short: a coarser grid (h = 1/16 instead of 1/32), the same tolerances."""
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
import h5py  # noqa: E402
from metrics import finish, metric  # noqa: E402

ARGS = cli.parser(__doc__).parse_args()
OUT = job.out_dir("channel-outflow")

PER = 16 if ARGS.short else 32  # cells per unit length
LX, LY = 4.0, 1.0

PARABOLIC = f"""
[scene]
name = "channel-parabolic"
[time]
dt = {0.25 / PER}
t_end = 16.0
[output]
interval = 4.0
[fluid]
density = 1.0
viscosity = 0.01
[fluid.grid]
cells = [{int(LX * PER)}, {int(LY * PER)}]
size = [{LX}, {LY}]
[fluid.boundary]
left = {{ type = "inflow", profile = "parabolic", mean = 1.0, ramp = "cosine", ramp_time = 1.0 }}
right = {{ type = "outflow" }}
bottom = {{ type = "wall" }}
top = {{ type = "wall" }}
[fluid.sponge]
cells = {PER // 2}
ratio = 1.1
[fluid.diagnostics]
wall_shear = "bottom"
"""

VORTEX = f"""
[scene]
name = "channel-vortex"
[time]
dt = {0.3 / PER}
t_end = 5.0
[output]
interval = 0.25
[fluid]
density = 1.0
viscosity = 0.001
[fluid.grid]
cells = [{int(LX * PER)}, {int(2 * LY * PER)}]
size = [{LX}, {2 * LY}]
[fluid.boundary]
left = {{ type = "inflow", profile = "uniform", mean = 1.0 }}
right = {{ type = "outflow", phase = "{{phase}}" }}
bottom = {{ type = "slip" }}
top = {{ type = "slip" }}
[fluid.sponge]
cells = {PER // 2}
ratio = 1.1
[fluid.initial]
type = "vortex"
velocity = [1.0, 0.0]
amplitude = 0.5
centre = [2.5, 1.0]
radius = 0.2
"""

metrics, runs = {}, []
folder, wall, *_ = job.run("channel-parabolic", PARABOLIC)
d = fluidout.last_state(folder)
i_out = int(LX * PER)  # face x = L (the sponge starts there)
y = d["y_centre"]
exact = 6.0 * y * (LY - y) / LY ** 2
err = np.max(np.abs(d["u_face"][:, i_out] - exact)) / 1.5
metrics["parabolic_outflow_max_relative_error"] = metric(err, 0.0, err, 0.01)
runs.append({"case": "parabolic", "per_unit": PER, "wall_s": wall, "error": err})
fig, ax = plt.subplots(1, 2, figsize=(10, 3.8))
for i in [0, i_out // 2, i_out]:
    ax[0].plot(d["u_face"][:, i], y, label=f"x = {d['x_face'][i]:.2f}")
ax[0].plot(exact, y, "k--", lw=0.8, label="parabola")
ax[0].set_xlabel("u")
ax[0].set_ylabel("y")
ax[0].legend(fontsize=7)


def perturbation_energy(step_group, h, x_face, y_face):
    u = np.array(h[step_group]["u_face"]) - 1.0
    v = np.array(h[step_group]["v_face"])
    dx, dy = np.diff(x_face), np.diff(y_face)
    xc = 0.5 * (x_face[1:] + x_face[:-1])
    inside_u = x_face <= LX + 1e-12
    inside_c = xc <= LX
    # face control volumes: half of each neighbouring cell
    wu = 0.5 * (np.concatenate([[0], dx]) + np.concatenate([dx, [0]]))
    wv = 0.5 * (np.concatenate([[0], dy]) + np.concatenate([dy, [0]]))
    eu = np.sum((u[:, inside_u] ** 2) * wu[inside_u][None, :] * dy[:, None])
    ev = np.sum((v[:, inside_c] ** 2) * dx[inside_c][None, :] * wv[:, None])
    return 0.5 * (eu + ev)


for phase in ["bulk", "orlanski"]:
    folder, wall, *_ = job.run(f"channel-vortex-{phase}", VORTEX.replace("{phase}", phase))
    with h5py.File(os.path.join(folder, "fluid.h5"), "r") as h:
        xf, yf = np.array(h["grid/x_face"]), np.array(h["grid/y_face"])
        steps = sorted(k for k in h.keys() if k.startswith("step_"))
        t = np.array([h[s].attrs["time"] for s in steps])
        e = np.array([perturbation_energy(s, h, xf, yf) for s in steps])
    ratio = np.max(e[t >= 2.5 - 1e-9]) / e[0]
    metrics[f"vortex_reflected_energy_fraction_{phase}"] = metric(ratio, 0.0, ratio, 0.01)
    runs.append({"case": f"vortex-{phase}", "per_unit": PER, "wall_s": wall, "energy_ratio": ratio})
    ax[1].semilogy(t, e / e[0], label=f"outlet phase speed: {phase}")
ax[1].axhline(0.01, color="k", lw=0.7, ls="--")
ax[1].set_xlabel("t")
ax[1].set_ylabel("perturbation energy in x <= L / initial")
ax[1].legend(fontsize=7)
plt.tight_layout()
plt.savefig(os.path.join(OUT, "channel_outflow.png"), dpi=120)
finish("channel-outflow", metrics, {"runs": runs}, short=ARGS.short)
