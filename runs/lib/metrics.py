"""A case's metrics, each {value, reference, error, tolerance, pass}: pass is error <= tolerance,
None for a number that is reported and not judged (tolerance None). finish() writes them with the
wall and CPU time of the case's jobs (job.RUNS) to summary.json and sets the exit code: 1 when a
judged metric fails."""
import json
import math
import os
import sys

import job


def _finite(x):
    return x is not None and math.isfinite(x)


def metric(value, reference, error, tolerance):
    """A judged metric (tolerance a number) or a reported one (tolerance None)."""
    ok = None if tolerance is None else bool(_finite(value) and _finite(error) and error <= tolerance)
    return {"value": None if value is None else float(value),
            "reference": None if reference is None else float(reference),
            "error": None if error is None else float(error),
            "tolerance": None if tolerance is None else float(tolerance), "pass": ok}


def relative(value, reference, tolerance):
    """|value - reference| / |reference| against tolerance."""
    return metric(value, reference, abs(value - reference) / abs(reference), tolerance)


def at_most(value, tolerance, reference=0.0):
    """|value - reference| against tolerance (an absolute error)."""
    return metric(value, reference, abs(value - reference), tolerance)


def at_least(value, bound):
    """value >= bound: the error is the shortfall, tolerance 0."""
    return metric(value, bound, max(0.0, bound - value), 0.0)


def holds(condition, value=None):
    """A condition that must hold: value 1/0 (or the given one), error 0 or 1, tolerance 0."""
    v = float(bool(condition)) if value is None else value
    return metric(v, 1.0 if value is None else value, 0.0 if condition else 1.0, 0.0)


def reported(value, reference=None):
    """A number worth recording that is not judged."""
    err = abs(value - reference) if _finite(reference) and _finite(value) else None
    return metric(value, reference, err, None)


def run_entry(error, grid, dt, quantity, reference=None):
    """One run of a grid or time-step sequence for the report (runs/report.py): the error of
    `quantity` (against `reference`, a value) on `grid` (text, e.g. "64x64") with time step dt
    (None: static), and the wall and CPU time of the case's last job (job.RUNS[-1]; CPU None for a reused run)."""
    r = job.RUNS[-1] if job.RUNS else {}
    return {"run": r.get("name"), "quantity": quantity, "grid": str(grid),
            "dt": None if dt is None else float(dt),
            "error": float(error), "reference": None if reference is None else float(reference),
            "wall_s": r.get("wall_s"), "cpu_s": r.get("cpu_s")}


def _fmt(x, spec=".6g"):
    return "-" if x is None else format(x, spec)


def finish(case, metrics, extra=None, short=False, name="summary.json", per_run=None,
           reference=None, copies=()):
    """Write job.OUT/name (metrics, extra, the jobs' wall and CPU time), and the same to each
    path of copies; print each metric; exit 1 when a judged metric fails. per_run: run_entry()
    of each run of a grid or time-step sequence; reference: where the reference values come
    from (text)."""
    runs = job.RUNS
    cpu = [r["cpu_s"] for r in runs if r.get("cpu_s") is not None]
    bad = [k for k, m in metrics.items() if m["pass"] is False]
    s = {"case": case, "short": short, "pass": not bad, "metrics": metrics,
         "wall_s": sum(r["wall_s"] for r in runs), "cpu_s": sum(cpu) if cpu else None,
         "jobs": runs}
    if per_run is not None:
        s["per_run"] = per_run
    if reference is not None:
        s["reference_source"] = reference
    s.update(extra or {})
    path = os.path.join(job.OUT, name)
    for p in [path, *copies]:
        with open(p, "w") as f:
            json.dump(s, f, indent=2)
    for k, m in metrics.items():
        verdict = {True: "pass", False: "FAIL", None: "reported"}[m["pass"]]
        print(f"  {k}: {_fmt(m['value'])} (reference {_fmt(m['reference'])}, error "
              f"{_fmt(m['error'], '.3g')}, tolerance {_fmt(m['tolerance'], '.3g')}) {verdict}")
    print(f"{case}: {len(runs)} job(s), wall {s['wall_s']:.1f} s, CPU "
          f"{_fmt(s['cpu_s'], '.1f')} s; summary in {path}" +
          "".join(f" and {p}" for p in copies))
    if bad:
        print(f"{case}: failed: {', '.join(bad)}")
        sys.exit(1)
    judged = sum(m["pass"] is not None for m in metrics.values())
    print(f"{case}: all {judged} judged metrics pass")
