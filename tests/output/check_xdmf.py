"""Independent check of an XDMF side file: well-formed XML (ElementTree), a temporal collection,
and every HDF5 DataItem pointing at an existing dataset of the declared shape (h5py).
Usage: check_xdmf.py FILE.xdmf [EXPECTED_STEPS]; prints problems and exits 1 if any."""
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import h5py


def main():
    path = Path(sys.argv[1])
    root = ET.parse(path).getroot()
    problems = []
    collection = root.find("Domain/Grid")
    if root.tag != "Xdmf" or collection is None or collection.get("CollectionType") != "Temporal":
        problems.append("not an Xdmf temporal collection")
    steps = collection.findall("Grid") if collection is not None else []
    times = [float(g.find("Time").get("Value")) for g in steps]
    if times != sorted(times):
        problems.append(f"times not increasing: {times}")
    if len(sys.argv) > 2 and len(steps) != int(sys.argv[2]):
        problems.append(f"{len(steps)} steps, expected {sys.argv[2]}")
    for item in root.iter("DataItem"):
        file_name, dataset = item.text.strip().split(":", 1)
        dims = tuple(int(d) for d in item.get("Dimensions").split())
        with h5py.File(path.parent / file_name, "r") as h5:
            if dataset not in h5:
                problems.append(f"{item.text}: missing")
            elif h5[dataset].shape != dims:
                problems.append(f"{item.text}: shape {h5[dataset].shape} != {dims}")
    for p in problems:
        print(p)
    sys.exit(1 if problems else 0)


main()
