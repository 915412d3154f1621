"""Shared code of the fiber validation cases: run the `fiber` program on a scene, read its probes,
support loads, HDF5 output and report, record metrics as {value, reference, error, tolerance,
pass} in summary.json. Environment (set by `./fsi validate`): FSI_ROOT, FSI_BIN, FSI_OUT."""
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
from caserun import BIN, OUT, ROOT, SHORT, finish, metric, relative, run_program  # noqa: E402,F401


HERE = os.path.dirname(os.path.abspath(__file__))

HEADER = """[scene]
name = "{name}"
[time]
dt = {dt!r}
t_end = {t_end!r}
[output]
interval = {interval!r}
"""


def write_points(name, points):
    """Marker positions for shape = "points"; returns the file name (next to the scene)."""
    os.makedirs(OUT, exist_ok=True)
    fname = name + "_points.csv"
    np.savetxt(os.path.join(OUT, fname), np.asarray(points), delimiter=", ", header="x, y", comments="")
    return fname


def table(path):
    """A CSV with a header `time,a.b,...` as a dict of numpy columns."""
    with open(path) as f:
        names = f.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return {n: data[:, i] for i, n in enumerate(names)}


def probes(folder):
    return table(os.path.join(folder, "fiber_probes.csv"))


def loads(folder):
    return table(os.path.join(folder, "fiber_loads.csv"))


def report(folder):
    with open(os.path.join(folder, "summary.json")) as f:
        return json.load(f)


def steps(folder):
    """Every output step of fiber.h5: list of dicts with time, X (n, 2), tension, curvature."""
    import h5py
    out = []
    with h5py.File(os.path.join(folder, "fiber.h5"), "r") as h:
        for k in sorted(k for k in h.keys() if k.startswith("step_")):
            g = h[k]
            out.append({"time": float(g.attrs["time"]), "X": np.array(g["X"]),
                        "tension": np.array(g["tension"]), "curvature": np.array(g["curvature"])})
    return out


def zero_crossings(t, y):
    s = np.signbit(y)
    i = np.nonzero(s[1:] != s[:-1])[0]
    return t[i] + (t[i + 1] - t[i]) * y[i] / (y[i] - y[i + 1])


def period(t, y):
    """Mean period over whole periods between zero crossings (an offset of the mean cancels)."""
    z = zero_crossings(t, y)
    if len(z) < 3:
        return float("nan")
    last = len(z) - 1 - (len(z) - 1) % 2
    return 2 * (z[last] - z[0]) / last


def run(name, scene_text, expect_error=False):
    """Run the fiber program on a scene (see caserun.run_program)."""
    return run_program("fiber", name, scene_text, expect_error)
