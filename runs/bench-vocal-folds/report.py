#!/usr/bin/python3
"""Where a coupled step of the vocal folds goes (`./fsi bench vocal-folds`): from the run's
summary.json, the coupler's phases per step (footprint, the fluid's and the solid's round trips,
reaction), each solver's own work (its time from input to answer, `port_seconds`, and its work
ahead of its input) and the messages (a round trip beyond the solver's port time); the solid's
phases (assembly, factorisation, solve) and its Newton iterations. Usage: report.py SUMMARY OUT."""
import json
import sys

s = json.load(open(sys.argv[1]))
n = s["steps"]
ms = lambda seconds: seconds / n * 1e3  # noqa: E731
c = {k: v["seconds_per_call"] * 1e3 for k, v in s["coupler"]["phases"].items()}
fl, so = s["fluid"], s["solid"]
rows = {
    "whole step": s["coupler"]["us_per_step"] / 1e3,
    "footprint (coupler)": c.get("footprint", 0.0),
    "reaction (coupler)": c.get("reaction", 0.0),
    "fluid round trip": c["fluid"],
    "  fluid work on its input": ms(fl["port_seconds"]),
    "  fluid work ahead of its input": ms(fl.get("ahead_seconds", 0.0)),
    "  messages to and from the fluid": c["fluid"] - ms(fl["port_seconds"]),
    "solid round trip": c["solid"],
    "  solid work on its input": ms(so["port_seconds"]),
    "  solid work ahead of its input": ms(so.get("ahead_seconds", 0.0)),
    "  messages to and from the solid": c["solid"] - ms(so["port_seconds"]),
}
for k, v in fl["phases"].items():
    rows[f"fluid phase {k}"] = ms(v)
for k, v in so["phases"].items():
    rows[f"solid phase {k}"] = ms(v)
r = {"steps": n, "ms_per_step": rows,
     "newton_iterations_per_step": so["newton_iterations"] / n,
     "factorizations_reused": so.get("factorizations_reused"),
     "minutes_for_240000_steps": rows["whole step"] * 240000 / 6e4}
json.dump(r, open(sys.argv[2], "w"), indent=2)
for k, v in rows.items():
    print(f"  {k:36s} {v:8.3f} ms")
print(f"  Newton iterations per step {r['newton_iterations_per_step']:.2f}; one clearance to t = 12"
      f" (240 000 steps) at this rate: {r['minutes_for_240000_steps']:.1f} min (target 20)")
