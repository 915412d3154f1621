"""The picture of any run folder, chosen from what the run wrote: the fluid field, the bodies'
current meshes, the fibers, the contact planes, and the probes' histories beside them. One frame
per output step: picture() draws the last one (runs/plot_run.py), runs/movie.py all of them.

What is shown when:
- fluid.h5: the field of the output step, with a colour bar. Vorticity, unless the flow is
  parallel (its vorticity varies along one axis only: averaging it along x or along y leaves
  less than 5 % of its RMS, as in a pressure-driven channel or a shear layer) or at rest; its
  vorticity then only restates the profile's slope, and the speed |u| is shown instead. The rule
  is applied to the last output step and holds for every frame of a movie, as does its colour
  scale (the 98th percentile of |field| at the last step).
- solid.h5: every body's mesh at the output step nearest in time, rigid bodies dark, elastic
  ones light, element edges drawn; rigid planes of contact (solid.plane) as hatched lines.
- fiber.h5: every fiber's markers and segments.
- probe CSVs (fluid_probes.csv, solid_probes.csv, fiber_probes.csv): one history axis per file
  and quantity, all the file's probes in it: the first two (one when there are three files) of
  ux, uy, vx, vy, p, then the file's other quantities, leaving out those that stay constant (their
  range below 1e-8 of the file's largest). Beside the field when the domain is about square,
  below it when it is wide. No probes: no history panel. A movie marks the time.
- Without a fluid the view is the box around every body's and fiber's positions of all steps.
"""
import os
import tomllib

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection, PolyCollection  # noqa: E402

import fiberout  # noqa: E402
import fluidout  # noqa: E402
import outputs  # noqa: E402
import solidout  # noqa: E402

PARALLEL = 0.05  # the x- or y-average of the vorticity leaves less than this of its RMS
PROBE_FILES = [("fluid_probes.csv", "fluid probe"), ("solid_probes.csv", "solid probe"),
               ("fiber_probes.csv", "fiber probe")]
MAX_PROBES = 6  # lines per history axis
PREFERRED = ("ux", "uy", "vx", "vy", "p")  # the quantities a history shows first
FLAT = 1e-8  # a quantity whose range is below this of the file's largest range is left out


def field_rule(u, v, w):
    """'vorticity' or 'speed' for cell-centred u, v and vorticity w (module docstring)."""
    rms = np.sqrt(np.mean(w ** 2))
    scale = max(np.max(np.abs(u)), np.max(np.abs(v)), 1e-300)
    if not np.isfinite(rms) or rms <= 1e-12 * scale / max(w.shape):
        return "speed"
    along_x = np.sqrt(np.mean((w - w.mean(axis=1, keepdims=True)) ** 2))
    along_y = np.sqrt(np.mean((w - w.mean(axis=0, keepdims=True)) ** 2))
    return "speed" if min(along_x, along_y) < PARALLEL * rms else "vorticity"


def _nearest(times, t):
    return int(np.argmin(np.abs(np.asarray(times) - t)))



class NoFields(SystemExit):
    """A run that wrote no field output ([output] interval = 0): nothing to draw. Uncaught, it
    ends the script with its message."""

class Run:
    """What a run folder holds, read once: the frames' times and, per frame, the field, the bodies
    and the fibers."""

    def __init__(self, folder):
        self.folder = folder
        self.name = os.path.basename(os.path.normpath(folder))
        if os.path.exists(os.path.join(folder, "summary.json")):
            self.name = outputs.summary(folder).get("scene", self.name)
        self.has_fluid = self._has_steps("fluid.h5")
        self.has_solid = self._has_steps("solid.h5")
        self.has_fiber = self._has_steps("fiber.h5")
        if not (self.has_fluid or self.has_solid or self.has_fiber):
            raise NoFields(f"{folder}: no fluid.h5, solid.h5 or fiber.h5 with output steps")
        self._read_fluid()
        self._read_solid()
        self._read_fiber()
        self._read_planes()
        self.times = (self.fluid_times if self.has_fluid else
                      self.solid_times if self.has_solid else self.fiber_times)
        self.probes = self._read_probes()

    def _has_steps(self, name):
        path = os.path.join(self.folder, name)
        if not os.path.exists(path):
            return False
        with h5py.File(path, "r") as h:
            return bool(outputs.step_keys(h))

    def _read_fluid(self):
        self.fluid_times, self.fields = [], []
        if not self.has_fluid:
            return
        self.grid = fluidout.grid(self.folder)
        states = fluidout.states(self.folder, ("u", "v", "vorticity"))
        self.fluid_times = [t for t, _ in states]
        last = states[-1][1]
        self.field = field_rule(last["u"], last["v"], last["vorticity"])
        for _, f in states:
            self.fields.append(f["vorticity"] if self.field == "vorticity"
                               else np.hypot(f["u"], f["v"]))
        # One colour scale for every frame, the last one's (the picture's): the 98th percentile
        # of |field|, so that a start-up transient or a corner singularity does not wash it out.
        top = float(np.percentile(np.abs(self.fields[-1]), 98))
        self.limit = top if np.isfinite(top) and top > 0 else 1.0

    def _read_solid(self):
        self.bodies, self.solid_times = [], []
        if not self.has_solid:
            return
        with h5py.File(os.path.join(self.folder, "solid.h5"), "r") as h:
            names = [(k[len("body_"):], str(h[k].attrs.get("kind", "elastic")))
                     for k in h.keys() if k.startswith("body_")]
        for name, kind in names:
            tri = solidout.last_state(self.folder, name)["triangles"]
            _, states = solidout.states(self.folder, name)
            self.solid_times = [t for t, _ in states]
            self.bodies.append({"name": name, "rigid": kind == "rigid", "triangles": tri,
                                "positions": [x for _, x in states]})

    def _read_fiber(self):
        self.fiber_times, self.fiber_markers, self.segments = [], [], None
        if not self.has_fiber:
            return
        with h5py.File(os.path.join(self.folder, "fiber.h5"), "r") as h:
            if "layout/segments" in h:
                self.segments = np.array(h["layout/segments"])
        steps = fiberout.steps(self.folder)
        self.fiber_times = [s["time"] for s in steps]
        self.fiber_markers = [s["X"] for s in steps]

    def _read_planes(self):
        """Rigid contact planes of the effective scene (solid.plane: point, normal)."""
        self.planes = []
        path = os.path.join(self.folder, "scene.effective.toml")
        if self.has_solid and os.path.exists(path):
            with open(path, "rb") as f:
                scene = tomllib.load(f)
            for p in scene.get("solid", {}).get("plane", []):
                self.planes.append((np.array(p["point"], float), np.array(p["normal"], float)))

    def _read_probes(self):
        found = []
        for fname, label in PROBE_FILES:
            path = os.path.join(self.folder, fname)
            if not os.path.exists(path):
                continue
            t = outputs.table(path)
            cols = [c for c in t.dtype.names if "." in c]
            if len(t) < 2 or not cols:
                continue
            found.append((label, t, cols))
        per_file = 1 if len(found) > 2 else 2
        axes = []
        for label, t, cols in found:
            quantities = list(dict.fromkeys(c.rsplit(".", 1)[1] for c in cols))
            spread = {q: max(np.ptp(t[c]) for c in cols if c.endswith("." + q))
                      for q in quantities}
            top = max(spread.values())
            live = [q for q in quantities if top > 0 and spread[q] > FLAT * top]
            chosen = [q for q in PREFERRED if q in live] + [q for q in live if q not in PREFERRED]
            for q in chosen[:per_file]:
                lines = [c for c in cols if c.rsplit(".", 1)[1] == q]
                axes.append({"label": label, "quantity": q, "time": t["time"],
                             "lines": [(c.rsplit(".", 1)[0], t[c]) for c in lines[:MAX_PROBES]],
                             "more": max(0, len(lines) - MAX_PROBES)})
        return axes

    def contents(self):
        """What the picture shows, in words: 'shows: vorticity, bodies, fibers; histories: ...'."""
        what = ([self.field] if self.has_fluid else []) + (["bodies"] if self.bodies else []) + \
            (["planes"] if self.planes else []) + (["fibers"] if self.fiber_markers else [])
        hist = [f"{h['label']} {h['quantity']}" for h in self.probes]
        return f"shows: {', '.join(what)}; histories: {', '.join(hist) or 'none'}"

    def box(self):
        """The view: the fluid's domain, else the box around all bodies and fibers of all steps."""
        if self.has_fluid:
            g = self.grid
            return g["x_face"][0], g["x_face"][-1], g["y_face"][0], g["y_face"][-1]
        pts = [x for b in self.bodies for x in b["positions"]] + list(self.fiber_markers)
        pts = np.vstack(pts)
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        pad = 0.08 * max(hi - lo) + 1e-12
        return lo[0] - pad, hi[0] + pad, lo[1] - pad, hi[1] + pad


def _wide(box):
    """A domain wider than 1.6 times its height: histories below, not beside."""
    return (box[1] - box[0]) > 1.6 * (box[3] - box[2])


def _layout(run):
    """Figure and axes: the field's axes and the history axes (beside or below)."""
    n = len(run.probes)
    wide = _wide(run.box())
    x0, x1, y0, y1 = run.box()
    aspect = (x1 - x0) / (y1 - y0)
    if wide:
        width = 11.0
        height = min(9.5 / aspect, 6.0) + 1.0 + (2.3 if n else 0)
        fig = plt.figure(figsize=(width, height), layout="constrained")
        if n:
            gs = fig.add_gridspec(2, n, height_ratios=[max(height - 2.3, 1.5), 2.0])
            ax = fig.add_subplot(gs[0, :])
            hist = [fig.add_subplot(gs[1, k]) for k in range(n)]
        else:
            ax, hist = fig.add_subplot(), []
    else:
        height = 5.5
        field_w = min(height * aspect, 9.0) + 1.2
        width = field_w + (4.2 if n else 0)
        fig = plt.figure(figsize=(width, height), layout="constrained")
        if n:
            gs = fig.add_gridspec(n, 2, width_ratios=[field_w, 4.0])
            ax = fig.add_subplot(gs[:, 0])
            hist = [fig.add_subplot(gs[k, 1]) for k in range(n)]
        else:
            ax, hist = fig.add_subplot(), []
    return fig, ax, hist


def _draw_planes(ax, planes, box):
    x0, x1, y0, y1 = box
    size = 4 * max(x1 - x0, y1 - y0)
    for p, n in planes:
        n = n / np.linalg.norm(n)
        t = np.array([-n[1], n[0]])
        a, b = p - size * t, p + size * t
        ax.plot([a[0], b[0]], [a[1], b[1]], color="k", lw=1.5, zorder=4)
        poly = np.array([a, b, b - 0.04 * size * n, a - 0.04 * size * n])
        ax.fill(poly[:, 0], poly[:, 1], facecolor="none", edgecolor="0.45", hatch="///",
                lw=0, zorder=3)


def draw(run, k, cursor=False):
    """The figure of frame k (an index into run.times); cursor: mark the time in the histories."""
    t = run.times[k]
    fig, ax, hist = _layout(run)
    box = run.box()
    what = []
    if run.has_fluid:
        f = run.fields[k]
        g = run.grid
        if run.field == "vorticity":
            m = ax.pcolormesh(g["x_face"], g["y_face"], f, cmap="RdBu_r", vmin=-run.limit,
                              vmax=run.limit, shading="flat", rasterized=True)
            label = "vorticity ∂v/∂x − ∂u/∂y"
        else:
            m = ax.pcolormesh(g["x_face"], g["y_face"], f, cmap="viridis", vmin=0,
                              vmax=run.limit, shading="flat", rasterized=True)
            label = "speed |u|"
        fig.colorbar(m, ax=ax, label=label, shrink=0.9, pad=0.01, extend="both" if
                     run.field == "vorticity" else "max")
        what.append(run.field)
    if run.bodies:
        j = _nearest(run.solid_times, t)
        # Element edges as thin as the elements are small on the page, so that a fine mesh
        # stays a mesh and does not turn into a black patch.
        px = 0.8 * fig.get_figwidth() * fig.dpi / (box[1] - box[0]) * (1 if not run.probes or
                                                                        _wide(box) else 0.6)
        for b in run.bodies:
            x = b["positions"][j]
            tris = x[b["triangles"]]
            edge = np.median(np.linalg.norm(tris[:, 1] - tris[:, 0], axis=1)) * px
            ax.add_collection(PolyCollection(tris, facecolors="0.35" if b["rigid"] else "0.85",
                                             edgecolors="0.15" if b["rigid"] else "0.3",
                                             linewidths=float(np.clip(0.06 * edge, 0.05, 0.4)),
                                             zorder=2))
        what.append("bodies")
    if run.planes:
        _draw_planes(ax, run.planes, box)
    if run.fiber_markers:
        X = run.fiber_markers[_nearest(run.fiber_times, t)]
        if run.segments is not None:
            ax.add_collection(LineCollection(X[run.segments], colors="k", linewidths=1.4,
                                             zorder=5))
        ax.plot(X[:, 0], X[:, 1], ".", color="darkorange", ms=2.5, zorder=6)
        what.append("fibers")
    ax.set_xlim(box[0], box[1])
    ax.set_ylim(box[2], box[3])
    ax.set_aspect("equal")
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_title(f"{run.name}: {', '.join(what)}, t = {t:.4g}")
    for a, h in zip(hist, run.probes):
        for name, y in h["lines"]:
            a.plot(h["time"], y, lw=0.9, label=name)
        if cursor:
            a.axvline(t, color="k", lw=0.8, ls="--")
        a.set_xlabel("t")
        a.set_ylabel(h["quantity"])
        more = f" (+{h['more']} more)" if h["more"] else ""
        a.set_title(f"{h['label']} {h['quantity']}{more}", fontsize=9)
        a.grid(alpha=0.3)
        a.legend(fontsize=7, loc="best")
    return fig


def picture(folder, png=None, dpi=120):
    """Draw the last output step of a run folder into png (default folder/picture.png); returns
    the PNG's path and what it shows (Run.contents)."""
    run = Run(folder)
    png = png or os.path.join(folder, "picture.png")
    fig = draw(run, len(run.times) - 1)
    fig.savefig(png, dpi=dpi)
    plt.close(fig)
    return png, run.contents()
