#!/usr/bin/python3
"""Taylor-Green vortex on the periodic square [0, 2 pi]^2:
    u = -U cos x sin y e^{-2 nu t},  v = U sin x cos y e^{-2 nu t}.
Metrics: L2 velocity error on 32^2, 64^2, 128^2 and the observed order in space (dt refined
with h^2), the order in time for explicit (AB2) and implicit (Crank-Nicolson) diffusion (fixed
grid, errors against a run with a 16x smaller dt), and a run with implicit diffusion at 4x the
explicit stability limit that must stay bounded and decay at the exact rate."""
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
from metrics import finish, metric, run_entry  # noqa: E402

ARGS = cli.parser(__doc__).parse_args()
OUT = job.out_dir("taylor-green")

L = 2 * np.pi
SCENE = """
[scene]
name = "{name}"
[time]
dt = {dt}
t_end = {t_end}
[output]
interval = {t_end}
[fluid]
density = 1.0
viscosity = {nu}
diffusion = "{diffusion}"
[fluid.grid]
cells = [{n}, {n}]
size = [{L}, {L}]
[fluid.boundary]
left = {{ type = "periodic" }}
right = {{ type = "periodic" }}
bottom = {{ type = "periodic" }}
top = {{ type = "periodic" }}
[fluid.initial]
type = "taylor-green"
amplitude = 1.0
[fluid.health]
cfl_max = 2.0
"""


def run(n, dt, diffusion, nu=0.05, t_end=1.0):
    name = f"tg-{diffusion}-{n}-{dt:g}"
    folder, wall, *_ = job.run(name, SCENE.format(name=name, n=n, dt=dt, t_end=t_end, nu=nu,
                                             diffusion=diffusion, L=L))
    return fluidout.last_state(folder), wall


def l2_exact(d, nu):
    e = np.exp(-2 * nu * d["time"])
    X, Y = np.meshgrid(d["x_face"][:-1], d["y_centre"])
    ue = -np.cos(X) * np.sin(Y) * e
    X, Y = np.meshgrid(d["x_centre"], d["y_face"][:-1])
    ve = np.sin(X) * np.cos(Y) * e
    du = d["u_face"][:, :-1] - ue
    dv = d["v_face"][:-1, :] - ve
    return np.sqrt((np.mean(du ** 2) + np.mean(dv ** 2)) / 2)


metrics, table, per_run = {}, [], []
grids = [16, 32, 64] if ARGS.short else [32, 64, 128]
for diffusion in ["explicit", "implicit"]:
    errs = []
    for n in grids:
        dt = 0.02 * (32 / n) ** 2  # dt ~ h^2: the time error falls with the space error
        d, wall = run(n, dt, diffusion)
        errs.append(l2_exact(d, 0.05))
        per_run.append(run_entry(errs[-1], f"{n}x{n}", dt, f"L2 velocity error, {diffusion}", 0.0))
        table.append({"diffusion": diffusion, "n": n, "dt": dt, "l2_error": errs[-1], "wall_s": wall})
    orders = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    metrics[f"space_order_{diffusion}"] = metric(orders[-1], 2.0, max(0.0, 1.9 - orders[-1]), 0.0)
    metrics[f"l2_error_{grids[-1]}_{diffusion}"] = metric(errs[-1], 0.0, errs[-1], 1e-3)
    plt.loglog(grids, errs, "o-", label=f"{diffusion} (orders {', '.join(f'{o:.2f}' for o in orders)})")
plt.loglog(grids, [errs[0] * (grids[0] / n) ** 2 for n in grids], "k--", lw=0.7, label="slope 2")
plt.xlabel("cells per side")
plt.ylabel("L2 velocity error")
plt.legend(fontsize=7)
plt.tight_layout()
plt.savefig(os.path.join(OUT, "space_convergence.png"), dpi=120)
plt.close()

# Time order: fixed grid, against a reference run with dt / 16.
n_t = 32
for diffusion in ["explicit", "implicit"]:
    ref, _ = run(n_t, 0.0025, diffusion)
    errs = []
    for dt in [0.04, 0.02]:
        d, _ = run(n_t, dt, diffusion)
        errs.append(np.sqrt(np.mean((d["u_face"] - ref["u_face"]) ** 2)))
    order = np.log2(errs[0] / errs[1])
    metrics[f"time_order_{diffusion}"] = metric(order, 2.0, max(0.0, 1.9 - order), 0.0)

# Implicit diffusion at 4x the explicit limit 1 / (4 nu (2 / h^2)): nu = 2 makes diffusion the limit.
nu, n = 2.0, 32
h = L / n
limit = 1.0 / (4 * nu * 2 / h ** 2)
d, _ = run(n, 4 * limit, "implicit", nu=nu, t_end=200 * limit)
e = l2_exact(d, nu) / np.exp(-2 * nu * d["time"])  # error relative to the current amplitude
metrics["implicit_4x_limit_relative_error"] = metric(e, 0.0, e, 0.05)
finish("taylor-green", metrics, {"runs": table, "explicit_limit_dt": limit}, short=ARGS.short,
       per_run=per_run, reference="exact decaying Taylor-Green vortex (L2 velocity error at t = 1)")
