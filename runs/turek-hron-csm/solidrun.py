"""Shared code of the solid validation cases: run the `solid` program on a scene, read its output
(HDF5 fields, probe and history CSV, summary.json), record metrics as {value, reference, error,
tolerance, pass} in summary.json. Environment (set by `./fsi validate`): FSI_ROOT, FSI_BIN,
FSI_OUT. `--short` selects the quick version that the test suite runs."""
import json
import os
import sys

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
from caserun import BIN, OUT, ROOT, SHORT, finish, metric, relative, run_program  # noqa: E402,F401


HERE = os.path.dirname(os.path.abspath(__file__))


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


def run(name, scene_text):
    """Run the solid program on a scene (see caserun.run_program)."""
    return run_program("solid", name, scene_text)
