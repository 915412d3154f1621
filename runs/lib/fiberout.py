"""Reading the fiber program's output: fiber.h5 (per output step the markers X, tension and
curvature), fiber_probes.csv (points along fibers), fiber_loads.csv (the load each fiber puts on
its support: fx, fy, moment)."""
import os

import h5py
import numpy as np

from outputs import step_keys, table


def probes(folder):
    return table(os.path.join(folder, "fiber_probes.csv"))


def loads(folder):
    return table(os.path.join(folder, "fiber_loads.csv"))


def steps(folder):
    """Every output step of fiber.h5: list of dicts with time, X (n, 2), tension, curvature."""
    out = []
    with h5py.File(os.path.join(folder, "fiber.h5"), "r") as h:
        for k in step_keys(h):
            g = h[k]
            out.append({"time": float(g.attrs["time"]), "X": np.array(g["X"]),
                        "tension": np.array(g["tension"]), "curvature": np.array(g["curvature"])})
    return out
