"""Open every XDMF file of a run's output folder in ParaView and check what it shows against the
HDF5 data the file points to. Run with pvpython (Debian's python3-paraview):

  pvpython check_paraview.py OUT_DIR [--image FILE.png]

For each .xdmf file and each of ParaView's three XDMF readers (XDMFReader, Xdmf3ReaderS,
Xdmf3ReaderT): the time steps equal the file's Time values; at the first and the last step the
grid has the cell count of its topology, its bounds are the extremes of the node positions in
the HDF5 file, and every array has the range of its HDF5 dataset (per component). Then one image
of the last step: the fluid's first scalar with the bodies and fibers drawn over it. Prints each
problem and exits 1 if there is any (or when the folder has no .xdmf file).
"""
import argparse
import os
import sys
import xml.etree.ElementTree as ET

import h5py
import numpy as np
from paraview import servermanager
from paraview import simple

READERS = ("XDMFReader", "Xdmf3ReaderS", "Xdmf3ReaderT")
RTOL = 1e-12


def heavy(path, item):
    """The array an XDMF DataItem points to ("file.h5:/dataset", relative to the .xdmf)."""
    name, dataset = item.text.strip().split(":", 1)
    with h5py.File(os.path.join(os.path.dirname(path), name), "r") as f:
        return f[dataset][()]


def expected(path):
    """Per step of the file: its time, cell count, node positions and {array name: values}."""
    steps = []
    for grid in ET.parse(path).getroot().find("Domain/Grid").findall("Grid"):
        topo = grid.find("Topology")
        kind = topo.get("TopologyType")
        geometry = grid.find("Geometry")
        if kind in ("2DSMesh", "2DRectMesh"):
            ny, nx = (int(d) for d in topo.get("Dimensions").split())
            cells = (nx - 1) * (ny - 1)
        else:
            cells = int(topo.get("NumberOfElements"))
        if geometry.get("GeometryType") == "VXVY":  # coordinates per direction
            x, y = (heavy(path, item) for item in geometry.findall("DataItem"))
            nodes = np.stack([c.ravel() for c in np.meshgrid(x, y)], axis=1)
        else:
            nodes = heavy(path, geometry.find("DataItem")).reshape(-1, 2)
        arrays = {a.get("Name"): heavy(path, a.find("DataItem")) for a in grid.findall("Attribute")}
        steps.append({"time": float(grid.find("Time").get("Value")), "kind": kind, "cells": cells,
                      "nodes": nodes, "arrays": arrays})
    return steps


def close(a, b, scale):
    return abs(a - b) <= RTOL * max(1.0, scale)


def check_reader(path, reader_name, steps, problems):
    where = f"{os.path.basename(path)} ({reader_name})"
    reader = getattr(simple, reader_name)(**({"FileNames": [path]} if reader_name == "XDMFReader"
                                               else {"FileName": [path]}))
    times = list(reader.TimestepValues) if len(steps) > 1 else [steps[0]["time"]]
    want = [s["time"] for s in steps]
    if len(times) != len(want) or any(not close(a, b, abs(b)) for a, b in zip(times, want)):
        problems.append(f"{where}: time steps {times}, the file has {want}")
        return
    for s in (steps[0], steps[-1]):
        reader.UpdatePipeline(s["time"])
        data = servermanager.Fetch(reader)
        if data.IsA("vtkMultiBlockDataSet"):
            data = data.GetBlock(0)
        at = f"{where} at t = {s['time']:g}"
        if data.GetNumberOfCells() != s["cells"]:
            problems.append(f"{at}: {data.GetNumberOfCells()} cells, the topology has {s['cells']}")
        b = data.GetBounds()
        lo, hi = s["nodes"].min(axis=0), s["nodes"].max(axis=0)
        span = float(np.max(hi - lo))
        if not all(close(g, w, span) for g, w in zip((b[0], b[1], b[2], b[3]), (lo[0], hi[0], lo[1], hi[1]))):
            problems.append(f"{at}: bounds x [{b[0]:g}, {b[1]:g}], y [{b[2]:g}, {b[3]:g}]; the nodes span "
                            f"x [{lo[0]:g}, {hi[0]:g}], y [{lo[1]:g}, {hi[1]:g}]")
        for name, values in s["arrays"].items():
            array = data.GetCellData().GetArray(name) or data.GetPointData().GetArray(name)
            if array is None:
                problems.append(f"{at}: no array '{name}'")
                continue
            values = values.reshape(array.GetNumberOfTuples(), -1) if values.size else values
            if values.size != array.GetNumberOfTuples() * array.GetNumberOfComponents():
                problems.append(f"{at}: '{name}' has {array.GetNumberOfTuples()} x "
                                f"{array.GetNumberOfComponents()} values, the dataset {values.size}")
                continue
            for c in range(array.GetNumberOfComponents()):
                got = array.GetRange(c)
                col = values[:, c]
                scale = float(np.max(np.abs(col))) if col.size else 0.0
                if not (close(got[0], col.min(), scale) and close(got[1], col.max(), scale)):
                    problems.append(f"{at}: '{name}' component {c} ranges [{got[0]:g}, {got[1]:g}], "
                                    f"the dataset [{col.min():g}, {col.max():g}]")
    simple.Delete(reader)


def render(files, image):
    """The last step: the structured grid's first array as colours, meshes and fibers over it."""
    view = simple.GetActiveViewOrCreate("RenderView")
    view.OrientationAxesVisibility = 0
    for path in files:
        reader = simple.XDMFReader(FileNames=[path])
        last = reader.TimestepValues[-1] if len(reader.TimestepValues) else 0.0
        view.ViewTime = last
        shown = simple.Show(reader, view)
        topo = ET.parse(path).getroot().find("Domain/Grid/Grid/Topology").get("TopologyType")
        cell_arrays = list(reader.CellData.keys())
        if topo in ("2DSMesh", "2DRectMesh") and cell_arrays:
            name = "vorticity" if "vorticity" in cell_arrays else cell_arrays[0]
            simple.ColorBy(shown, ("CELLS", name))
            shown.RescaleTransferFunctionToDataRange(True)
        else:
            simple.ColorBy(shown, ("POINTS", ""))
            shown.SetRepresentationType("Wireframe" if topo == "Triangle" else "Surface")
            shown.AmbientColor = shown.DiffuseColor = [0.1, 0.1, 0.1]
            shown.LineWidth = 2.0
    view.InteractionMode = "2D"
    simple.ResetCamera(view)
    simple.SaveScreenshot(image, view, ImageResolution=[800, 500])


# A drawn picture has the background, the field's colour map and the outlines: more than a few
# colours; a failed render leaves the background alone.
MIN_COLOURS = 8


def picture_colours(image):
    """The number of distinct colours in a PNG file (0 if it is missing)."""
    if not os.path.exists(image):
        return 0
    from vtkmodules.vtkIOImage import vtkPNGReader
    from vtkmodules.util.numpy_support import vtk_to_numpy
    r = vtkPNGReader()
    r.SetFileName(image)
    r.Update()
    pixels = vtk_to_numpy(r.GetOutput().GetPointData().GetScalars())
    return len(np.unique(pixels.reshape(len(pixels), -1), axis=0))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out_dir")
    ap.add_argument("--image", help="where to write the rendered picture (default OUT_DIR/paraview.png)")
    a = ap.parse_args()
    files = sorted(os.path.join(os.path.abspath(a.out_dir), f) for f in os.listdir(a.out_dir)
                   if f.endswith(".xdmf"))
    if not files:
        sys.exit(f"check_paraview: no .xdmf file in {a.out_dir}")
    problems = []
    # The picture first: rendering after the readers' checks fails under Xvfb (GLXBadContext).
    image = a.image or os.path.join(a.out_dir, "paraview.png")
    render(files, image)
    colours = picture_colours(image)
    if colours < MIN_COLOURS:
        problems.append(f"the picture {image} has {colours} colours: nothing was drawn")
    for path in files:
        steps = expected(path)
        for reader in READERS:
            check_reader(path, reader, steps, problems)
        print(f"check_paraview: {os.path.basename(path)}: {len(steps)} steps, {steps[-1]['cells']} cells, "
              f"arrays {', '.join(steps[-1]['arrays'])}")
    for p in problems:
        print("check_paraview: " + p)
    if problems:
        sys.exit(1)
    print(f"check_paraview: {len(files)} files read alike by {', '.join(READERS)}; picture {image}")


if __name__ == "__main__":
    main()
