"""The glycocalyx channel's field figures (validate.py draws them after glycocalyx.png), read
from each variant's run folder (fluid.h5, fiber.h5, solid.h5, fluid_flow_rate.csv):

- profiles(): u(y) along the vertical line through C (x = 1/2) from the wall's surface to the
  symmetry plane y = 3H/4, every variant on one axes, at the output time of the last period
  nearest the smallest driving |sin(2 pi t / T)| (the paper's Fig. 21);
- fields(): the pressure (colour) with velocity vectors, the fibers and the wall's mesh at the
  output times of the last period with the largest forward and the largest backward flow rate
  through x = 1/2 (the paper's Figs. 17-18);
- flow_rate_vs_e(): the flow-rate amplitude against the wall's Young's modulus, the rigid wall
  with fibers as E -> infinity (the paper's Fig. 23).

"The last period" is that of the output steps written: the times from the last one minus T on,
so that a short test run (a few output steps) draws its last steps. Each function returns the
numbers it plotted, for summary.json."""
import math
import os
import sys

import h5py
import matplotlib
import matplotlib.ticker

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection, PolyCollection  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "lib"))
import make_scene  # noqa: E402
from outputs import step_keys, table  # noqa: E402

T = make_scene.PERIOD
QUIVER_EVERY = 4     # one velocity vector per 4 x 4 cells
TIE = 1e-9           # |sin| values closer than this are a tie (output times on kT/2 exactly)


def output_times(folder, name="fluid.h5"):
    """[(step key, time)] of an HDF5 output file of a run, in step order."""
    with h5py.File(os.path.join(folder, name), "r") as h:
        return [(k, float(h[k].attrs["time"])) for k in step_keys(h)]


def last_period(times):
    """Indices of the times within one period T of the last one (all of them for a short run)."""
    times = np.asarray(times)
    return np.nonzero(times >= times[-1] - T - 1e-9)[0]


def smallest_driving(times):
    """Index of the output time of the last period where the driving |sin(2 pi t / T)| is
    smallest; of equal ones (t on kT/2 exactly), the latest."""
    idx = last_period(times)
    s = np.abs(np.sin(2 * math.pi * np.asarray(times)[idx] / T))
    return int(idx[np.nonzero(s <= s.min() + TIE)[0][-1]])


def _nearest(pairs, t):
    """The step key of [(key, time)] nearest to time t."""
    return pairs[int(np.argmin([abs(tt - t) for _, tt in pairs]))][0]


def fluid_step(folder, key):
    """Grid and the fields of one output step of fluid.h5."""
    with h5py.File(os.path.join(folder, "fluid.h5"), "r") as h:
        d = {"x_face": np.array(h["grid/x_face"]), "y_face": np.array(h["grid/y_face"])}
        d.update({k: np.array(h[key][k]) for k in ("u", "v", "p", "u_face")})
        d["time"] = float(h[key].attrs["time"])
    d["x_centre"] = 0.5 * (d["x_face"][1:] + d["x_face"][:-1])
    d["y_centre"] = 0.5 * (d["y_face"][1:] + d["y_face"][:-1])
    return d


def wall_state(folder, t):
    """The wall at the solid.h5 output step nearest time t: positions, velocities (x, y),
    triangles, kind, its surface nodes in x order and the node at C. The rigid wall writes its
    (fixed) mesh there too; without solid.h5 steps, the surface polyline of make_scene."""
    path = os.path.join(folder, "solid.h5")
    pairs = output_times(folder, "solid.h5") if os.path.exists(path) else []
    if not pairs:
        xs = np.linspace(0.0, make_scene.L, make_scene.NX + 1)
        pos = np.column_stack([xs, [make_scene.surface_y(x) for x in xs]])
        c = int(np.argmin(np.abs(xs - make_scene.C_X)))
        return {"position": pos, "velocity": np.zeros_like(pos), "triangles": None,
                "rigid": True, "surface": np.arange(len(xs)), "C": c}
    with h5py.File(path, "r") as h:
        key = _nearest(pairs, t)
        x_ref = np.array(h["body_wall/x_ref"])
        d = {"position": np.array(h[key]["body_wall/position"]),
             "velocity": np.array(h[key]["body_wall/velocity"])[:, :2],
             "triangles": np.array(h["body_wall/triangles"]),
             "rigid": str(h["body_wall"].attrs.get("kind", "elastic")) == "rigid"}
    # The surface nodes: those of the reference mesh on the cosine surface (wall.geo).
    on = np.abs(x_ref[:, 1] - np.array([make_scene.surface_y(x) for x in x_ref[:, 0]])) < 1e-9
    surface = np.nonzero(on)[0]
    d["surface"] = surface[np.argsort(x_ref[surface, 0])]
    d["C"] = int(np.argmin(np.hypot(x_ref[:, 0] - make_scene.C_X,
                                    x_ref[:, 1] - make_scene.surface_y(make_scene.C_X))))
    return d


def surface_at(wall, x):
    """The wall's current surface height at x (linear between its surface nodes)."""
    s = wall["position"][wall["surface"]]
    return np.interp(x, s[:, 0], s[:, 1])


def fibers_at(folder, t):
    """The fibers' markers X (n, 2) and segments (pairs of marker indices) at the fiber.h5 output
    step nearest time t; None without fibers."""
    path = os.path.join(folder, "fiber.h5")
    if not os.path.exists(path):
        return None
    pairs = output_times(folder, "fiber.h5")
    if not pairs:
        return None
    with h5py.File(path, "r") as h:
        return np.array(h[_nearest(pairs, t)]["X"]), np.array(h["layout/segments"])


def flow_rate_at(folder, times):
    """The flow rate through x = 1/2 (fluid_flow_rate.csv) at the given times."""
    q = table(os.path.join(folder, "fluid_flow_rate.csv"))
    return np.interp(times, q["time"], q["Q0"])


def draw_wall(ax, wall):
    """The wall's mesh (rigid dark, elastic light, as runs/lib/picture.py) and its surface line."""
    if wall["triangles"] is not None:
        ax.add_collection(PolyCollection(wall["position"][wall["triangles"]],
                                         facecolors="0.45" if wall["rigid"] else "0.85",
                                         edgecolors="0.3", linewidths=0.08, zorder=3))
    s = wall["position"][wall["surface"]]
    ax.plot(s[:, 0], s[:, 1], color="k", lw=0.8, zorder=4)


def profile(folder, key):
    """u along x = 1/2 (the u faces on that line) from the wall's surface at C up to y = 3H/4:
    the wall's own velocity at its surface, then the cell centres above it. (y, u, time)."""
    f = fluid_step(folder, key)
    wall = wall_state(folder, f["time"])
    i = int(np.argmin(np.abs(f["x_face"] - make_scene.C_X)))
    yc, vc = wall["position"][wall["C"]], wall["velocity"][wall["C"]]
    above = f["y_centre"] > yc[1]
    y = np.concatenate([[yc[1]], f["y_centre"][above]])
    u = np.concatenate([[vc[0]], f["u_face"][above, i]])
    return y, u, f["time"]


def profiles(folders, png):
    """profiles.png: u(y) through C for every variant at the output time of its last period with
    the smallest driving. folders: {variant: folder}. Returns {variant: {t, sin, flow_rate, y, u}}."""
    fig, ax = plt.subplots(figsize=(6.2, 5.2), layout="constrained")
    out = {}
    for v, folder in folders.items():
        pairs = output_times(folder)
        k = smallest_driving([t for _, t in pairs])
        y, u, t = profile(folder, pairs[k][0])
        q = float(flow_rate_at(folder, [t])[0])
        out[v] = {"t": t, "sin": math.sin(2 * math.pi * t / T), "flow_rate": q,
                  "y": y.tolist(), "u": u.tolist()}
        ax.plot(u, y, ".-", ms=3, lw=1.2, label=f"{v} (t = {t:.4g}, Q = {q:.3g})")
    ax.axvline(0.0, color="k", lw=0.6)
    ax.axhline(make_scene.surface_y(make_scene.C_X), color="0.5", lw=0.6, ls=":",
               label="rest position of the wall's surface at C")
    ax.set_ylim(top=0.75 * make_scene.H)
    ax.set_xlabel("u")
    ax.set_ylabel("y")
    ts = sorted({round(x["t"], 9) for x in out.values()})
    ax.set_title("streamwise velocity along x = 1/2 (through C), smallest pressure gradient\n"
                 f"(output time of the last period nearest t = kT/2: t = "
                 f"{', '.join(f'{t:.4g}' for t in ts)})", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    fig.savefig(png, dpi=110)
    plt.close(fig)
    return out


def fields(folder, variant, png):
    """fields_<variant>.png: pressure (minus its mean over the fluid) with velocity vectors (every
    QUIVER_EVERY-th cell in the fluid), the fibers and the wall at the output times of the last
    period with the largest forward and the largest backward flow rate; one colour scale and one
    vector scale for both. Returns {forward: {t, flow_rate}, backward: {...}}."""
    pairs = output_times(folder)
    times = np.array([t for _, t in pairs])
    idx = last_period(times)
    q = flow_rate_at(folder, times[idx])
    picks = [("forward", int(idx[np.argmax(q)]), float(np.max(q))),
             ("backward", int(idx[np.argmin(q)]), float(np.min(q)))]
    frames = []
    for what, k, qk in picks:
        f = fluid_step(folder, pairs[k][0])
        wall = wall_state(folder, f["time"])
        X, Y = np.meshgrid(f["x_centre"], f["y_centre"])
        fluid = Y > surface_at(wall, X)     # cells whose centre lies above the wall's surface
        p = f["p"] - np.mean(f["p"][fluid])  # the pressure's level is arbitrary
        frames.append((what, qk, f, wall, X, Y, fluid, np.ma.masked_where(~fluid, p)))
    lim = max(float(np.percentile(np.abs(fr[7].compressed()), 98)) for fr in frames)
    lim = lim if math.isfinite(lim) and lim > 0 else 1.0
    speed = max(float(np.max(np.hypot(fr[2]["u"], fr[2]["v"])[fr[6]])) for fr in frames)
    speed = speed if math.isfinite(speed) and speed > 0 else 1.0
    h = float(frames[0][2]["x_face"][1] - frames[0][2]["x_face"][0])
    # the fastest vector 1.5 times the vectors' spacing long
    scale = speed / (1.5 * QUIVER_EVERY * h)
    fig, axes = plt.subplots(1, 2, figsize=(12.5, 4.9), layout="constrained")
    out = {}
    for ax, (what, qk, f, wall, X, Y, fluid, p) in zip(axes, frames):
        m = ax.pcolormesh(f["x_face"], f["y_face"], p, cmap="RdBu_r", vmin=-lim, vmax=lim,
                          shading="flat", rasterized=True)
        s = (slice(QUIVER_EVERY // 2, None, QUIVER_EVERY),) * 2
        keep = fluid[s]
        qv = ax.quiver(X[s][keep], Y[s][keep], f["u"][s][keep], f["v"][s][keep], angles="xy",
                       scale_units="xy", scale=scale, width=0.0025, color="k", zorder=5)
        draw_wall(ax, wall)
        fib = fibers_at(folder, f["time"])
        if fib is not None:
            ax.add_collection(LineCollection(fib[0][fib[1]], colors="darkgreen", linewidths=1.3,
                                             zorder=6))
        c = wall["position"][wall["C"]]
        ax.plot(c[0], c[1], "o", color="m", ms=4, zorder=7)
        ax.annotate("C", c, xytext=(4, -10), textcoords="offset points", color="m", fontsize=8)
        ax.set_xlim(f["x_face"][0], f["x_face"][-1])
        ax.set_ylim(f["y_face"][0], f["y_face"][-1])
        ax.set_aspect("equal")
        ax.set_xlabel("x")
        ax.set_ylabel("y")
        # a short run may have no backward flow yet: say so instead of calling it backward
        label = {"forward": "largest forward flow" if qk > 0 else "largest flow (none forward)",
                 "backward": "largest backward flow" if qk < 0 else "smallest flow (none backward)"}
        ax.set_title(f"{variant}: {label[what]}, t = {f['time']:.4g}, Q = {qk:.3g}", fontsize=10)
        out[what] = {"t": f["time"], "flow_rate": qk}
    # the vectors' key at the figure's top left, clear of the titles
    ax.quiverkey(qv, 0.05, 0.965, speed, f"|u| = {speed:.3g}", labelpos="E",
                  coordinates="figure", fontproperties={"size": 8})
    fig.colorbar(m, ax=list(axes), shrink=0.85, pad=0.01, extend="both",
                 label="pressure minus its mean over the fluid")
    fig.suptitle("pressure, velocity (every 4th cell), fibers and wall at the extremes of the "
                 "flow rate in the last period", fontsize=10)
    fig.savefig(png, dpi=110)
    plt.close(fig)
    return out


def flow_rate_vs_e(amplitudes, rigid, default_e, png):
    """flow_rate_vs_E.png: the flow-rate amplitude of the elastic wall with fibers against its
    Young's modulus (log axis; amplitudes {E: value}, the default E marked), the rigid wall with
    fibers (rigid: its value, or None when it was not run) as the line E -> infinity. Returns the
    numbers."""
    es = sorted(amplitudes)
    a = [amplitudes[e] for e in es]
    fig, ax = plt.subplots(figsize=(6.2, 4.4), layout="constrained")
    ax.plot(es, a, "o-", color="C3", label="elastic wall with fibers")
    if default_e in amplitudes:
        ax.plot([default_e], [amplitudes[default_e]], "s", ms=9, mfc="none", color="k",
                label=f"default E = {default_e:g} (Table 4)")
    if rigid is not None:
        ax.axhline(rigid, color="C1", ls="--", label="rigid wall with fibers (E → ∞)")
    ax.set_xscale("log")
    ax.xaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    if len(es) <= 8:
        ax.set_xticks(es)  # the moduli run, labelled as they are
    ax.set_xlabel("Young's modulus of the wall E")
    ax.set_ylabel("flow-rate amplitude (max − min)/2")
    missing = [] if rigid is not None else ["rigid-fibers not run"]
    missing += [] if default_e in amplitudes else [f"E = {default_e:g} not run"]
    ax.set_title("flow-rate amplitude through x = 1/2 against the wall's stiffness"
                 + (f"\n({'; '.join(missing)})" if missing else ""), fontsize=9)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    fig.savefig(png, dpi=110)
    plt.close(fig)
    return {"E": es, "flow_rate_amplitude": a, "rigid_fibers_flow_rate_amplitude": rigid,
            "default_E": default_e}
