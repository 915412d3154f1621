#!/usr/bin/python3
"""Womersley flow between plane walls: periodic in x, walls at y = 0 and H, driven by the
sinusoidal pressure gradient -dp/dx = A sin(omega t) (paper Eq. 29) as a body force. The
time-periodic exact solution is u = Im[U(y) exp(i omega t)] with
    U(y) = A / (i omega rho) (1 - cosh(k (y - H/2)) / cosh(k H / 2)),  k = sqrt(i omega / nu).
Metrics: amplitude and phase of the centreline velocity over the last period, 32 cells across."""
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
OUT = job.out_dir("womersley")

H, RHO, NU, A, T = 1.0, 1.0, 0.05, 1.0, 2.0
OMEGA = 2 * np.pi / T
NY = 32
PERIODS = 10  # the start-up transient decays like exp(-nu pi^2 t / H^2): e^-10 after 10 periods
DT = T / 1000
Y_PROBE = (NY // 2 + 0.5) * H / NY  # a cell centre next to the centreline

SCENE = f"""
[scene]
name = "womersley"
[time]
dt = {DT}
t_end = {PERIODS * T}
[output]
interval = {T / 4}
[fluid]
density = {RHO}
viscosity = {RHO * NU}
[fluid.grid]
cells = [4, {NY}]
size = [0.5, {H}]
[fluid.boundary]
left = {{ type = "periodic" }}
right = {{ type = "periodic" }}
bottom = {{ type = "wall" }}
top = {{ type = "wall" }}
[fluid.forcing]
oscillating = [{A}, 0.0]
period = {T}
[[fluid.probes]]
name = "c"
at = [0.25, {Y_PROBE}]
"""


def exact_hat(y):
    k = np.sqrt(1j * OMEGA / NU)
    return A / (1j * OMEGA * RHO) * (1 - np.cosh(k * (y - H / 2)) / np.cosh(k * H / 2))


folder, wall, *_ = job.run("womersley", SCENE)
p = fluidout.probes(folder)
t, u = p["time"], p["c.ux"]
last = t >= t[-1] - T - 1e-12
M = np.column_stack([np.sin(OMEGA * t[last]), np.cos(OMEGA * t[last]), np.ones(last.sum())])
a, b, _ = np.linalg.lstsq(M, u[last], rcond=None)[0]
amp, phase = np.hypot(a, b), np.arctan2(b, a)
U = exact_hat(Y_PROBE)
amp_ex, phase_ex = abs(U), np.arctan2(U.imag, U.real)
dphi = (phase - phase_ex + np.pi) % (2 * np.pi) - np.pi
metrics = {
    "centreline_amplitude": metric(amp, amp_ex, abs(amp - amp_ex) / amp_ex, 0.01),
    "centreline_phase_fraction_of_period": metric(phase / (2 * np.pi), phase_ex / (2 * np.pi),
                                                     abs(dphi) / (2 * np.pi), 0.01),
}
fig, ax = plt.subplots(1, 2, figsize=(9, 3.5))
ax[0].plot(t, u, "b-", lw=0.8, label="computed")
ax[0].plot(t, (U * np.exp(1j * OMEGA * t)).imag, "k--", lw=0.8, label="exact periodic")
ax[0].set_xlabel("t")
ax[0].set_ylabel("u centreline")
ax[0].legend(fontsize=7)
d = fluidout.last_state(folder)
yy = np.linspace(0, H, 200)
ax[1].plot(d["u_face"][:, 0], d["y_centre"], "o", ms=3, label=f"t = {d['time']:.3g}")
ax[1].plot((exact_hat(yy) * np.exp(1j * OMEGA * d["time"])).imag, yy, "k-", lw=0.8, label="exact")
ax[1].set_xlabel("u")
ax[1].set_ylabel("y")
ax[1].legend(fontsize=7)
plt.tight_layout()
plt.savefig(os.path.join(OUT, "womersley.png"), dpi=120)
finish("womersley", metrics, {"grid": [4, NY], "dt": DT, "wall_s": wall,
                                 "womersley_number": H / 2 * np.sqrt(OMEGA / NU)}, short=ARGS.short)
