"""Shared code of the solid validation cases: run the `solid` program on a scene, read its output
(HDF5 fields, probe and history CSV, summary.json), record metrics as {value, reference, error,
tolerance, pass} in summary.json. Environment (set by `./fsi validate`): FSI_ROOT, FSI_BIN,
FSI_OUT. `--short` selects the quick version that the test suite runs."""
import json
import os
import subprocess
import sys
import time

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.environ.get("FSI_ROOT", os.path.abspath(os.path.join(HERE, "..", "..")))
BIN = os.environ.get("FSI_BIN", os.path.join(ROOT, "build", "bin"))
OUT = os.environ.get("FSI_OUT", os.path.join(os.getcwd(), "out"))
SHORT = "--short" in sys.argv


def scene_from(path, replace):
    """A committed scene file's text with lines replaced: {"key": "new line"} swaps the first
    line that starts with `key =`; mesh file names become absolute so that the scene runs from
    OUT."""
    folder = os.path.dirname(os.path.abspath(path))
    lines, pending = [], dict(replace)
    for line in open(path).read().splitlines():
        key = line.split("=")[0].strip()
        if key in pending:
            line = pending.pop(key)
        elif key == "mesh":
            name = line.split("=", 1)[1].strip().strip('"')
            line = f'mesh = "{os.path.join(folder, name)}"'
        lines.append(line)
    return "\n".join(lines) + "\n"


def run(name, scene_text):
    """Write OUT/name.toml, run the solid program into OUT/name; return (folder, wall seconds)."""
    os.makedirs(OUT, exist_ok=True)
    scene = os.path.join(OUT, name + ".toml")
    with open(scene, "w") as f:
        f.write(scene_text)
    folder = os.path.join(OUT, name)
    t0 = time.time()
    r = subprocess.run([os.path.join(BIN, "solid"), scene, "--out-dir", folder, "--overwrite"],
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    wall = time.time() - t0
    if r.returncode != 0:
        sys.stderr.write(r.stdout)
        raise RuntimeError(f"solid failed on scene {name}")
    return folder, wall


def summary(folder):
    with open(os.path.join(folder, "summary.json")) as f:
        return json.load(f)


def csv(folder, name):
    """A CSV written by the program (header row), as a dict of numpy columns."""
    data = np.genfromtxt(os.path.join(folder, name), delimiter=",", names=True, deletechars="")
    return {k: np.atleast_1d(data[k]) for k in data.dtype.names}


def last_state(folder, body):
    """Reference nodes, triangles and the last written fields of one body."""
    with h5py.File(os.path.join(folder, "solid.h5"), "r") as h:
        steps = sorted(k for k in h.keys() if k.startswith("step_"))
        g = h[steps[-1]][f"body_{body}"]
        d = {k: np.array(g[k]) for k in g.keys()}
        d["time"] = float(h[steps[-1]].attrs["time"])
        d["x_ref"] = np.array(h[f"body_{body}/x_ref"])
        d["triangles"] = np.array(h[f"body_{body}/triangles"])
    return d


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
