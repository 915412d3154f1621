#!/usr/bin/python3
"""Rigid-limit pendulum: a stiff fiber hinged at its top end, under gravity, released from rest at
60 degrees from the vertical. Its period against the rigid rod pivoted at one end,
T = 4 sqrt(2 L / (3 g)) K(sin(theta0 / 2)) (complete elliptic integral of the first kind,
other-cases.md). The fiber's stiffness gamma / (rho' g L^3) = 100 makes its first bending mode
about 120 times faster than the swing; the lumped marker masses give the chain the inertia
rho' L^3 / 3 (1 + 1 / (2 N^2)), a period longer by about 1 / (4 N^2)."""
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
from metrics import finish, metric, relative  # noqa: E402

ARGS = cli.parser(__doc__).parse_args()
OUT = job.out_dir("fiber-pendulum")

L, RHO, G = 1.0, 1.0, 9.81
STIFFNESS = 100.0  # gamma / (rho' g L^3)
THETA0 = math.radians(60)


def elliptic_k(k):
    a, b = 1.0, math.sqrt(1 - k * k)
    for _ in range(40):
        a, b = 0.5 * (a + b), math.sqrt(a * b)
    return math.pi / (2 * a)


T_EXACT = 4 * math.sqrt(2 * L / (3 * G)) * elliptic_k(math.sin(THETA0 / 2))

SCENE = scenes.HEADER + """
[fiber]
gravity = [0, {g_neg!r}]
probe_interval = {probe_dt!r}
[[fiber.fiber]]
name = "rod"
length = {L}
segments = {n}
density = {rho}
bending = {gamma!r}
position = [0, 0]
angle = {angle!r}
[fiber.fiber.root]
kind = "hinged"
[[fiber.probe]]
name = "tip"
fiber = "rod"
s = {L}
"""

segments = [10] if ARGS.short else [10, 20, 40]
periods = 1.3 if ARGS.short else 3.2
gamma = STIFFNESS * RHO * G * L ** 3
rows, metrics = [], {}
plt.figure(figsize=(6, 4))
for n in segments:
    ds = L / n
    dt = 0.9 * ds * ds * math.sqrt(RHO / (12 * gamma))
    name = f"pendulum-n{n}"
    folder, wall, *_ = job.run(name, SCENE.format(name=name, dt=dt, t_end=periods * T_EXACT, interval=0.0, g_neg=-G, probe_dt=T_EXACT / 10000,
                                             L=L, n=n, rho=RHO, gamma=gamma, angle=-90 + math.degrees(THETA0)))
    p = fiberout.probes(folder)
    theta = np.arctan2(p["tip.x"], -p["tip.y"])
    T = series.period(p["time"], theta)
    err = T / T_EXACT - 1
    lumped = 1 / (4 * n * n)
    rows.append({"segments": n, "dt": dt, "period": T, "period_rigid_rod": T_EXACT, "relative_error": err,
                 "lumped_inertia_estimate": lumped, "amplitude_deg": math.degrees(theta.max()), "wall_s": wall})
    print(f"  {n} segments: period {T:.6f} (rigid rod {T_EXACT:.6f}), error {err:+.3e} "
          f"(lumped-mass estimate {lumped:+.1e}), {wall:.1f} s")
    plt.plot(p["time"] / T_EXACT, np.degrees(theta), label=f"{n} segments")
    metrics[f"period_{n}_segments"] = relative(T, T_EXACT, 0.01)
# The swing keeps its amplitude (the scheme's damping acts on the fast bending modes only).
metrics["amplitude_deg"] = metric(rows[-1]["amplitude_deg"], 60.0, abs(rows[-1]["amplitude_deg"] - 60.0), 0.5)
tt = np.linspace(0, periods, 400)
plt.xlabel("t / T_rigid")
plt.ylabel("angle from the vertical [deg]")
plt.legend(fontsize=8)
plt.tight_layout()
plt.savefig(os.path.join(OUT, "pendulum.png"), dpi=120)
finish("fiber-pendulum", metrics, {"runs": rows}, short=ARGS.short)
