#!/usr/bin/python3
"""Fibers standing on a soft block in a shear flow: a neo-Hookean block bonded to the bottom wall,
four fibers attached at right angles to its top surface, the top wall moving at U = 1, periodic
in x; fluid + solid + fiber + coupler. The same scene without the fibers (fluid + solid + coupler)
is the control. At the steady state it checks:
  1. the block deforms under the fibers' root loads: at each root, the rotation of the surface
     edge that holds it (with fibers minus without) has the sign of the root moment the fiber
     exerts on the block, and is well above the control run's own drift;
  2. the global momentum balance of the fluid, with T_wall = sum over the wall's cells of
     tau dx (fluid.h5 tau_top, tau_bottom: tau = mu du_t/dn, n into the fluid; the force of the
     fluid on that wall), F_block = the block's hydrodynamic force (coupler_forces.csv) and
     F_fibers = the fibers' root loads (fiber_loads.csv; at rest, the fluid force on them):
         T_top + T_bottom + F_block + F_fibers = 0   (x components),
     i.e. the force the moving wall puts into the fluid leaves it through the bottom wall, the
     block and the fibers. Judged relative to |T_top|.
`--short`: the same runs to t = 1 (the balance is then judged at 2 %: measured residual drift).
Environment (set by `./fsi validate`): FSI_ROOT, FSI_BIN, FSI_OUT."""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import cli  # noqa: E402
import couplerout  # noqa: E402
import fluidout  # noqa: E402
import fiberout  # noqa: E402
import job  # noqa: E402
import matplotlib  # noqa: E402
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from metrics import at_least, finish, metric  # noqa: E402
import solidout  # noqa: E402

ARGS = cli.parser(__doc__).parse_args()
SHORT = ARGS.short
HERE = os.path.dirname(os.path.abspath(__file__))
OUT = job.out_dir("fibers-on-block")

T_END = 1.0 if SHORT else 2.0
# Tolerances fixed before the runs: the balance residual relative to |T_top| (the wall shear
# diagnostic is a one-sided second-order stencil, not the discrete momentum flux itself, and the
# block's last oscillation has not fully decayed by t = 1).
TOL_BALANCE = 0.02
# An edge rotation counts when it is at least this many times the control run's change of the
# same edge over the last 10 % of the run.
MIN_SIGNAL = 10.0
TOP = 0.15  # the block's top surface in the reference configuration


def scene_text(with_fibers):
    text = open(os.path.join(HERE, "scene.toml")).read().replace("t_end = 2.0", f"t_end = {T_END:g}")
    if with_fibers:
        return text
    # The control: no [fiber] tables and no [coupler] kappa (nothing to feed back).
    keep, skip = [], False
    for line in text.splitlines():
        s = line.strip()
        if s.startswith("["):
            skip = s.startswith("[fiber") or s.startswith("[[fiber") or s.startswith("[coupler")
        if not skip:
            keep.append(line)
    return "\n".join(keep).replace('name = "fibers-on-block"', 'name = "block-alone"') + "\n"


def run(name, text, programs):
    r = job.run(name, text, programs=programs)
    return r.folder, r.wall


def surface(folder):
    """Top-surface nodes of the block: reference x, current positions (sorted by x)."""
    d = solidout.last_state(folder, "block")
    X, x = d["x_ref"], d["position"]
    top = np.where(np.abs(X[:, 1] - TOP) < 1e-9)[0]
    top = top[np.argsort(X[top, 0])]
    return X[top], x[top]


def edge_angles(Xs, xs, points):
    """Angle of the deformed surface edge holding each reference point."""
    out = []
    for p in points:
        k = np.searchsorted(Xs[:, 0], p) - 1
        d = xs[k + 1] - xs[k]
        out.append(float(np.arctan2(d[1], d[0])))
    return np.array(out)


def wall_forces(folder):
    d = fluidout.last_state(folder)
    dx = np.diff(d["x_face"])
    return float(np.sum(d["tau_top"] * dx)), float(np.sum(d["tau_bottom"] * dx))


def main():
    fw, wall_w = run("with-fibers", scene_text(True), ["fluid", "solid", "fiber", "coupler"])
    fo, wall_o = run("without-fibers", scene_text(False), ["fluid", "solid", "coupler"])
    loads = fiberout.loads(fw)
    names = [c[:-3] for c in loads.dtype.names if c.endswith(".fx")]
    roots = 0.3125 + 0.125 * np.arange(len(names))
    moments = np.array([loads[f"{n}.moment"][-1] for n in names])
    f_fibers = float(sum(loads[f"{n}.fx"][-1] for n in names))

    Xs, xw = surface(fw)
    _, xo = surface(fo)
    rot = edge_angles(Xs, xw, roots) - edge_angles(Xs, xo, roots)
    # The control's own drift: the same edges' angle change over the last 10 % of its run, from
    # the solid's state at the last two output steps is not available; use the probe instead.
    po = solidout.probes(fo)
    late = po["time"] >= 0.9 * T_END
    drift = float(np.ptp(po["top_mid.ux"][late])) / 0.05  # displacement change over an edge length

    results = {"root_points": roots.tolist(), "root_moments": moments.tolist(),
               "edge_rotation_with_minus_without": rot.tolist(), "control_drift_rad": drift,
               "surface_ux_with": (xw[:, 0] - Xs[:, 0]).tolist(), "surface_uy_with": (xw[:, 1] - Xs[:, 1]).tolist(),
               "surface_ux_without": (xo[:, 0] - Xs[:, 0]).tolist(),
               "surface_uy_without": (xo[:, 1] - Xs[:, 1]).tolist(),
               "wall_s": {"with": wall_w, "without": wall_o}}
    metrics = {}
    weakest = float(np.min(np.abs(rot)) / max(drift, 1e-300))
    wrong = int(np.sum(np.sign(rot) != np.sign(moments)))
    metrics["root_rotation_sign_matches_moment"] = metric(len(names) - wrong, len(names), wrong, 0.0)
    metrics["root_rotation_over_control_drift"] = at_least(weakest, MIN_SIGNAL)

    for tag, folder, ff in [("with", fw, f_fibers), ("without", fo, 0.0)]:
        t_top, t_bot = wall_forces(folder)
        cf = couplerout.forces(folder)
        f_block = float(cf["block.fx"][-1])
        res = t_top + t_bot + f_block + ff
        results[f"balance_{tag}"] = {"T_top": t_top, "T_bottom": t_bot, "F_block": f_block,
                                     "F_fibers": ff, "residual": res, "relative": res / abs(t_top)}
        metrics[f"momentum_balance_{tag}_fibers"] = metric(res / abs(t_top), 0.0, abs(res / t_top),
                                                           TOL_BALANCE)
        print(f"fibers-on-block ({tag} fibers): T_top {t_top:.5f}, T_bottom {t_bot:.5f}, F_block "
              f"{f_block:.5f}, F_fibers {ff:.5f}: residual {res:.3e} ({100 * res / abs(t_top):.3f} % of "
              f"|T_top|)", flush=True)
    print(f"fibers-on-block: root moments {np.array2string(moments, precision=4)}, edge rotations "
          f"(with - without) {np.array2string(rot, precision=4)} rad, control drift {drift:.2e} rad; "
          f"walls {wall_w:.0f} s, {wall_o:.0f} s", flush=True)

    fig, ax = plt.subplots(1, 2, figsize=(12, 4))
    X = fiberout.steps(fw)[-1]["X"]
    ax[0].plot(xo[:, 0], xo[:, 1], "k--", lw=1, label="block surface, no fibers")
    ax[0].plot(xw[:, 0], xw[:, 1], "b-", lw=1, label="block surface, with fibers")
    ax[0].plot(X[:, 0], X[:, 1], ".", ms=2, color="C1", label="fiber markers")
    ax[0].set_aspect("equal")
    ax[0].legend(fontsize=7)
    ax[0].set_title("steady state (surface displacement to scale)")
    scale = 20.0
    ax[1].plot(Xs[:, 0], scale * (xo[:, 1] - Xs[:, 1]), "k--", label=f"u_y x {scale:g}, no fibers")
    ax[1].plot(Xs[:, 0], scale * (xw[:, 1] - Xs[:, 1]), "b-", label=f"u_y x {scale:g}, with fibers")
    ax[1].plot(Xs[:, 0], scale * (xo[:, 0] - Xs[:, 0]), "k:", label=f"u_x x {scale:g}, no fibers")
    ax[1].plot(Xs[:, 0], scale * (xw[:, 0] - Xs[:, 0]), "g-", label=f"u_x x {scale:g}, with fibers")
    for r in roots:
        ax[1].axvline(r, color="C1", lw=0.6, ls=":")
    ax[1].set_xlabel("x (reference)")
    ax[1].set_title("top-surface displacement (dotted lines: roots)")
    ax[1].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "fibers-on-block.png"), dpi=120)
    plt.close(fig)

    finish("fibers-on-block", metrics, {"t_end": T_END, "results": results}, short=SHORT)


if __name__ == "__main__":
    main()
