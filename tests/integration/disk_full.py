#!/usr/bin/python3
"""Disk full mid-run: the fluid writes fields every step into a 2 MB tmpfs (mounted here; the
test is skipped, exit 77, when it cannot mount). The run must stop with "no space left on
device" naming the file, exit non-zero, and leave every step group of fluid.h5 readable.

  disk_full.py --work DIR --scene disk_full.toml --fluid FLUID -- MPIEXEC...
"""
import argparse
import os
import subprocess
import sys

import h5py


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--work", required=True)
    p.add_argument("--scene", required=True)
    p.add_argument("--fluid", required=True)
    p.add_argument("mpiexec", nargs=argparse.REMAINDER)
    a = p.parse_args()
    mpiexec = a.mpiexec[1:] if a.mpiexec and a.mpiexec[0] == "--" else a.mpiexec
    mnt = os.path.join(a.work, "tmpfs")
    os.makedirs(mnt, exist_ok=True)
    subprocess.run(["umount", mnt], stderr=subprocess.DEVNULL)
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=2m", "tmpfs", mnt]).returncode != 0:
        print("SKIP: cannot mount a tmpfs (not root?)")
        return 77
    problems = []
    try:
        out = os.path.join(mnt, "out")
        r = subprocess.run(mpiexec + ["-n", "1", a.fluid, a.scene, "--out-dir", out],
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=100)
        text = r.stdout.decode(errors="replace")
        print(text)
        if r.returncode == 0:
            problems.append("exit code 0 on a full disk")
        if "no space left on device: writing" not in text or f"{out}/fluid.h5" not in text:
            problems.append("no 'no space left on device' naming fluid.h5")
        with h5py.File(os.path.join(out, "fluid.h5"), "r") as h:
            groups = [k for k in h if k.startswith("step_")]
            for g in groups:
                for d in h[g]:
                    h[g][d][()]
            print(f"{len(groups)} step groups, all readable")
            if len(groups) < 2:
                problems.append(f"only {len(groups)} step groups written")
    except Exception as e:
        problems.append(f"reading the output: {e}")
    finally:
        subprocess.run(["umount", mnt])
    for pr in problems:
        print("FAIL:", pr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
