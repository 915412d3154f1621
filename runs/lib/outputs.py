"""What every program's output folder shares: CSV files with a header row (probes, histories,
loads, forces), summary.json, and HDF5 files whose output steps are groups `step_<k>`."""
import json
import os

import numpy as np


def table(path, in_progress=False):
    """A CSV with a header row as a numpy record array (columns by name, dots kept: t["A.ux"]).
    in_progress: the file of a run still writing it, whose last line may be torn: a row without
    every column is left out instead of an error."""
    return np.atleast_1d(np.genfromtxt(path, delimiter=",", names=True, deletechars="",
                                       invalid_raise=not in_progress))


def commented_rows(path):
    """The rows of a small CSV file with a header row, whose blank lines and lines starting with
    `#` (sources, notes) are skipped, as dicts of strings by column name; the last column keeps
    any commas of its own (a source's text)."""
    lines = [ln.strip() for ln in open(path) if ln.strip() and not ln.startswith("#")]
    head = lines[0].split(",")
    return [dict(zip(head, ln.split(",", len(head) - 1))) for ln in lines[1:]]


def summary(folder):
    """A run's summary.json (settings, steps, wall time per program, the program's results)."""
    with open(os.path.join(folder, "summary.json")) as f:
        return json.load(f)


def step_keys(h5):
    """The output step groups of an open HDF5 file, in step order."""
    return sorted((k for k in h5.keys() if k.startswith("step_")), key=lambda k: int(k.split("_")[1]))
