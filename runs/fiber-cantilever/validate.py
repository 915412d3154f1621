#!/usr/bin/python3
"""Cantilever in vacuum, small amplitude: the first two bending frequencies of a clamped-free
fiber against Euler-Bernoulli, omega_k = (beta_k L)^2 sqrt(gamma / (rho' L^4)), and their
convergence with the number of segments. The fiber starts at rest in the shape of mode k
(tip deflection 1e-3 L); the frequency is measured from the zero crossings of the tip deflection
over whole periods."""
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import cli  # noqa: E402
import fiberout  # noqa: E402
import job  # noqa: E402
import scenes  # noqa: E402
import series  # noqa: E402
import matplotlib  # noqa: E402
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from metrics import finish, metric  # noqa: E402

ARGS = cli.parser(__doc__).parse_args()
OUT = job.out_dir("fiber-cantilever")

BETA = [1.875104068711961, 4.694091132974175]  # beta_k L (other-cases.md)
L, RHO, GAMMA = 1.0, 1.0, 1.0


def mode_slope(k, s):
    b = BETA[k - 1] / L
    bl = BETA[k - 1]
    sigma = (math.cosh(bl) + math.cos(bl)) / (math.sinh(bl) + math.sin(bl))
    return b * (np.sinh(b * s) + np.sin(b * s) - sigma * (np.cosh(b * s) - np.cos(b * s)))


def shape(k, n, tip=1e-3):
    """Markers along x deflected in mode k, from the tangent angle (every segment exactly ds)."""
    ds = L / n
    eps = tip / 2.0  # phi_k(L) = 2 for the clamped-free modes
    psi = np.arctan(eps * mode_slope(k, (np.arange(n) + 0.5) * ds))
    p = np.zeros((n + 1, 2))
    p[1:, 0] = np.cumsum(ds * np.cos(psi))
    p[1:, 1] = np.cumsum(ds * np.sin(psi))
    return p


SCENE = scenes.HEADER + """
[fiber]
probe_interval = {probe_dt!r}
[[fiber.fiber]]
name = "beam"
length = {L}
segments = {n}
density = {rho}
bending = {gamma}
shape = "points"
points = "{points}"
[fiber.fiber.root]
kind = "clamped"
angle = 0
[[fiber.probe]]
name = "tip"
fiber = "beam"
s = {L}
"""

segments = [12, 24] if ARGS.short else [8, 16, 32, 64]
periods = [3.2, 8.2]
errors = {1: [], 2: []}
rows = []
fig, ax = plt.subplots(1, 2, figsize=(10, 4))
for n in segments:
    ds = L / n
    dt = 0.9 * ds * ds * math.sqrt(RHO / (12 * GAMMA))  # 0.9 of the explicit bending limit
    for k in (1, 2):
        omega = BETA[k - 1] ** 2 * math.sqrt(GAMMA / (RHO * L ** 4))
        name = f"cantilever-n{n}-mode{k}"
        pts = scenes.write_points(OUT, name, shape(k, n))
        t_end = periods[k - 1] * 2 * math.pi / omega
        folder, wall, *_ = job.run(name, SCENE.format(name=name, dt=dt, t_end=t_end, interval=0.0, probe_dt=2 * math.pi / omega / 4000, L=L, n=n,
                                                 rho=RHO, gamma=GAMMA, points=pts))
        p = fiberout.probes(folder)
        w = 2 * math.pi / series.period(p["time"], p["tip.y"])
        err = w / omega - 1
        errors[k].append(err)
        rows.append({"segments": n, "mode": k, "dt": dt, "omega": w, "omega_exact": omega,
                     "relative_error": err, "wall_s": wall})
        print(f"  {n} segments, mode {k}: omega = {w:.6f} (exact {omega:.6f}), error {err:+.3e}, {wall:.1f} s")
        if n == segments[-1]:
            ax[0].plot(p["time"] / (2 * math.pi / omega), p["tip.y"] / 1e-3, label=f"mode {k}, {n} segments")

metrics = {}
finest = segments[-1]
for k in (1, 2):
    metrics[f"omega{k}_error_{finest}_segments"] = metric(
        rows[-3 + k]["omega"], rows[-3 + k]["omega_exact"], abs(errors[k][-1]), 0.01)
    # observed order between the two finest resolutions (second order expected)
    order = math.log(abs(errors[k][-2] / errors[k][-1])) / math.log(segments[-1] / segments[-2])
    metrics[f"omega{k}_order"] = metric(order, 2.0, abs(order - 2.0), 0.2)
# 1 % is reached from this resolution on (the case's target)
for k in (1, 2):
    first_ok = next((n for n, e in zip(segments, errors[k]) if abs(e) <= 0.01), None)
    print(f"  mode {k}: within 1 % from {first_ok} segments on")

ax[0].set_xlabel("t / T_k")
ax[0].set_ylabel("tip deflection / 1e-3 L")
ax[0].legend(fontsize=8)
for k in (1, 2):
    ax[1].loglog(segments, np.abs(errors[k]), "o-", label=f"mode {k}")
ax[1].loglog(segments, [abs(errors[2][0]) * (segments[0] / n) ** 2 for n in segments], "k--", lw=0.8,
             label="second order")
ax[1].axhline(0.01, color="r", lw=0.8, ls=":", label="1 %")
ax[1].set_xlabel("segments")
ax[1].set_ylabel("|omega / omega_EB - 1|")
ax[1].legend(fontsize=8)
fig.tight_layout()
fig.savefig(os.path.join(OUT, "cantilever.png"), dpi=120)
finish("fiber-cantilever", metrics, {"runs": rows}, short=ARGS.short)
