"""Reading the fluid program's output: fluid.h5 (the MAC grid's faces, staggered fields per
output step: u_face, v_face, pressure, vorticity, wall shear) and fluid_probes.csv."""
import os

import h5py
import numpy as np

from outputs import step_keys, table


def probes(folder):
    return table(os.path.join(folder, "fluid_probes.csv"))


def grid(folder):
    """Face coordinates x_face, y_face and cell centres x_centre, y_centre."""
    with h5py.File(os.path.join(folder, "fluid.h5"), "r") as h:
        d = {"x_face": np.array(h["grid/x_face"]), "y_face": np.array(h["grid/y_face"])}
    d["x_centre"] = 0.5 * (d["x_face"][1:] + d["x_face"][:-1])
    d["y_centre"] = 0.5 * (d["y_face"][1:] + d["y_face"][:-1])
    return d


def last_state(folder):
    """Grid and every field of the last output step, with its time."""
    d = grid(folder)
    with h5py.File(os.path.join(folder, "fluid.h5"), "r") as h:
        g = h[step_keys(h)[-1]]
        d.update({k: np.array(g[k]) for k in g.keys()})
        d["time"] = float(g.attrs["time"])
    return d


def states(folder, fields=("u_face", "v_face")):
    """[(time, {field: array})] of every output step."""
    out = []
    with h5py.File(os.path.join(folder, "fluid.h5"), "r") as h:
        for k in step_keys(h):
            out.append((float(h[k].attrs["time"]), {f: np.array(h[k][f]) for f in fields}))
    return out


def mean_u(folder, since=None):
    """x-averaged u at the cell centres: (y_centre, times, profiles) of the output steps from
    time `since` on (None: the last step only)."""
    g = grid(folder)
    ts, us = [], []
    with h5py.File(os.path.join(folder, "fluid.h5"), "r") as h:
        keys = step_keys(h)
        for k in keys if since is not None else keys[-1:]:
            t = float(h[k].attrs["time"])
            if since is None or t >= since - 1e-9:
                ts.append(t)
                us.append(np.array(h[k]["u_face"])[:, :-1].mean(axis=1))
    return g["y_centre"], np.array(ts), np.array(us)
