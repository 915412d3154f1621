#!/usr/bin/python3
"""Run one command (usually an mpirun MPMD job) as a test and check its outcome.

  run_job.py [--expect-fail] [--regex R]... [--absent R]... [--within S] [--timeout S]
             [--cwd DIR] [--file-exists F]... [--csv-max-abs F:C:L]... [--post CMD]...
             -- COMMAND...

Passes when the exit code is 0 (or non-zero with --expect-fail), every --regex matches the
combined stdout+stderr, no --absent pattern matches, the job ended within --within seconds,
every --file-exists path exists afterwards, and for every --csv-max-abs FILE:COLUMN_REGEX:LIMIT
the largest |value| of the matching columns of that CSV (header line, then numbers) is at most
LIMIT, and every --post command (a command line, run in --cwd after the job) exits 0. The
output is printed in any case.
"""
import argparse
import os
import re
import shlex
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
    p.add_argument("--csv-max-abs", action="append", default=[])
    p.add_argument("--post", action="append", default=[])
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
    for spec in a.csv_max_abs:
        fname, col_rx, limit = spec.rsplit(":", 2)
        path = os.path.join(a.cwd or ".", fname)
        if not os.path.exists(path):
            problems.append(f"missing CSV file {path}")
            continue
        with open(path) as f:
            header = f.readline().strip().split(",")
            cols = [k for k, h in enumerate(header) if re.fullmatch(col_rx, h)]
            if not cols:
                problems.append(f"no column of {path} matches /{col_rx}/")
                continue
            worst, rows = 0.0, 0
            for line in f:
                vals = line.strip().split(",")
                worst = max([worst] + [abs(float(vals[k])) for k in cols])
                rows += 1
        print(f"{fname}: max |{col_rx}| = {worst:.3e} over {rows} rows (limit {limit})")
        if rows == 0 or not worst <= float(limit):
            problems.append(f"{fname}: max |{col_rx}| = {worst:.3e} over {rows} rows, limit {limit}")
    for post in a.post:
        r = subprocess.run(shlex.split(post), cwd=a.cwd, stdout=subprocess.PIPE,
                           stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL)
        print(r.stdout.decode(errors="replace"))
        if r.returncode != 0:
            problems.append(f"post-check failed (exit {r.returncode}): {post}")
    for pr in problems:
        print("FAIL:", pr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
