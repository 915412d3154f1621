#!/usr/bin/python3
"""Patch tests: a homogeneous deformation must be reproduced exactly (to round-off, <= 1e-12)
by linear triangles on an irregular mesh, for both materials: uniform stretch by prescribed
displacements, simple shear with periodic sides, uniform stretch under dead tractions P N (P
computed here independently from the constitutive laws: St.Venant-Kirchhoff, paper Eq. 6, and
plane-strain neo-Hookean, Eq. 7 with C33 = 1)."""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import cli  # noqa: E402
import job  # noqa: E402
import scenes  # noqa: E402
import solidout  # noqa: E402
import matplotlib  # noqa: E402
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from metrics import finish, metric  # noqa: E402

ARGS = cli.parser(__doc__).parse_args()
OUT = job.out_dir("patch-test")

HERE = os.path.dirname(os.path.abspath(__file__))
E, NU = 1000.0, 0.3
LAM, MU = E * NU / ((1 + NU) * (1 - 2 * NU)), E / (2 * (1 + NU))
BULK = E / (3 * (1 - 2 * NU))


def first_piola(model, F):
    """P = F S for plane strain (C33 = 1)."""
    C = F.T @ F
    if model == "saint-venant-kirchhoff":
        Eg = 0.5 * (C - np.eye(2))
        S = LAM * np.trace(Eg) * np.eye(2) + 2 * MU * Eg
    else:
        J = np.linalg.det(F)
        I1 = np.trace(C) + 1
        Ci = np.linalg.inv(C)
        S = MU * J ** (-2 / 3) * (np.eye(2) - I1 / 3 * Ci) + BULK * (J * J - J) * Ci
    return F @ S


CASES = {"stretch": np.array([[1.3, 0], [0, 0.8]]),
         "shear": np.array([[1, 0.4], [0, 1]]),
         "traction": np.array([[1.2, 0], [0, 0.9]])}
# The short version meshes the patch coarser (h = 0.25).
mesh_size = 0.25 if ARGS.short else 0.12
metrics, rows = {}, []
fig, ax = plt.subplots(1, 3, figsize=(12, 4))
for k, (case, F) in enumerate(CASES.items()):
    for model in ("saint-venant-kirchhoff", "neo-hookean"):
        tag = f"{case}-{'svk' if model.startswith('saint') else 'nh'}"
        replace = {"name": f'name = "patch-{tag}"', "model": f'model = "{model}"',
                   "mesh": None}
        text = scenes.edit(os.path.join(HERE, f"{case}.toml"), {"name": replace["name"],
                                                                    "model": replace["model"]})
        text = text.replace('mesh = "', f'mesh_parameters = "h = {mesh_size}"\nmesh = "')
        if case == "traction":
            P = first_piola(model, F)
            lines = text.splitlines()
            tractions = iter([(P[0, 0], P[1, 0]), (P[0, 1], P[1, 1])])  # right: P (1,0); top: P (0,1)
            for i, line in enumerate(lines):
                if line.startswith("traction ="):
                    tx, ty = next(tractions)
                    lines[i] = f"traction = [{tx!r}, {ty!r}]"
            text = "\n".join(lines) + "\n"
        folder, wall, *_ = job.run(f"patch-{tag}", text)
        d = solidout.last_state(folder, "patch")
        exact = d["x_ref"] @ F.T
        err = float(np.max(np.abs(d["position"] - exact)))
        metrics[f"{tag}_max_error"] = metric(err, 0.0, err, 1e-12)
        rows.append({"case": case, "model": model, "nodes": len(d["x_ref"]), "max_error": err})
        print(f"{tag}: {len(d['x_ref'])} nodes, triangles {len(d['triangles'])}, max |x - F X| = {err:.2e}")
        if model == "neo-hookean":
            x = d["position"]
            ax[k].triplot(d["x_ref"][:, 0], d["x_ref"][:, 1], d["triangles"], lw=0.3, color="0.7")
            ax[k].triplot(x[:, 0], x[:, 1], d["triangles"], lw=0.5, color="tab:red")
            ax[k].set_aspect("equal")
            ax[k].set_title(f"{case}: max |x - F X| = {err:.1e}")
fig.tight_layout()
fig.savefig(os.path.join(OUT, "patch.png"), dpi=120)
finish("patch-test", metrics, {"runs": rows}, short=ARGS.short)
