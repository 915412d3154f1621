#!/usr/bin/python3
"""Run one command (usually an mpirun MPMD job) as a test and check its outcome.

  run_job.py [--expect-fail] [--regex R]... [--absent R]... [--within S] [--timeout S]
             [--cwd DIR] [--file-exists F]... -- COMMAND...

Passes when the exit code is 0 (or non-zero with --expect-fail), every --regex matches the
combined stdout+stderr, no --absent pattern matches, the job ended within --within seconds, and
every --file-exists path exists afterwards. The output is printed in any case.
"""
import argparse
import os
import re
import subprocess
import sys
import time


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--expect-fail", action="store_true")
    p.add_argument("--regex", action="append", default=[])
    p.add_argument("--absent", action="append", default=[])
    p.add_argument("--within", type=float, default=None)
    p.add_argument("--timeout", type=float, default=120)
    p.add_argument("--cwd", default=None)
    p.add_argument("--file-exists", action="append", default=[])
    p.add_argument("command", nargs=argparse.REMAINDER)
    a = p.parse_args()
    cmd = a.command[1:] if a.command and a.command[0] == "--" else a.command
    if a.cwd:
        os.makedirs(a.cwd, exist_ok=True)
    t0 = time.monotonic()
    try:
        r = subprocess.run(cmd, cwd=a.cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                           timeout=a.timeout, stdin=subprocess.DEVNULL)
        out, code = r.stdout.decode(errors="replace"), r.returncode
    except subprocess.TimeoutExpired as e:
        out = (e.stdout or b"").decode(errors="replace")
        print(out)
        print(f"FAIL: no exit within {a.timeout} s: {' '.join(cmd)}")
        return 1
    elapsed = time.monotonic() - t0
    print(out)
    print(f"exit code {code} after {elapsed:.2f} s")
    problems = []
    if a.expect_fail and code == 0:
        problems.append("expected a non-zero exit code, got 0")
    if not a.expect_fail and code != 0:
        problems.append(f"expected exit code 0, got {code}")
    for rx in a.regex:
        if not re.search(rx, out, re.MULTILINE):
            problems.append(f"output does not match /{rx}/")
    for rx in a.absent:
        if re.search(rx, out, re.MULTILINE):
            problems.append(f"output matches /{rx}/, which must not appear")
    if a.within is not None and elapsed > a.within:
        problems.append(f"took {elapsed:.2f} s, more than {a.within} s")
    for f in a.file_exists:
        path = os.path.join(a.cwd or ".", f)
        if not os.path.exists(path):
            problems.append(f"missing output file {path}")
    for pr in problems:
        print("FAIL:", pr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
