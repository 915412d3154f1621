#!/usr/bin/python3
"""A free rigid disk in simple shear (scene.toml, the set-up of runs/neutral-disk), moved by the
Python solid program solid-rigid; and the same disk held fixed by solid-rigid and by solid.

For each free run: whether it completes, the rotation rate (mean angular velocity over the second
half) against -shear/2 (a torque-free disk in the unconfined Stokes limit; the confinement
2r/H = 0.3 slows it slightly), the drift of the centre across the streamlines. For the fixed disk:
the largest difference between the fluid's force on it (coupler_forces.csv) under the two
programs, relative to the largest force.

  validate            rho_s/rho_f = 3 explicit and 1 with coupled iterations, to t = 4; the fixed
                      disk (at y = 0.35) under both programs to t = 1
  validate --short    the same to t = 2 and t = 0.25
Environment (set by ./fsi validate): FSI_ROOT, FSI_BIN, FSI_OUT; FSI_MPIRUN (default mpirun)."""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import cli  # noqa: E402
import couplerout  # noqa: E402
import job  # noqa: E402
import numpy as np  # noqa: E402
from metrics import finish, holds, metric  # noqa: E402
import outputs  # noqa: E402

ARGS = cli.parser(__doc__).parse_args()
SHORT = ARGS.short
HERE = os.path.dirname(os.path.abspath(__file__))
OUT = job.out_dir("rigid-shear-disk")

SHEAR = 1.0
RADIUS = 0.15
T_END = 2.0 if SHORT else 4.0
T_FIXED = 0.25 if SHORT else 1.0
RUNS = [(3.0, False), (1.0, True)]  # (rho_s / rho_f, coupled iterations?)
ITERATIONS = """
[coupler.iterations]
max = 30
tolerance = 1e-6
relaxation = 0.5
reuse = 20
"""
# As runs/neutral-disk: the rate within 3 % of -shear/2, the centred disk's drift below 1e-4
# radii; the fixed disk's force the same under both programs to 1e-12 of its largest value (the
# same mesh, the same kind on the wire: the coupler sees the same input).
TOL_RATE = 0.03
TOL_DRIFT = 1e-4
TOL_FIXED = 1e-12


def base(t_end):
    text = open(os.path.join(HERE, "scene.toml")).read()
    text = text.replace('mesh = "../neutral-disk/disk.geo"',
                        f'mesh = "{os.path.join(HERE, "..", "neutral-disk", "disk.geo")}"')
    return text.replace("t_end = 4.0", f"t_end = {t_end:g}")


def free(ratio, iterate):
    return base(T_END).replace("density = 3.0", f"density = {ratio:g}") + (
        ITERATIONS if iterate else "")


def fixed(program):
    # Off the centreline (y = 0.35), where the passing flow pushes it: a centred disk takes no
    # net force (symmetry), which would compare round-off.
    text = base(T_FIXED).replace("[[solid.body.material]]\ndensity = 3.0\n", "")
    text = text.replace("cy = 0.5", "cy = 0.35")
    if program == "solid-rigid":
        return text.replace('name = "disk"\n', 'name = "disk"\nfixed = true\n')
    return text.replace('program = "solid-rigid"\n', "").replace('name = "disk"\n',
                                                                 'name = "disk"\nkind = "rigid"\n')


def main():
    rows, metrics = [], {}
    for ratio, iterate in RUNS:
        name = f"ratio-{ratio:g}-{'iter' if iterate else 'explicit'}"
        r = job.run(name, free(ratio, iterate), check=False)
        row = {"ratio": ratio, "iterations": iterate, "completed": r.returncode == 0,
               "message": job.first_error(r.log), "wall_s": r.wall}
        key = f"ratio_{ratio:g}_{'iterated' if iterate else 'explicit'}"
        if row["completed"]:
            d = outputs.table(os.path.join(r.folder, "solid_rigid.csv"))
            s = outputs.summary(r.folder)
            t = d["time"]
            late = t >= 0.5 * t[-1]
            rate = float(np.mean(d["disk.omega"][late]))
            drift = float(np.max(np.abs(d["disk.y"] - d["disk.y"][0]))) / RADIUS
            row.update({"rotation_rate": rate, "rate_error": abs(rate + SHEAR / 2) / (SHEAR / 2),
                        "drift_in_radii": drift,
                        "solid_port_s_per_step": s["solid"]["port_seconds"] / s["solid"]["steps"],
                        "fluid_port_s_per_step": s["fluid"]["port_seconds"] / s["fluid"]["steps"]})
            metrics[f"{key}_rotation_rate"] = metric(rate, -SHEAR / 2, row["rate_error"], TOL_RATE)
            metrics[f"{key}_drift"] = metric(drift, 0.0, drift, TOL_DRIFT)
            if iterate:
                it = couplerout.iterations(r.folder)
                row.update({"iterations_mean": it["mean"], "iterations_max": it["max"],
                            "not_converged": it["not_converged_steps"]})
                metrics[f"{key}_converged"] = holds(it["not_converged_steps"] == 0)
        else:
            metrics[f"{key}_completed"] = holds(False)
        rows.append(row)
        print(f"{name}: " + (f"rotation rate {row['rotation_rate']:.4f} (-shear/2 = "
                             f"{-SHEAR / 2}), drift {row['drift_in_radii']:.2e} radii, solid "
                             f"{1e3 * row['solid_port_s_per_step']:.3f} ms/step, fluid "
                             f"{1e3 * row['fluid_port_s_per_step']:.3f} ms/step, {r.wall:.0f} s"
                             + (f", iterations {row['iterations_mean']:.2f} (max "
                                f"{row['iterations_max']})" if iterate else "")
                             if row["completed"] else f"stopped: {row['message']}"), flush=True)

    forces = {}
    for program in ("solid-rigid", "solid"):
        r = job.run(f"fixed-{program}", fixed(program))
        f = outputs.table(os.path.join(r.folder, "coupler_forces.csv"))
        forces[program] = np.column_stack((f["disk.fx"], f["disk.fy"]))
    a, b = forces["solid-rigid"], forces["solid"]
    diff = float(np.max(np.abs(a - b)) / np.max(np.abs(b))) if a.shape == b.shape else float("inf")
    metrics["fixed_disk_force_same"] = metric(diff, 0.0, diff, TOL_FIXED)
    print(f"fixed disk: largest force difference solid-rigid vs solid {diff:.3e} of the largest "
          f"force ({np.max(np.abs(b)):.6g}); last row fx, fy {a[-1]} vs {b[-1]}", flush=True)
    finish("rigid-shear-disk", metrics, {"runs": rows, "fixed_force_difference": diff},
           short=SHORT)


if __name__ == "__main__":
    main()
