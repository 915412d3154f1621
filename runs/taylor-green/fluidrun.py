"""Helpers of the fluid validation cases: run the `fluid` program on a scene, read its HDF5
output, record metrics as {value, reference, error, tolerance, pass} in summary.json.
Environment (set by `./fsi validate`): FSI_ROOT, FSI_BIN, FSI_OUT."""
import os
import sys

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
from caserun import BIN, OUT, ROOT, SHORT, finish, metric, relative, run_program  # noqa: E402,F401


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


def run(name, scene_text):
    """Run the fluid program on a scene (see caserun.run_program)."""
    return run_program("fluid", name, scene_text)
