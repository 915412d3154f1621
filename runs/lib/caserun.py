"""What every validation case shares: run one of the programs on a scene written into the case's
output folder, and record metrics as {value, reference, error, tolerance, pass} in summary.json.
Environment (set by `./fsi validate`): FSI_ROOT, FSI_BIN, FSI_OUT; `--short` on the command line
selects a case's short version."""
import json
import os
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.environ.get("FSI_ROOT", os.path.abspath(os.path.join(HERE, "..", "..")))
BIN = os.environ.get("FSI_BIN", os.path.join(ROOT, "build", "bin"))
OUT = os.environ.get("FSI_OUT", os.path.join(os.getcwd(), "out"))
SHORT = "--short" in sys.argv

# Coupled iterations for the layer cases (two-layer channel, equal densities, wavy channel;
# coupler/README.md). relaxation: the first iteration of a step (before IQN-ILS has columns) must
# not overshoot the slowest mode, amplified about 1/(omega_1 dt)^2 ~ 1e4-1e5 times at
# rho_s = rho_f (runs/equal-density/README.md); with 0.5 the 32-cell channel diverged in its
# first steps. reuse: the map changes little from step to step.
COUPLED_ITERATIONS = """[coupler]
[coupler.iterations]
max = 30
tolerance = 1e-6
acceleration = "iqn-ils"
relaxation = 1e-4
reuse = 20
"""


def iterations_per_step(folder):
    """Mean coupled iterations per step of a run (its coupler_iterations.csv), None when the run
    had no coupled iterations."""
    path = os.path.join(folder, "coupler_iterations.csv")
    if not os.path.exists(path):
        return None
    return float(np.mean(np.genfromtxt(path, delimiter=",", names=True)["iterations"]))


def run_program(program, name, scene_text, expect_error=False):
    """Write OUT/name.toml, run `program` on it into OUT/name; return (folder, wall seconds).
    With expect_error, require a failure and return the program's output instead."""
    os.makedirs(OUT, exist_ok=True)
    scene = os.path.join(OUT, name + ".toml")
    with open(scene, "w") as f:
        f.write(scene_text)
    folder = os.path.join(OUT, name)
    t0 = time.time()
    r = subprocess.run([os.path.join(BIN, program), scene, "--out-dir", folder, "--overwrite"],
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    wall = time.time() - t0
    if expect_error:
        if r.returncode == 0:
            raise RuntimeError(f"{program} should have failed on {scene}")
        return r.stdout
    if r.returncode != 0:
        sys.stderr.write(r.stdout)
        raise RuntimeError(f"{program} failed on {scene}")
    return folder, wall


def metric(value, reference, error, tolerance):
    ok = bool(np.isfinite(value) and np.isfinite(error) and error <= tolerance)
    return {"value": float(value), "reference": float(reference), "error": float(error),
            "tolerance": float(tolerance), "pass": ok}


def relative(value, reference, tolerance):
    return metric(value, reference, abs(value - reference) / abs(reference), tolerance)


def finish(case, metrics, extra=None):
    """Write OUT/summary.json; exit 1 when a metric fails."""
    s = {"case": case, "short": SHORT, "metrics": metrics}
    if extra:
        s.update(extra)
    with open(os.path.join(OUT, "summary.json"), "w") as f:
        json.dump(s, f, indent=2)
    bad = [k for k, m in metrics.items() if not m["pass"]]
    for k, m in metrics.items():
        print(f"  {k}: {m['value']:.6g} (reference {m['reference']:.6g}, error {m['error']:.3g}, "
              f"tolerance {m['tolerance']:.3g}) {'pass' if m['pass'] else 'FAIL'}")
    if bad:
        print(f"{case}: failed: {', '.join(bad)}")
        sys.exit(1)
    print(f"{case}: all {len(metrics)} metrics pass")


def run_coupled(work, name, scene_text, roles=("fluid", "solid", "coupler")):
    """Write work/name.toml and run the roles as one MPMD job into work/name (FSI_MPIRUN,
    default mpirun); return (folder, wall seconds). A failed job stops the case."""
    os.makedirs(work, exist_ok=True)
    path = os.path.join(work, f"{name}.toml")
    with open(path, "w") as f:
        f.write(scene_text)
    folder = os.path.join(work, name)
    cmd = [os.environ.get("FSI_MPIRUN", "mpirun"), "--oversubscribe"]
    if os.geteuid() == 0:
        cmd.append("--allow-run-as-root")
    for k, prog in enumerate(roles):
        if k:
            cmd.append(":")
        cmd += ["-n", "1", os.path.join(BIN, prog), path, "--out-dir", folder, "--overwrite"]
    t0 = time.time()
    r = subprocess.run(cmd, cwd=work, capture_output=True, text=True)
    if r.returncode != 0:
        sys.stderr.write(r.stdout[-2000:] + r.stderr[-4000:])
        raise SystemExit(f"{name}: the coupled run failed (exit {r.returncode})")
    return folder, time.time() - t0
