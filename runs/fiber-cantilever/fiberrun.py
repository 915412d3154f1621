"""Shared code of the fiber validation cases: run the `fiber` program on a scene, read its probes,
support loads, HDF5 output and report, record metrics as {value, reference, error, tolerance,
pass} in summary.json. Environment (set by `./fsi validate`): FSI_ROOT, FSI_BIN, FSI_OUT."""
import json
import os
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
BIN = os.environ.get("FSI_BIN", os.path.join(HERE, "..", "..", "build", "bin"))
OUT = os.environ.get("FSI_OUT", os.path.join(os.getcwd(), "out"))
SHORT = "--short" in sys.argv

HEADER = """[scene]
name = "{name}"
[time]
dt = {dt!r}
t_end = {t_end!r}
[output]
interval = {interval!r}
"""


def run(name, scene_text, expect_error=False):
    """Write OUT/name.toml, run the fiber program into OUT/name; return (folder, wall seconds).
    With expect_error, return the program's output instead and require a failure."""
    os.makedirs(OUT, exist_ok=True)
    scene = os.path.join(OUT, name + ".toml")
    with open(scene, "w") as f:
        f.write(scene_text)
    folder = os.path.join(OUT, name)
    t0 = time.time()
    r = subprocess.run([os.path.join(BIN, "fiber"), scene, "--out-dir", folder, "--overwrite"],
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    wall = time.time() - t0
    if expect_error:
        if r.returncode == 0:
            raise RuntimeError(f"fiber should have failed on {scene}")
        return r.stdout
    if r.returncode != 0:
        sys.stderr.write(r.stdout)
        raise RuntimeError(f"fiber failed on {scene}")
    return folder, wall


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


def metric(value, reference, error, tolerance):
    ok = bool(np.isfinite(value) and np.isfinite(error) and error <= tolerance)
    return {"value": float(value), "reference": float(reference), "error": float(error),
            "tolerance": float(tolerance), "pass": ok}


def relative(value, reference, tolerance):
    return metric(value, reference, abs(value - reference) / abs(reference), tolerance)


def finish(case, metrics, extra=None):
    """Write OUT/summary.json; exit 1 when a metric fails."""
    s = {"case": case, "short": SHORT, "metrics": metrics}
    if extra:
        s.update(extra)
    with open(os.path.join(OUT, "summary.json"), "w") as f:
        json.dump(s, f, indent=2)
    bad = [k for k, m in metrics.items() if not m["pass"]]
    for k, m in metrics.items():
        print(f"  {k}: {m['value']:.6g} (reference {m['reference']:.6g}, error {m['error']:.3g}, "
              f"tolerance {m['tolerance']:.3g}) {'pass' if m['pass'] else 'FAIL'}")
    if bad:
        print(f"{case}: failed: {', '.join(bad)}")
        sys.exit(1)
    print(f"{case}: all {len(metrics)} metrics pass")
