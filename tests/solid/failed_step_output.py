#!/usr/bin/python3
"""A stopped run's last two outputs: the state the failed step started from (t^n, the last
converged one) and the failed attempt's last iterate (stored at t^n + dt). The first must be the
state a run ending at t^n writes, bit for bit.

usage: failed_step_output.py SOLID SCENE WORKDIR
"""
import os
import subprocess
import sys

import h5py
import numpy as np

solid, scene, work = sys.argv[1:4]
os.makedirs(work, exist_ok=True)
failed = subprocess.run([solid, scene, "--out-dir", os.path.join(work, "failed"), "--overwrite"],
                        capture_output=True, text=True)
assert failed.returncode != 0, "the run was to stop at step 6"
assert "[solid] ERROR: Newton did not converge in 3 iterations at step 6" in failed.stderr, failed.stderr
assert "the state the failed step started from (t = 0.05)" in failed.stderr, failed.stderr
# The same scene ending at t = 0.05, which converges every step.
with open(scene) as f:
    text = f.read().replace("t_end = 0.1\n", "t_end = 0.05\n")
short_scene = os.path.join(work, "short.toml")
with open(short_scene, "w") as f:
    f.write(text)
short = subprocess.run([solid, short_scene, "--out-dir", os.path.join(work, "short"), "--overwrite"],
                       capture_output=True, text=True)
assert short.returncode == 0, short.stderr
with h5py.File(os.path.join(work, "failed", "solid.h5"), "r") as a, \
        h5py.File(os.path.join(work, "short", "solid.h5"), "r") as b:
    steps = sorted(k for k in a if k.startswith("step_"))
    assert steps[-2:] == ["step_000005", "step_000006"], steps
    assert a["step_000005"].attrs["time"] == 0.05 and abs(a["step_000006"].attrs["time"] - 0.06) < 1e-15
    for q in ("position", "velocity", "displacement", "det_f"):
        x, y = a[f"step_000005/body_beam/{q}"][()], b[f"step_000005/body_beam/{q}"][()]
        assert np.array_equal(x, y), f"{q} at t = 0.05 differs from the run ending there"
    moved = np.abs(a["step_000006/body_beam/position"][()] - a["step_000005/body_beam/position"][()]).max()
    assert moved > 0, "the failed iterate is the converged state"
print("the stopped run's last converged state is the short run's, bit for bit; the failed iterate "
      f"moved {moved:.3e} from it")
