#!/usr/bin/python3
"""Where the immersed-solid forcing puts a wall that lies inside a cell.

Steady Couette flow, periodic in x: the bottom wall is covered by a fixed rigid block whose top
lies at y0 = (4 + delta) h, delta = 0 ... 1 of a cell; the top wall moves at U = 1. The exact
profile is linear, u = U (y - y0) / (1 - y0), on any grid. The computed profile above the block is
linear too; extended to u = 0 it gives the wall the flow sees, e. The offset (e - y0) / h is the
forcing's error in the wall's position, as a function of where the wall lies in its cell.

In a cell the block covers a fraction alpha of, the paper's forcing (its Eqs. 18-21) sets
u = alpha u_s + (1 - alpha) u~ each step, where u~ = u^n + dt R (R: the fluid's own right-hand
side). At rest, u^(n+1) = u^n gives alpha u = (1 - alpha) dt R: the cell holds a velocity of order
(1 - alpha) dt R / alpha. How much of the cell is blocked depends on alpha against
lambda = nu dt / h^2, the fluid's own relaxation in one step, so the case runs at
lambda = 0.02 (FSI1's L2 level: nu = 1e-3, dt = 5e-4, h = 5e-3) and 0.1 with explicit diffusion,
and 0.128, 0.5, 2 with Crank-Nicolson, its forcing after the solve (the default before) and in its
increment ([fluid] implicit_forcing = "increment"; also at 4, 6 and 8 with the factored solve);
and at lambda = 0.02 the smoothed footprint ([coupler] footprint_smoothing = 1) as well; at
lambda = 0.02 and 0.1 the sharp interface ([fluid] interface = "sharp", which places the wall
inside its cell from the volume fraction: the offset is round-off), alone with `--sharp`.

For each case the largest offset |e - y0| / h is judged against the tolerance in TOL_OFFSET
(TOL_OFFSET_SMOOTHED for the smoothed footprint; README.md: what was measured, and why that
margin); the largest gain (change of the wall seen
over change of the true wall, between successive delta; 1 for a wall placed in proportion) is
reported.
Environment: FSI_BIN, FSI_OUT, FSI_ROOT; FSI_MPIRUN (default mpirun)."""
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
from metrics import at_most, finish, reported  # noqa: E402

_p = cli.parser(__doc__)
_p.add_argument("--sharp", action="store_true",
                help="the sharp interface's cases only ([fluid] interface = \"sharp\")")
ARGS = _p.parse_args()
job.out_dir("sub-cell-wall")
OUT = job.nest("sharp" if ARGS.sharp else None)
SHORT = ARGS.short

N = 16           # cells across the channel (height 1); the exact profile is linear on any grid
H = 1.0 / N
DT = 1e-3
# (lambda, diffusion, [fluid] implicit_forcing ("sharp": [fluid] interface = "sharp" instead),
# [fluid] helmholtz, [coupler] footprint_smoothing): the sharp interface at two lambda; the
# forcing after the Crank-Nicolson solve (the default before) and in its increment (the
# default), with the direct Helmholtz solve, and the increment with the factored one; and at
# FSI2's lambda the smoothed footprint's tent (smoothing 1).
CASES = [(0.02, "explicit", "sharp", None), (0.1, "explicit", "sharp", None),
         (0.02, "explicit", None, None), (0.02, "explicit", None, None, 1.0),
         (0.1, "explicit", None, None),
         (0.128, "implicit", "after_solve", "direct"), (0.5, "implicit", "after_solve", "direct"),
         (2.0, "implicit", "after_solve", "direct"),
         (0.128, "implicit", "increment", "direct"), (0.5, "implicit", "increment", "direct"),
         (2.0, "implicit", "increment", "direct"),
         (0.128, "implicit", "increment", "factored"), (0.5, "implicit", "increment", "factored"),
         (2.0, "implicit", "increment", "factored"), (4.0, "implicit", "increment", "factored"),
         (6.0, "implicit", "increment", "factored"), (8.0, "implicit", "increment", "factored")]
if ARGS.sharp:
    CASES = [c for c in CASES if c[2] == "sharp"]
DELTAS = [0.0, 0.1, 0.5] if SHORT else [0.0, 0.02, 0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 0.9, 1.0]
# The largest offset of the wall seen, in cells, each with 0.05 of a cell to spare: half a cell
# with explicit diffusion (a wall on a grid line is seen at the centre of the cut row's u-faces,
# 0.500 measured); the leak of the forcing after the Crank-Nicolson solve, 0.560, 0.707, 1.117;
# the forcing in its increment, half a cell at lambda = 0.128 and 0.5, and at lambda = 2 the
# explicit balance blocking a cut row more (0.667 measured, at delta = 0.5). The factored
# Helmholtz solve has the same steady states (measured: the same offsets to the printed digits);
# at lambda = 4, 6 and 8 (factored) the largest offsets measured are 0.832, 0.920 and 0.974, at
# delta = 0.7, which the short version does not run. The block is rigid and fixed, so the
# default body_viscosity = "none" keeps the fluid's viscosity in it as "kelvin-voigt" does (it
# takes it out of elastic bodies only) and the offsets are the forcing's alone (README.md).
# The sharp interface holds the linear profile exactly: 1.6e-10 cells measured; a twentieth of a
# cell allowed, as for the others' margins.
TOL_OFFSET = {(0.02, "sharp"): 0.05, (0.1, "sharp"): 0.05, (0.02, None): 0.55, (0.1, None): 0.55,
              (0.128, "after_solve"): 0.61, (0.5, "after_solve"): 0.76, (2.0, "after_solve"): 1.17,
              (0.128, "increment"): 0.55, (0.5, "increment"): 0.55, (2.0, "increment"): 0.72,
              (4.0, "increment"): 0.88, (6.0, "increment"): 0.97, (8.0, "increment"): 1.03}
# The smoothed footprint (footprint_smoothing = 1) places the wall seen 0.413 cells out at most
# (delta = 0.9), measured; 0.05 to spare.
TOL_OFFSET_SMOOTHED = {0.02: 0.46}


def scene(name, y0, lam, diffusion, forcing, helmholtz, smoothing=0.0):
    mu = lam * H * H / DT  # rho = 1: nu = mu
    # 2.5 diffusion times of the fluid layer: the slowest mode decays by exp(-2.5 pi^2) ~ 2e-11;
    # and at least 1000 steps, so that a slow growth at large lambda shows.
    t_end = max(2.5 * (1.0 - y0) ** 2 / mu, 1000 * DT)
    return f"""[scene]
name = "{name}"
description = "Couette flow over a fixed block whose top lies inside a cell"
[time]
dt = {DT}
t_end = {t_end:.8g}
[output]
interval = {t_end:.8g}
[fluid]
density = 1.0
viscosity = {mu!r}
diffusion = "{diffusion}"
{f'implicit_forcing = "{forcing}"' if forcing and forcing != "sharp" else ""}
{'interface = "sharp"' if forcing == "sharp" else ""}
{f'helmholtz = "{helmholtz}"' if helmholtz else ""}
[fluid.grid]
cells = [4, {N}]
size = [0.25, 1.0]
[fluid.boundary]
left = {{ type = "periodic" }}
right = {{ type = "periodic" }}
bottom = {{ type = "wall" }}
top = {{ type = "wall", velocity = 1.0 }}
[solid]
[[solid.body]]
name = "block"
kind = "rigid"
rectangle = {{ origin = [0.0, 0.0], size = [0.25, {y0!r}], cells = [2, 4] }}
{f"[coupler]{chr(10)}footprint_smoothing = {smoothing!r}" if smoothing else ""}
"""


def run(name, text):
    r = job.run(name, text, work=os.path.join(OUT, "runs"))
    yc, _, u = fluidout.mean_u(r.folder)
    return yc, u[-1], r.wall


def main():
    metrics, results = {}, {}
    fig, ax = plt.subplots(figsize=(6, 4.2))
    for lam, diffusion, forcing, helmholtz, *rest in CASES:
        smoothing = rest[0] if rest else 0.0
        offsets = []
        label = (diffusion + (f", {forcing}" if forcing else "") +
                 (f", {helmholtz}" if helmholtz == "factored" else "") +
                 (f", smoothed footprint {smoothing:g}" if smoothing else ""))
        for d in DELTAS:
            y0 = (4.0 + d) * H
            name = (f"wall-{lam:g}-{d:g}" + (f"-{forcing}" if forcing in ("increment", "sharp") else "") +
                    (f"-{helmholtz}" if helmholtz == "factored" else "") +
                    (f"-smoothed-{smoothing:g}" if smoothing else ""))
            yc, u, wall = run(name, scene(name, y0, lam, diffusion, forcing, helmholtz, smoothing))
            # Rows away from the block and the cut row: more than (1 + smoothing) h above the
            # block, twice the smoothed weight's reach, as one cell is for the box.
            free = yc > y0 + (1 + smoothing) * H
            slope, icpt = np.polyfit(yc[free], u[free], 1)
            e = -icpt / slope
            offset = (e - y0) / H
            offsets.append(offset)
            results[name] = {"lambda": lam, "diffusion": diffusion, "forcing": forcing,
                             "helmholtz": helmholtz, "smoothing": smoothing, "delta": d,
                             "offset_cells": offset, "slope": slope,
                             "exact_slope": 1.0 / (1.0 - y0), "wall_s": wall}
            print(f"[sub-cell-wall] lambda {lam:g} ({label}), wall at {d:.2f} of a cell: "
                  f"seen at {offset:+.3f} cells ({wall:.1f} s)", flush=True)
        worst = float(np.max(np.abs(offsets)))
        seen = np.array(DELTAS) + np.array(offsets)
        gain = float(np.max(np.diff(seen) / np.diff(DELTAS)))
        key = (f"lambda_{lam:g}_{diffusion}" + (f"_{forcing}" if forcing in ("increment", "sharp") else "") +
               (f"_{helmholtz}" if helmholtz == "factored" else "") +
               (f"_smoothed_{smoothing:g}" if smoothing else ""))
        tol = TOL_OFFSET_SMOOTHED[lam] if smoothing else TOL_OFFSET[(lam, forcing)]
        metrics[f"largest_offset_{key}"] = at_most(worst, tol)
        metrics[f"largest_gain_{key}"] = reported(gain, 1.0)
        ax.plot(DELTAS, [d + o for d, o in zip(DELTAS, offsets)], "o-",
                label=f"lambda = {lam:g} ({label})")
    ax.plot([0, 1], [0, 1], "k--", lw=0.8, label="exact")
    ax.set_xlabel("true wall position in its cell (cells above a grid line)")
    ax.set_ylabel("wall position the flow sees (cells)")
    ax.set_title("Steady Couette flow over an immersed block")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "sub-cell-wall.png"), dpi=120)
    finish("sub-cell-wall", metrics, {"runs": results, "settings": {"cells": N, "dt": DT}},
           short=SHORT)


if __name__ == "__main__":
    main()
