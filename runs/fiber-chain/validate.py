#!/usr/bin/python3
"""Bending-free chain (gamma = 0) under gravity. (a) Hanging from a hinge it stays at rest with
the exact tension T(s) = rho' g (L - s). (b) Between two hinges, started in the exact discrete
catenary (equal segments, equal marker weights: tan psi_j = (j - (N - 1)/2) rho' g ds / H), it
stays at rest; the tension is H / cos psi_j and each hinge carries half the weight. (c) Released
from rest 45 degrees sideways from a hinge it swings, and the tension stays positive along the
chain (up to the free end, where T = 0) at every output step."""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import cli  # noqa: E402
import fiberout  # noqa: E402
import job  # noqa: E402
import outputs  # noqa: E402
import scenes  # noqa: E402
import matplotlib  # noqa: E402
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from metrics import finish, metric  # noqa: E402

ARGS = cli.parser(__doc__).parse_args()
OUT = job.out_dir("fiber-chain")

L, RHO, G = 1.0, 0.5, 9.81
N = 20 if ARGS.short else 40
DS = L / N

HANGING = scenes.HEADER + """
[fiber]
gravity = [0, {g_neg!r}]
[[fiber.fiber]]
name = "chain"
length = {L}
segments = {n}
density = {rho}
bending = 0
position = [0, 0]
angle = {angle!r}
[fiber.fiber.root]
kind = "hinged"
"""

CATENARY = scenes.HEADER + """
[fiber]
gravity = [0, {g_neg!r}]
[[fiber.fiber]]
name = "chain"
length = {L}
segments = {n}
density = {rho}
bending = 0
shape = "points"
points = "{points}"
[fiber.fiber.root]
kind = "hinged"
[fiber.fiber.tip]
kind = "hinged"
"""

metrics, extra = {}, {}
fig, ax = plt.subplots(1, 3, figsize=(13, 4))

# (a) hanging at rest
t_end = 0.2 if ARGS.short else 2.0
folder, wall, *_ = job.run("chain-hanging", HANGING.format(name="chain-hanging", dt=1e-3, t_end=t_end, interval=t_end,
                                                       g_neg=-G, L=L, n=N, rho=RHO, angle=-90.0))
st = fiberout.steps(folder)
moved = np.max(np.abs(st[-1]["X"] - st[0]["X"]))
s = np.arange(N + 1) * DS
exact = RHO * G * (L - s)
t_err = np.max(np.abs(st[-1]["tension"][1:N] - exact[1:N])) / (RHO * G * L)
metrics["hanging_displacement"] = metric(moved, 0.0, moved, 1e-12)
metrics["hanging_tension_error"] = metric(t_err, 0.0, t_err, 1e-8)
ax[0].plot(s, st[-1]["tension"], "o", ms=3, label="hanging, computed")
ax[0].plot(s, exact, "k-", lw=0.8, label="rho' g (L - s)")

# (b) discrete catenary between two hinges
H = 0.6 * RHO * G * L  # horizontal tension
c = RHO * G * DS / H
psi = np.arctan((np.arange(N) - (N - 1) / 2) * c)
pts = np.zeros((N + 1, 2))
pts[1:, 0] = np.cumsum(DS * np.cos(psi))
pts[1:, 1] = np.cumsum(DS * np.sin(psi))
pname = scenes.write_points(OUT, "chain-catenary", pts)
folder, wall, *_ = job.run("chain-catenary", CATENARY.format(name="chain-catenary", dt=1e-3, t_end=t_end, interval=t_end,
                                                         g_neg=-G, L=L, n=N, rho=RHO, points=pname))
st = fiberout.steps(folder)
moved = np.max(np.abs(st[-1]["X"] - st[0]["X"]))
seg_t = H / np.cos(psi)
marker_t = np.concatenate([[seg_t[0]], 0.5 * (seg_t[1:] + seg_t[:-1]), [seg_t[-1]]])
cat_err = np.max(np.abs(st[-1]["tension"] - marker_t)) / H
ld = fiberout.loads(folder)
weight = RHO * G * L
half = np.max(np.abs(np.array([ld["chain.fy"][-1], ld["chain_tip.fy"][-1]]) + weight / 2)) / weight
metrics["catenary_displacement"] = metric(moved, 0.0, moved, 1e-12)
metrics["catenary_tension_error"] = metric(cat_err, 0.0, cat_err, 1e-8)
metrics["catenary_hinge_loads"] = metric(half, 0.0, half, 1e-8)
ax[1].plot(pts[:, 0], pts[:, 1], "k-", lw=0.8, label="discrete catenary")
ax[1].plot(st[-1]["X"][:, 0], st[-1]["X"][:, 1], "o", ms=3, label=f"t = {st[-1]['time']:g}")
ax[1].set_aspect("equal")

# (c) released sideways
t_swing = 0.8 if ARGS.short else 4.0
folder, wall, *_ = job.run("chain-swing", HANGING.format(name="chain-swing", dt=1e-4, t_end=t_swing, interval=0.01,
                                                     g_neg=-G, L=L, n=N, rho=RHO, angle=-45.0))
st = fiberout.steps(folder)
tmin = min(float(np.min(x["tension"][:N])) for x in st[1:])  # all markers but the free end, after t = 0
scale = RHO * G * DS  # the weight of one segment
rep = outputs.summary(folder)["fiber"]
metrics["swing_min_tension"] = metric(tmin / scale, 0.0, max(0.0, -tmin / scale), 0.0)
metrics["swing_max_stretch"] = metric(rep["max_stretch"], 0.0, rep["max_stretch"], 1e-10)
extra["swing"] = {"min_tension_over_segment_weight": tmin / scale, "max_stretch": rep["max_stretch"],
                  "outputs": len(st), "wall_s": wall}
for x in st[:: max(1, len(st) // 12)]:
    ax[2].plot(x["X"][:, 0], x["X"][:, 1], "-", lw=0.8)
ax[2].set_aspect("equal")
ax[2].set_title(f"swing: min T = {tmin / scale:.2f} rho' g ds")
ax[0].set_xlabel("s")
ax[0].set_ylabel("tension")
ax[0].legend(fontsize=8)
ax[1].legend(fontsize=8)
fig.tight_layout()
fig.savefig(os.path.join(OUT, "chain.png"), dpi=120)
finish("fiber-chain", metrics, extra, short=ARGS.short)
