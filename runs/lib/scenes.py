"""Scene text for a case's runs: a committed scene file with some lines replaced, and marker
files for fibers given by points."""
import os

import numpy as np


def edit(path, replace, strict=True):
    """The scene file's text with lines replaced: {"key": "new line"} swaps the first line whose
    key is `key`; `mesh = "file"` becomes absolute so that the scene runs from any folder. With
    strict, every key must be found."""
    folder = os.path.dirname(os.path.abspath(path))
    lines, pending = [], dict(replace)
    for line in open(path).read().splitlines():
        key = line.split("=")[0].strip()
        if key in pending:
            line = pending.pop(key)
        elif key == "mesh" and not line.strip().startswith("#"):
            name = line.split("=", 1)[1].strip().strip('"')
            line = f'mesh = "{os.path.join(folder, name)}"'
        lines.append(line)
    if strict and pending:
        raise SystemExit(f"{path} lacks the keys {list(pending)}")
    return "\n".join(lines) + "\n"


def shifted_band(band, shift):
    """A grid band (from, to, cells) moved by `shift` of its spacing, its ends rounded as a
    scene written with {:g} holds them (so a run's record and its scene agree)."""
    a, b, m = band
    d = shift * (b - a) / m
    return float(f"{a + d:g}"), float(f"{b + d:g}"), m


def write_points(folder, name, points):
    """Marker positions for a fiber's shape = "points" in folder/name_points.csv; returns the
    file name (the scene beside it names it)."""
    os.makedirs(folder, exist_ok=True)
    fname = name + "_points.csv"
    np.savetxt(os.path.join(folder, fname), np.asarray(points), delimiter=", ", header="x, y",
               comments="")
    return fname


# The head of a scene: its name, time step, end time and output interval (fields for format()).
HEADER = """[scene]
name = "{name}"
[time]
dt = {dt!r}
t_end = {t_end!r}
[output]
interval = {interval!r}
"""
