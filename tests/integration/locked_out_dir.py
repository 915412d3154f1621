#!/usr/bin/python3
"""A second run pointed at the output folder of a live run is refused, naming the folder and the
run that holds it (its PID), with and without --overwrite; the first run's files are left alone.

  locked_out_dir.py --work DIR --scene NO_BODIES.toml --null NULL_SOLVER --coupler COUPLER -- MPIEXEC...
"""
import argparse
import os
import re
import shutil
import signal
import subprocess
import sys
import time


def job(a, scene, out, extra):
    cmd = list(a.mpiexec)
    for k, role in enumerate(["fluid", "solid", "fiber", "coupler"]):
        if k:
            cmd.append(":")
        prog = [a.coupler] if role == "coupler" else [a.null, role]
        cmd += ["-n", "1"] + prog + [scene, "--out-dir", out] + extra
    return cmd


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--work", required=True)
    p.add_argument("--scene", required=True)
    p.add_argument("--null", required=True)
    p.add_argument("--coupler", required=True)
    p.add_argument("mpiexec", nargs=argparse.REMAINDER)
    a = p.parse_args()
    a.mpiexec = a.mpiexec[1:] if a.mpiexec and a.mpiexec[0] == "--" else a.mpiexec
    os.makedirs(a.work, exist_ok=True)
    out = os.path.join(a.work, "shared")
    shutil.rmtree(out, ignore_errors=True)
    hold = os.path.join(os.path.dirname(a.scene), "job_hold.toml")
    problems = []
    first = subprocess.Popen(job(a, hold, out, ["--overwrite"]), stdout=subprocess.PIPE,
                             stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, start_new_session=True)
    lock = os.path.join(out, ".lock")
    t0 = time.monotonic()
    while not (os.path.exists(lock) and open(lock).read().strip()):
        if time.monotonic() - t0 > 30 or first.poll() is not None:
            print(first.communicate()[0].decode())
            print("FAIL: the first run never took its folder's lock")
            return 1
        time.sleep(0.05)
    holder = open(lock).read().strip()
    print(f"lock: {holder}")
    pid = re.match(r"pid (\d+)", holder).group(1)
    time.sleep(0.5)
    for extra in ([], ["--overwrite"]):
        r = subprocess.run(job(a, a.scene, out, extra), stdout=subprocess.PIPE,
                           stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, timeout=30)
        text = r.stdout.decode(errors="replace")
        print(text)
        want = (f"ERROR: output folder '{out}' is in use by another run that is still running "
                f"(pid {pid} on ")
        if r.returncode == 0:
            problems.append(f"second run {extra} exited 0")
        if want not in text:
            problems.append(f"second run {extra}: no line with: {want}")
    if first.poll() is not None:
        problems.append("the first run ended while the second was refused")
    if not os.path.exists(os.path.join(out, "scene.effective.toml")) and not os.listdir(out):
        problems.append("the first run's folder was emptied")
    os.killpg(first.pid, signal.SIGTERM)
    first.communicate(timeout=30)
    # A lock left by a dead run is taken over: the same folder, now free, is accepted.
    r = subprocess.run(job(a, a.scene, out, ["--overwrite"]), stdout=subprocess.PIPE,
                       stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, timeout=30)
    text = r.stdout.decode(errors="replace")
    print(text)
    if r.returncode != 0:
        problems.append(f"a run in the folder of the ended run exited {r.returncode}")
    for pr in problems:
        print("FAIL:", pr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
