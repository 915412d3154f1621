#!/usr/bin/python3
"""Cantilever eigenmodes and free vibration: a slender clamped-free beam (L = 1, h = 0.02,
E = 1e6, nu = 0.3, rho = 1) in plane strain. (1) The lowest three eigenfrequencies (paper
Eq. 28, Spectra shift-invert) against Euler-Bernoulli with the plane-strain modulus; (2) the same
frequencies from free-vibration time runs started with each mode's velocity (tip displacement
zero crossings); (3) total energy of a linear-regime free vibration over 1000 Newmark steps."""
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import cli  # noqa: E402
import job  # noqa: E402
import outputs  # noqa: E402
import scenes  # noqa: E402
import solidout  # noqa: E402
import matplotlib  # noqa: E402
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from metrics import finish, metric, relative  # noqa: E402

ARGS = cli.parser(__doc__).parse_args()
OUT = job.out_dir("cantilever-modes")

HERE = os.path.dirname(os.path.abspath(__file__))
L, H, E, NU, RHO = 1.0, 0.02, 1e6, 0.3, 1.0
BETA_L = [1.875104, 4.694091, 7.854757]
E_PLANE = E / (1 - NU * NU)
OMEGA_EB = [b * b / L**2 * math.sqrt(E_PLANE * H**3 / 12 / (RHO * H)) for b in BETA_L]
NY = 4 if ARGS.short else 16
NX = 50 * NY
# Beam theory is met within 2 % from 8 elements across (measured 1.8, 1.6, 1.3 %); the short
# version's 4 across are 6.9, 6.7, 6.3 % stiff, hence its 8 % tolerance.
TOL_MODES = 0.08 if ARGS.short else 0.02
STEPS_PER_PERIOD = 100


def scene(name, mode, periods, ny, steps_per_period=STEPS_PER_PERIOD, modes=3):
    period = 2 * math.pi / OMEGA_EB[mode - 1]
    dt = period / steps_per_period
    return scenes.edit(os.path.join(HERE, "cantilever.toml"), {
        "name": f'name = "{name}"',
        "dt": f"dt = {dt!r}",
        "t_end": f"t_end = {periods * period!r}",
        "interval": f"interval = {periods * period / 10!r}",
        "modes": f"modes = {modes}",
        "initial_mode": f"initial_mode = {mode}",
        # Tip amplitude about 1e-6 L: speed = omega * amplitude.
        "initial_mode_speed": f"initial_mode_speed = {1e-6 * OMEGA_EB[mode - 1]!r}",
        "cells": f"cells = [{50 * ny}, {ny}]"})


def crossing_period(t, u):
    """Mean period from the zero crossings of u(t) (linear interpolation)."""
    s = np.signbit(u)
    idx = np.nonzero(s[1:] != s[:-1])[0]
    tc = t[idx] - u[idx] * (t[idx + 1] - t[idx]) / (u[idx + 1] - u[idx])
    return float(np.mean(tc[2:] - tc[:-2])) if len(tc) >= 3 else float("nan")


metrics, runs = {}, []
fig, ax = plt.subplots(1, 3, figsize=(13, 3.6))
for mode in (1, 2, 3):
    folder, wall, *_ = job.run(f"mode{mode}", scene(f"mode{mode}", mode, 2.2, NY))
    s = outputs.summary(folder)["solid"]
    f_fe = s["mode_frequencies"][mode - 1]
    p = solidout.probes(folder)
    period = crossing_period(p["time"], p["tip.uy"])
    f_run = 1 / period
    f_eb = OMEGA_EB[mode - 1] / (2 * math.pi)
    dt = 2 * math.pi / OMEGA_EB[mode - 1] / STEPS_PER_PERIOD
    # Trapezoidal Newmark lengthens the period by (omega dt)^2 / 12.
    elongation = (2 * math.pi * f_fe * dt) ** 2 / 12
    metrics[f"mode{mode}_frequency"] = relative(f_fe, f_eb, TOL_MODES)
    metrics[f"mode{mode}_time_run_frequency"] = relative(f_run, f_eb, TOL_MODES)
    metrics[f"mode{mode}_time_run_vs_modal"] = metric(f_run, f_fe, abs(f_fe / f_run - 1 - elongation), 2e-4)
    runs.append({"mode": mode, "euler_bernoulli": f_eb, "modal": f_fe, "time_run": f_run,
                 "modal_error": f_fe / f_eb - 1, "time_run_error": f_run / f_eb - 1, "wall_s": wall})
    print(f"mode {mode}: Euler-Bernoulli {f_eb:.6g}, modes {f_fe:.6g} ({100 * (f_fe / f_eb - 1):+.3f} %), "
          f"time run {f_run:.6g} ({100 * (f_run / f_eb - 1):+.3f} %), {wall:.1f} s")
    ax[0].plot(p["time"] * f_eb, p["tip.uy"] / np.max(np.abs(p["tip.uy"])), label=f"mode {mode}")
    if mode == 3:
        x, shapes = solidout.modes(folder, "beam", 3)
        on_axis = np.abs(x[:, 1] - H / 2) < 1e-9
        order = np.argsort(x[on_axis, 0])
        for k, phi in enumerate(shapes, start=1):
            w = phi[on_axis, 1][order]
            ax[1].plot(x[on_axis, 0][order], w / np.max(np.abs(w)), label=f"mode {k}")
ax[0].set_xlabel("t f (Euler-Bernoulli)")
ax[0].set_ylabel("tip u_y / max")
ax[0].legend(fontsize=7)
ax[1].set_xlabel("x")
ax[1].set_ylabel("mode shape (centre line)")
ax[1].legend(fontsize=7)

# Energy of a linear-regime free vibration over 1000 steps (mode 1, 100 steps per period).
ny_energy = 4 if ARGS.short else 8
folder, wall, *_ = job.run("energy", scene("energy", 1, 10, ny_energy, modes=1))
h = solidout.history(folder)
e = h["total_energy"]
drift = float(np.max(np.abs(e - e[0])) / e[0])
steps = len(e) - 1
metrics["energy_drift_1000_steps"] = metric(drift, 0.0, drift, 1e-6)
print(f"energy over {steps} steps: largest relative change {drift:.3e}")
ax[2].plot(h["time"], (e - e[0]) / e[0])
ax[2].set_xlabel("t")
ax[2].set_ylabel("(E - E0) / E0")
ax[2].set_title(f"{steps} steps, {ny_energy} elements across")
fig.tight_layout()
fig.savefig(os.path.join(OUT, "modes.png"), dpi=120)
finish("cantilever-modes", metrics, {"elements_across": NY, "modes": runs, "energy_steps": steps,
                                        "energy_drift": drift}, short=ARGS.short)
