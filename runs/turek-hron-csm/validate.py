#!/usr/bin/python3
"""Turek-Hron CSM1 and CSM2 (Turek & Hron 2006): the elastic bar behind the cylinder bends
under its own weight (static, St.Venant-Kirchhoff). Tip displacement of point A = (0.6, 0.2)
against the published values, on structured criss-cross meshes with 4 ... 32 elements across
the thickness (short version: 16 across). Writes the convergence table and plots."""
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
from metrics import finish, relative, run_entry  # noqa: E402

ARGS = cli.parser(__doc__).parse_args()
OUT = job.out_dir("turek-hron-csm")

HERE = os.path.dirname(os.path.abspath(__file__))
# Reference values (Turek & Hron 2006, as quoted by the Feel++ toolbox docs, CoCoNuT, NREL PVade).
REFERENCE = {"csm1": (-7.187e-3, -66.10e-3), "csm2": (-0.4690e-3, -16.97e-3)}
LEVELS = [16] if ARGS.short else [4, 8, 16, 32]
# Tolerance on the finest mesh: 1 % (the case's target). The short version's 16 elements across
# are measured at -0.9 % (u_y) and -1.7 % (u_x) for CSM1, hence 2 % there.
TOL = 0.02 if ARGS.short else 0.01

metrics, rows, per_run = {}, [], []
fig, ax = plt.subplots(1, 2, figsize=(10, 4))
for case, (ref_x, ref_y) in REFERENCE.items():
    errs = []
    for ny in LEVELS:
        nx = int(round(17.5 * ny))  # square cells: 0.35 / nx = 0.02 / ny
        text = scenes.edit(os.path.join(HERE, f"{case}.toml"),
                             {"mesh_parameters": f'mesh_parameters = "nx = {nx}, ny = {ny}"',
                              "name": f'name = "{case}-ny{ny}"'})
        folder, wall, *_ = job.run(f"{case}-ny{ny}", text)
        s = outputs.summary(folder)["solid"]
        ux, uy = s["probes"]["A"]["ux"], s["probes"]["A"]["uy"]
        nodes = s["bodies"][0]["nodes"]
        ex, ey = ux / ref_x - 1, uy / ref_y - 1
        errs.append((ny, ex, ey))
        for q, err, ref in [("u_y(A)", ey, ref_y), ("u_x(A)", ex, ref_x)]:
            per_run.append(run_entry(err, f"{nx}x{ny}", None, f"{case} {q}", ref))
        rows.append({"case": case, "across": ny, "along": nx, "nodes": nodes, "ux": ux, "uy": uy,
                     "error_ux": ex, "error_uy": ey, "newton": s["newton_iterations"], "wall_s": wall})
        print(f"{case} {ny:3d} x {nx:4d} ({nodes} nodes): ux {ux:.5e} ({100 * ex:+.2f} %), "
              f"uy {uy:.5e} ({100 * ey:+.2f} %), {wall:.1f} s")
    ny, ex, ey = errs[-1]
    metrics[f"{case}_ux_A"] = relative(rows[-1]["ux"], ref_x, TOL)
    metrics[f"{case}_uy_A"] = relative(rows[-1]["uy"], ref_y, TOL)
    e = np.array(errs)
    ax[0].loglog(e[:, 0], np.abs(e[:, 2]), "o-", label=f"{case} $u_y$")
    ax[0].loglog(e[:, 0], np.abs(e[:, 1]), "s--", label=f"{case} $u_x$")
    # Deformed bar of the finest level.
    d = solidout.last_state(folder, "bar")
    x = d["position"]
    ax[1].triplot(x[:, 0], x[:, 1], d["triangles"], lw=0.1, label=case)
ax[0].axhline(0.01, color="k", lw=0.6, ls=":")
ax[0].set_xlabel("elements across the thickness")
ax[0].set_ylabel("|relative error| at A")
ax[0].legend(fontsize=7)
ax[1].set_aspect("equal")
ax[1].set_xlabel("x")
ax[1].set_ylabel("y")
ax[1].set_title("deformed bar (finest mesh)")
fig.tight_layout()
fig.savefig(os.path.join(OUT, "convergence.png"), dpi=120)
with open(os.path.join(OUT, "convergence.md"), "w") as f:
    f.write("| case | across x along | nodes | u_x(A) | error | u_y(A) | error | Newton its | wall s |\n")
    f.write("|---|---|---|---|---|---|---|---|---|\n")
    for r in rows:
        f.write(f"| {r['case']} | {r['across']} x {r['along']} | {r['nodes']} | {r['ux']:.5e} | "
                f"{100 * r['error_ux']:+.2f} % | {r['uy']:.5e} | {100 * r['error_uy']:+.2f} % | "
                f"{r['newton']} | {r['wall_s']:.1f} |\n")
finish("turek-hron-csm", metrics, {"levels": rows}, short=ARGS.short, per_run=per_run,
       reference="Turek & Hron 2006, CSM1 u_x(A) -7.187 mm, u_y(A) -66.10 mm; CSM2 -0.4690 mm,"
                 " -16.97 mm")
