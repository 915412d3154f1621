"""Helpers of the fluid validation cases: run the `fluid` program on a scene, read its HDF5
output, record metrics as {value, reference, error, tolerance, pass} in summary.json.
Environment (set by `./fsi validate`): FSI_ROOT, FSI_BIN, FSI_OUT."""
import json
import os
import subprocess
import sys
import time

import h5py
import numpy as np

BIN = os.environ.get("FSI_BIN", os.path.join(os.path.dirname(__file__), "..", "..", "build", "bin"))
OUT = os.environ.get("FSI_OUT", os.path.join(os.getcwd(), "out"))
SHORT = "--short" in sys.argv


def run(name, scene_text):
    """Write OUT/name.toml, run the fluid program into OUT/name; return (folder, wall seconds)."""
    os.makedirs(OUT, exist_ok=True)
    scene = os.path.join(OUT, name + ".toml")
    with open(scene, "w") as f:
        f.write(scene_text)
    folder = os.path.join(OUT, name)
    t0 = time.time()
    r = subprocess.run([os.path.join(BIN, "fluid"), scene, "--out-dir", folder, "--overwrite"],
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    wall = time.time() - t0
    if r.returncode != 0:
        sys.stderr.write(r.stdout)
        raise RuntimeError(f"fluid failed on {scene}")
    return folder, wall


def last_state(folder):
    """Grid and staggered fields of the last output step."""
    with h5py.File(os.path.join(folder, "fluid.h5"), "r") as h:
        steps = sorted(k for k in h.keys() if k.startswith("step_"))
        g = h[steps[-1]]
        d = {k: np.array(g[k]) for k in g.keys()}
        d["time"] = float(g.attrs["time"])
        d["x_face"] = np.array(h["grid/x_face"])
        d["y_face"] = np.array(h["grid/y_face"])
    d["x_centre"] = 0.5 * (d["x_face"][1:] + d["x_face"][:-1])
    d["y_centre"] = 0.5 * (d["y_face"][1:] + d["y_face"][:-1])
    return d


def probes(folder):
    data = np.genfromtxt(os.path.join(folder, "fluid_probes.csv"), delimiter=",", names=True)
    return data


def metric(value, reference, error, tolerance):
    ok = bool(np.isfinite(value) and np.isfinite(error) and error <= tolerance)
    return {"value": float(value), "reference": float(reference), "error": float(error),
            "tolerance": float(tolerance), "pass": ok}


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
