#!/usr/bin/python3
"""The solid's energy balance in a run's solid_history.csv (solid/README.md): every row's
kinetic + strain + load potential, less the first row's, equals the work of the coupling forces
and of contact since then, to TOL of the largest work of KIND (coupling or contact), and that
work is not zero (the check reads a run whose bodies the fluid moves, or that touch).

usage: check_energy_balance.py RUN_DIR [--tolerance TOL] [--work coupling|contact]"""
import argparse
import csv
import os
import sys

p = argparse.ArgumentParser()
p.add_argument("run")
p.add_argument("--tolerance", type=float, default=1e-2)
p.add_argument("--work", choices=("coupling", "contact"), default="coupling")
a = p.parse_args()
path = os.path.join(a.run, "solid_history.csv")
with open(path) as f:
    rows = list(csv.DictReader(f))
if not rows:
    sys.exit(f"{path}: no rows")
for k in ("total_energy", "coupling_work", "contact_work"):
    if k not in rows[0]:
        sys.exit(f"{path}: no column {k}")
work = max(abs(float(r[a.work + "_work"])) for r in rows)
if not work > 0:
    sys.exit(f"{path}: {a.work} did no work")
def balance(r):
    return float(r["total_energy"]) - float(r["coupling_work"]) - float(r["contact_work"])


worst = max(abs(balance(r) - balance(rows[0])) for r in rows)
print(f"{path}: largest |energy - work| {worst:.3g} against the largest {a.work} work {work:.3g}"
      f" (ratio {worst / work:.2e}, tolerance {a.tolerance:g})")
sys.exit(0 if worst <= a.tolerance * work else 1)
