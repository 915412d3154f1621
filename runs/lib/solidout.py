"""Reading the solid program's output: solid.h5 (per body its reference nodes x_ref, triangles
and modes; per output step its fields: position, velocity, contact pressure ...),
solid_probes.csv, solid_history.csv."""
import os

import h5py
import numpy as np

from outputs import step_keys, table


def probes(folder):
    return table(os.path.join(folder, "solid_probes.csv"))


def history(folder):
    return table(os.path.join(folder, "solid_history.csv"))


def last_state(folder, body):
    """Reference nodes, triangles and the last written fields of one body, with the time."""
    with h5py.File(os.path.join(folder, "solid.h5"), "r") as h:
        last = step_keys(h)[-1]
        g = h[last][f"body_{body}"]
        d = {k: np.array(g[k]) for k in g.keys()}
        d["time"] = float(h[last].attrs["time"])
        d["x_ref"] = np.array(h[f"body_{body}/x_ref"])
        d["triangles"] = np.array(h[f"body_{body}/triangles"])
    return d


def states(folder, body):
    """Reference nodes of a body and [(time, positions)] of every output step."""
    with h5py.File(os.path.join(folder, "solid.h5"), "r") as h:
        x_ref = np.array(h[f"body_{body}/x_ref"])
        out = [(float(h[k].attrs["time"]), np.array(h[k][f"body_{body}/position"]))
               for k in step_keys(h)]
    return x_ref, out


def modes(folder, body, count):
    """Reference nodes and the first `count` mode shapes of a body (solid.analysis with modes)."""
    with h5py.File(os.path.join(folder, "solid.h5"), "r") as h:
        return (np.array(h[f"body_{body}/x_ref"]),
                [np.array(h[f"body_{body}/mode_{k}"]) for k in range(1, count + 1)])
