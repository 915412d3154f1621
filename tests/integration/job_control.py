#!/usr/bin/python3
"""Job control of the launcher `./fsi run`, measured.

  job_control.py --fsi ./fsi --scenes DIR --work DIR CHECK...

CHECK is one of:
  term, int, kill  start `./fsi run job_long.toml`, wait until its four programs run, send the
                   launcher (only the launcher, not its process group) SIGTERM, SIGINT or SIGKILL
                   and measure the time until mpirun and every program are gone (at most 10 s);
                   the launcher's exit code must be 128 + the signal's number (TERM, INT)
  twice            two launches of job_short.toml at once: both exit 0 in two output folders,
                   each holding one complete run
  fault            a launch whose solid fails: non-zero exit, the launcher names the solid, and
                   none of Open MPI's "ORTE_ERROR_LOG" lines appear
The processes of a launch are found by the FSI_LAUNCHER_PID in their environment.
"""
import argparse
import os
import re
import signal
import subprocess
import sys
import time

LIMIT = 10.0  # seconds from the signal to the last process gone


def job_pids(launcher_pid):
    """PIDs of processes whose environment has FSI_LAUNCHER_PID=launcher_pid (mpirun, programs)."""
    key = f"FSI_LAUNCHER_PID={launcher_pid}".encode()
    found = []
    for d in os.listdir("/proc"):
        if not d.isdigit():
            continue
        try:
            with open(f"/proc/{d}/environ", "rb") as f:
                env = f.read().split(b"\0")
            with open(f"/proc/{d}/stat") as f:
                state = f.read().rsplit(")", 1)[1].split()[0]
        except OSError:
            continue
        if key in env and state not in ("Z", "X"):
            found.append(int(d))
    return found


def names(pids):
    out = []
    for p in pids:
        try:
            with open(f"/proc/{p}/comm") as f:
                out.append(f"{f.read().strip()}({p})")
        except OSError:
            pass
    return out


def launch(a, scene, log):
    env = dict(os.environ, FSI_OUT_ROOT=os.path.join(a.work, "out"))
    return subprocess.Popen([a.fsi, "run", os.path.join(a.scenes, scene), "--overwrite"]
                            if scene == "job_long.toml" else [a.fsi, "run", os.path.join(a.scenes, scene)],
                            stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, env=env,
                            start_new_session=True)


def check_signal(a, sig):
    logname = os.path.join(a.work, f"{sig.name}.log")
    with open(logname, "w") as log:
        p = launch(a, "job_long.toml", log)
        t0 = time.monotonic()
        while len([n for n in names(job_pids(p.pid)) if not n.startswith("mpirun")]) < 4:
            if time.monotonic() - t0 > 120 or p.poll() is not None:
                print(open(logname).read())
                return [f"{sig.name}: the job's four programs never ran"]
            time.sleep(0.1)
        time.sleep(1.0)  # into the stepping
        before = names(job_pids(p.pid))
        t0 = time.monotonic()
        os.kill(p.pid, sig)
        gone = None
        while time.monotonic() - t0 < 30:
            if not job_pids(p.pid):
                gone = time.monotonic() - t0
                break
            time.sleep(0.05)
        try:
            code = p.wait(timeout=30)
        except subprocess.TimeoutExpired:
            p.kill()
            code = p.wait()
    print(open(logname).read())
    problems = []
    print(f"{sig.name}: processes before: {' '.join(before)}")
    if gone is None:
        left = names(job_pids(p.pid))
        for q in job_pids(p.pid):
            os.kill(q, signal.SIGKILL)
        return [f"{sig.name}: processes still running 30 s after the signal: {' '.join(left)}"]
    print(f"{sig.name}: launcher signalled -> last process gone in {gone:.2f} s; launcher exit code {code}")
    if gone > LIMIT:
        problems.append(f"{sig.name}: the job took {gone:.2f} s to end, more than {LIMIT} s")
    if sig != signal.SIGKILL and code != 128 + sig:
        problems.append(f"{sig.name}: launcher exit code {code}, expected {128 + sig}")
    return problems


def check_twice(a):
    logs = [os.path.join(a.work, f"twice_{k}.log") for k in (1, 2)]
    files = [open(n, "w") for n in logs]
    procs = [launch(a, "job_short.toml", f) for f in files]
    codes = [p.wait(timeout=200) for p in procs]
    for f in files:
        f.close()
    problems = []
    folders = []
    for n, c in zip(logs, codes):
        text = open(n).read()
        print(text)
        if c != 0:
            problems.append(f"twice: a launch exited {c}")
        for line in text.splitlines():
            if line.startswith("[fsi] output in "):
                folders.append(line.split("output in ", 1)[1].strip())
    print(f"twice: exit codes {codes}, folders {folders}")
    if len(folders) != 2 or folders[0] == folders[1]:
        problems.append(f"twice: expected two different output folders, got {folders}")
    for d in folders:
        d = d.rstrip("/")
        path = d if os.path.isabs(d) else os.path.join(os.path.dirname(os.path.abspath(a.fsi)), d)
        if not os.path.exists(os.path.join(path, "summary.json")):
            problems.append(f"twice: no summary.json in {path}")
    return problems


def check_fault(a):
    logname = os.path.join(a.work, "fault.log")
    with open(logname, "w") as log:
        p = launch(a, "job_fault.toml", log)
        code = p.wait(timeout=100)
    text = open(logname).read()
    print(text)
    problems = []
    if code == 0:
        problems.append("fault: the launcher exited 0")
    # The solid fails first; a peer may report its own end after it (the launcher names each).
    named = re.search(r"the error came from: (.*)", text)
    if not named or "solid" not in named.group(1).split(", "):
        problems.append("fault: the launcher does not name the solid program")
    if "ORTE_ERROR_LOG" in text:
        problems.append("fault: Open MPI's ORTE_ERROR_LOG lines appear")
    if "[solid] ERROR: test fault injected at step 3" not in text:
        problems.append("fault: the solid's own error line is missing")
    return problems


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--fsi", required=True)
    p.add_argument("--scenes", required=True)
    p.add_argument("--work", required=True)
    p.add_argument("checks", nargs="+")
    a = p.parse_args()
    os.makedirs(a.work, exist_ok=True)
    problems = []
    for c in a.checks:
        if c in ("term", "int", "kill"):
            problems += check_signal(a, {"term": signal.SIGTERM, "int": signal.SIGINT,
                                         "kill": signal.SIGKILL}[c])
        elif c == "twice":
            problems += check_twice(a)
        elif c == "fault":
            problems += check_fault(a)
        else:
            problems.append(f"unknown check {c}")
    for pr in problems:
        print("FAIL:", pr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
