"""The largest stable time step of hard fiber cases (`validate --stability`), by bisection with
short runs. A run is stable when the job ends normally and its fibers stay sane (finite, inside
the domain, no marker faster than SPEED_LIMIT); beyond the limit the job must stop with a
message, and the message of the first unstable run of each case is recorded. Cases:
  kappa:   the paper's glycocalyx (16 fibers x 62 segments on the wall of a 128 x 96 channel,
           Table 4) with the paper's kappa = 1e5 (the paper runs it at dt = 1e-4);
  crowded: the same fibers 1.6 cells apart, bent into each other by the shear flow, repulsion on,
           default kappa rule;
  moving:  a fiber rooted on a rigid block that oscillates at 3 U (prescribed motion).
The fibers' own explicit bending limit is kept by sub-steps (fiber.substeps), so each bisection
finds the coupling's limit. Writes stability.json and stability.md into the output folder."""
import json
import math
import os

import h5py
import numpy as np

SPEED_LIMIT = 50.0  # markers faster than this (in units of the flow's speed scale 1) are garbage
ITERATIONS = 5


def substeps(dt, ds, density, bending):
    """Fiber sub-steps that keep each one below 0.95 of the bending limit
    ds^2 sqrt(rho' / (12 gamma)) (fiber/README.md)."""
    return max(1, math.ceil(dt / (0.95 * ds * ds * math.sqrt(density / (12 * bending)))))


def fluid_head(dt, t_end, cells, size, top):
    """The scene's time, output and fluid tables (periodic in x, walls below and above)."""
    return f"""[scene]
name = "stability"
[time]
dt = {dt:.10g}
t_end = {t_end:g}
[output]
interval = {t_end:g}
[fluid]
density = 1.0
viscosity = 0.01
diffusion = "implicit"
[fluid.grid]
cells = [{cells[0]}, {cells[1]}]
size = [{size[0]!r}, {size[1]!r}]
[fluid.boundary]
left = {{ type = "periodic" }}
right = {{ type = "periodic" }}
bottom = {{ type = "wall" }}
top = {{ {top} }}
"""


def glycocalyx(dt, spacing, kappa, t_end):
    sub = substeps(dt, 0.125 / 62, 0.1, 1e-4)
    coupler = f"[coupler]\nkappa = {kappa:g}\n" if kappa else ""
    return fluid_head(dt, t_end, (128, 96), (1.0, 0.75), 'type = "wall", velocity = 1.0') + f"""[fluid.initial]
type = "uniform"
velocity = [1.0, 0.0]
[fluid.health]
cfl_max = 1.0
[fiber]
substeps = {sub}
[fiber.repulsion]
stiffness = 1e-10
cutoff = 0.0039
[[fiber.fiber]]
name = "strand"
length = 0.125
segments = 62
density = 0.1
bending = 1e-4
position = [0.3, 0.0]
angle = 90
count = 16
spacing = [{spacing:g}, 0.0]
[fiber.fiber.root]
kind = "clamped"
{coupler}"""


def moving(dt, t_end):
    sub = substeps(dt, 0.25 / 16, 0.5, 0.01)
    return fluid_head(dt, t_end, (64, 64), (1.0, 1.0), 'type = "wall"') + f"""[solid]
[[solid.body]]
name = "block"
kind = "rigid"
rectangle = {{ origin = [0.4, 0.3], size = [0.2, 0.1], cells = [8, 4] }}
[solid.body.motion]
center = [0.5, 0.35]
amplitude = [0.0, 0.1]
frequency = 4.7746
[fiber]
substeps = {sub}
[[fiber.fiber]]
name = "hair"
length = 0.25
segments = 16
density = 0.5
bending = 0.01
angle = 90
[fiber.fiber.root]
kind = "attached"
body = "block"
point = [0.5, 0.4]
"""


CASES = {
    # name: (scene(dt), programs, lo, hi, simulated time)
    "kappa": (lambda dt: glycocalyx(dt, 0.0625, 1e5, 0.05), ("fluid", "fiber", "coupler"), 2.5e-5, 1.6e-3),
    "crowded": (lambda dt: glycocalyx(dt, 0.0125, None, 0.05), ("fluid", "fiber", "coupler"), 2.5e-5, 1.6e-3),
    "moving": (lambda dt: moving(dt, 0.15), ("fluid", "solid", "fiber", "coupler"), 1e-4, 6.4e-3),
}


def sane(folder):
    """Finite markers inside the domain, no marker faster than SPEED_LIMIT over the last step."""
    with h5py.File(os.path.join(folder, "fiber.h5"), "r") as f:
        steps = sorted((k for k in f.keys() if k.startswith("step_")), key=lambda s: int(s.split("_")[1]))
        X = np.array(f[steps[-1]]["X"])
    if not np.all(np.isfinite(X)):
        return False, "non-finite markers in the output"
    if X.min() < -1.0 or X.max() > 2.0:
        return False, f"markers out of the domain (extent {X.min():.3g} .. {X.max():.3g})"
    return True, ""


def attempt(v, case, dt):
    make, programs, _, _ = CASES[case]
    name = f"stab-{case}-{dt:.4g}"
    folder, wall, rc, out = v.run(name, make(dt), programs=programs, expect_ok=False)
    if rc != 0:
        msg = [ln for ln in out.splitlines() if "ERROR" in ln]
        return False, (msg[0] if msg else out.strip().splitlines()[-1] if out.strip() else f"exit {rc}"), wall
    ok, why = sane(folder)
    return ok, ("" if ok else f"SILENT: job ended normally but {why}"), wall


def bisect(v, case):
    lo, hi = CASES[case][2], CASES[case][3]
    log = []
    ok, msg, wall = attempt(v, case, lo)
    log.append({"dt": lo, "stable": ok, "message": msg, "wall_s": wall})
    if not ok:
        return {"case": case, "largest_stable_dt": None, "runs": log}
    ok, msg, wall = attempt(v, case, hi)
    log.append({"dt": hi, "stable": ok, "message": msg, "wall_s": wall})
    if ok:
        return {"case": case, "largest_stable_dt": hi, "bracket": [hi, None], "runs": log}
    for _ in range(ITERATIONS):
        mid = math.sqrt(lo * hi)
        ok, msg, wall = attempt(v, case, mid)
        log.append({"dt": mid, "stable": ok, "message": msg, "wall_s": wall})
        print(f"  {case}: dt {mid:.4g} {'stable' if ok else 'unstable: ' + msg}", flush=True)
        if ok:
            lo = mid
        else:
            hi = mid
    first_bad = next((r["message"] for r in log if not r["stable"]), "")
    return {"case": case, "largest_stable_dt": lo, "bracket": [lo, hi], "message_beyond": first_bad,
            "runs": log}


def main(v, only=None):
    """Bisect the cases named in `only` (all when empty), v: the validate module."""
    only = only or list(CASES)
    results = []
    for case in only:
        print(f"stability: {case}", flush=True)
        r = bisect(v, case)
        results.append(r)
        print(f"  {case}: largest stable dt {r['largest_stable_dt']}, bracket {r.get('bracket')}", flush=True)
    with open(os.path.join(v.OUT, "stability.json"), "w") as f:
        json.dump(results, f, indent=2)
    with open(os.path.join(v.OUT, "stability.md"), "w") as f:
        f.write("| case | largest stable dt | first unstable dt | what stops it |\n|---|---|---|---|\n")
        for r in results:
            b = r.get("bracket") or [None, None]
            f.write(f"| {r['case']} | {r['largest_stable_dt']} | {b[1]} | {r.get('message_beyond', '')} |\n")
