#!/usr/bin/python3
"""Inextensibility: max | |X_s| - 1 | over every segment and every step of 1e4 steps of a strong
flapping motion: a fiber clamped at a root whose direction swings by +-45 degrees at 0.5 Hz (near
its first bending frequency), under gravity, at 0.9 of the explicit bending limit. Target 1e-6.
For information the same run with a single linear solve of the tension equation per step (the
discrete Eq. 17 with its pull-back term, Huang et al. 2007's choice) is reported too."""
import math
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
OUT = job.out_dir("fiber-inextensibility")

N, L, RHO, GAMMA = 32, 1.0, 1.0, 0.01
DT = 0.9 * (L / N) ** 2 * math.sqrt(RHO / (12 * GAMMA))
STEPS = 10000

SCENE = scenes.HEADER + """
[fiber]
gravity = [0, -1]
tension_iterations = {iterations}
stretch_limit = 1e-2
[[fiber.fiber]]
name = "flag"
length = {L}
segments = {n}
density = {rho}
bending = {gamma}
position = [0, 0]
[fiber.fiber.root]
kind = "clamped"
angle_amplitude = 45
frequency = 0.5
[[fiber.probe]]
name = "tip"
fiber = "flag"
s = {L}
"""

metrics, extra = {}, {}
fig, ax = plt.subplots(1, 2, figsize=(11, 4))
for iterations, label in [(8, "newton"), (1, "single_solve")]:
    name = f"inextensibility-{label}"
    folder, wall, *_ = job.run(name, SCENE.format(name=name, dt=DT, t_end=STEPS * DT, interval=STEPS * DT / 20,
                                             iterations=iterations, L=L, n=N, rho=RHO, gamma=GAMMA))
    rep = outputs.summary(folder)["fiber"]
    st = fiberout.steps(folder)
    final = max(np.max(np.abs(np.linalg.norm(np.diff(x["X"], axis=0), axis=1) / (L / N) - 1)) for x in st[-1:])
    extra[label] = {"tension_iterations_max": iterations, "max_stretch_over_run": rep["max_stretch"],
                    "stretch_at_end": float(final), "steps": rep["steps"], "wall_s": wall,
                    "us_per_step": rep["us_per_step"]}
    print(f"  {label}: max stretch over {rep['steps']} steps {rep['max_stretch']:.3e}, at the end {final:.3e}")
    if label == "newton":
        metrics["max_stretch"] = metric(rep["max_stretch"], 0.0, rep["max_stretch"], 1e-6)
        p = fiberout.probes(folder)
        ax[0].plot(p["tip.x"], p["tip.y"], lw=0.5)
        for x in st:
            ax[1].plot(x["X"][:, 0], x["X"][:, 1], lw=0.8)
ax[0].set_title("tip path")
ax[1].set_title("shapes")
for a in ax:
    a.set_aspect("equal")
fig.tight_layout()
fig.savefig(os.path.join(OUT, "inextensibility.png"), dpi=120)
finish("fiber-inextensibility", metrics, extra, short=ARGS.short)
