#!/usr/bin/python3
"""A rigid disk settling midway between the walls of a closed channel (scene.toml), moved by the
Python solid program solid-rigid: its terminal velocity against Faxen's wall-corrected Stokes drag
of a cylinder between two plane walls (README.md).

  validate            h = 1/32 and 1/64 (64 x 128 and 128 x 256 cells; dt = 1e-3 (32 h)^2, the
                      same nu dt / h^2 = 1.02), rho_s/rho_f = 3 explicit and 1.5 with coupled
                      iterations, to t = 1.5
  validate --short    h = 1/32 only, both density ratios, to t = 1
  validate --after-solve [--short]
                      the default grids and time steps with Crank-Nicolson's forcing after its
                      solve ([fluid] implicit_forcing = "after_solve", the default before
                      "increment"); summary-after-solve.json
  validate --explicit-diffusion [--short]
                      the same grids with explicit diffusion at nu dt / h^2 = 0.1 (dt = 0.1 h^2),
                      rho_s/rho_f = 3 only; its summary goes to summary-explicit-diffusion.json
Environment (set by ./fsi validate): FSI_ROOT, FSI_BIN, FSI_OUT; FSI_MPIRUN (default mpirun)."""
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import cli  # noqa: E402
import couplerout  # noqa: E402
import job  # noqa: E402
import numpy as np  # noqa: E402
from metrics import finish, holds, metric  # noqa: E402
import outputs  # noqa: E402

PARSER = cli.parser(__doc__)
PARSER.add_argument("--explicit-diffusion", action="store_true",
                    help="explicit diffusion at nu dt / h^2 = 0.1, rho_s/rho_f = 3 only")
PARSER.add_argument("--after-solve", action="store_true",
                    help='Crank-Nicolson with [fluid] implicit_forcing = "after_solve"')
ARGS = PARSER.parse_args()
if ARGS.explicit_diffusion and ARGS.after_solve:
    PARSER.error("--after-solve chooses Crank-Nicolson's forcing; --explicit-diffusion has no "
                 "implicit solve: give one of them")
SHORT = ARGS.short
EXPLICIT = ARGS.explicit_diffusion
AFTER_SOLVE = ARGS.after_solve
HERE = os.path.dirname(os.path.abspath(__file__))
OUT = job.out_dir("rigid-sedimentation")

RADIUS = 0.125
HALF_WIDTH = 1.0
MU = 1.0
EXCESS_WEIGHT = 20.0  # (rho_s - rho_f) g per unit area, the same in every run
T_END = 1.0 if SHORT else 1.5
GRIDS = [32] if SHORT else [32, 64]  # cells per unit length
# (rho_s / rho_f, coupled iterations?)
RATIOS = [(3.0, False)] if EXPLICIT else [(3.0, False), (1.5, True)]
ITERATIONS = """
[coupler.iterations]
max = 30
tolerance = 1e-6
relaxation = 0.5
reuse = 20
"""
# Judged: the terminal velocity within these of Faxen's (chosen before the runs: the immersed
# boundary's effective radius is within about a third of a cell of the mesh's, and
# dU/U ~ -(da/a) / 1.19 at a/h = 0.125).
TOL = {32: 0.08, 64: 0.04}


def faxen(k):
    """Drag of a cylinder of radius a moving at U midway between walls at distance h = a / k,
    F = 4 pi mu U / (ln(1/k) - 0.9157 + 1.7244 k^2 - 1.7302 k^4 + 2.4056 k^6 - 4.5913 k^8)
    (Faxen 1946, as given by Happel & Brenner 1965, Low Reynolds number hydrodynamics, Sec. 7-5):
    the denominator."""
    return (math.log(1 / k) - 0.9157 + 1.7244 * k ** 2 - 1.7302 * k ** 4 + 2.4056 * k ** 6
            - 4.5913 * k ** 8)


def scene(n, ratio, iterate):
    text = open(os.path.join(HERE, "scene.toml")).read()
    lc = 1.0 / n
    text = text.replace('mesh = "../neutral-disk/disk.geo"',
                        f'mesh = "{os.path.join(HERE, "..", "neutral-disk", "disk.geo")}"')
    text = text.replace("lc = 0.03125", f"lc = {lc:g}")
    text = text.replace("cells = [64, 128]", f"cells = [{2 * n}, {4 * n}]")
    text = text.replace("density = 3.0", f"density = {ratio:g}")
    text = text.replace("gravity = [0.0, -10.0]", f"gravity = [0.0, {-EXCESS_WEIGHT / (ratio - 1):g}]")
    text = text.replace("t_end = 2.0", f"t_end = {T_END:g}")
    if EXPLICIT:
        text = text.replace('diffusion = "implicit"', 'diffusion = "explicit"')
        text = text.replace("dt = 1e-3", f"dt = {0.1 / (MU * n * n):.10g}")
    else:
        text = text.replace("dt = 1e-3", f"dt = {1e-3 * (32 / n) ** 2:g}")
        if AFTER_SOLVE:
            text = text.replace('diffusion = "implicit"',
                                'diffusion = "implicit"\nimplicit_forcing = "after_solve"')
    return text + (ITERATIONS if iterate else "")


def main():
    rows, metrics = [], {}
    for n in GRIDS:
        for ratio, iterate in RATIOS:
            name = (("diffusion-explicit-" if EXPLICIT else "after-solve-" if AFTER_SOLVE else "")
                    + f"h{n}-ratio-{ratio:g}-{'iter' if iterate else 'explicit'}")
            r = job.run(name, scene(n, ratio, iterate), check=False)
            row = {"cells_per_length": n, "ratio": ratio, "iterations": iterate,
                   "completed": r.returncode == 0, "message": job.first_error(r.log),
                   "wall_s": r.wall}
            key = f"h{n}_ratio_{ratio:g}"
            if row["completed"]:
                d = outputs.table(os.path.join(r.folder, "solid_rigid.csv"))
                s = outputs.summary(r.folder)
                area = s["solid"]["bodies"]["disk"]["area"]
                t, v = d["time"], d["disk.v"]
                late = t >= 0.75 * t[-1]
                u = -float(np.mean(v[late]))
                ref = EXCESS_WEIGHT * area * faxen(RADIUS / HALF_WIDTH) / (4 * math.pi * MU)
                row.update({"terminal_velocity": u, "reference": ref,
                            "error": abs(u - ref) / ref,
                            "steady": float(np.ptp(v[late]) / u),
                            "drift_x": float(np.max(np.abs(d["disk.x"] - d["disk.x"][0]))),
                            "reynolds": u * 2 * RADIUS / MU,
                            "solid_port_s_per_step": s["solid"]["port_seconds"] / s["solid"]["steps"],
                            "fluid_port_s_per_step": s["fluid"]["port_seconds"] / s["fluid"]["steps"]})
                if iterate:
                    it = couplerout.iterations(r.folder)
                    row.update({"iterations_mean": it["mean"], "iterations_max": it["max"],
                                "not_converged": it["not_converged_steps"]})
                    metrics[f"{key}_converged"] = holds(it["not_converged_steps"] == 0)
                metrics[f"{key}_terminal_velocity"] = metric(u, ref, row["error"], TOL[n])
            else:
                metrics[f"{key}_completed"] = holds(False)
            rows.append(row)
            print(f"{name}: " + (f"terminal velocity {row['terminal_velocity']:.5f} (Faxen "
                                 f"{row['reference']:.5f}, error {100 * row['error']:.2f} %), Re "
                                 f"{row['reynolds']:.3f}, late variation {row['steady']:.1e}, "
                                 f"solid {1e3 * row['solid_port_s_per_step']:.3f} ms/step, fluid "
                                 f"{1e3 * row['fluid_port_s_per_step']:.3f} ms/step, {r.wall:.0f} s"
                                 + (f", iterations {row['iterations_mean']:.2f} (max "
                                    f"{row['iterations_max']})" if iterate else "")
                                 if row["completed"] else f"stopped: {row['message']}"), flush=True)
    finish("rigid-sedimentation", metrics, {"runs": rows}, short=SHORT,
           name="summary-explicit-diffusion.json" if EXPLICIT
           else "summary-after-solve.json" if AFTER_SOLVE else "summary.json")


if __name__ == "__main__":
    main()
