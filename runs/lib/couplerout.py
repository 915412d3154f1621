"""Reading the coupler's output: coupler_forces.csv (the fluid's force on each body and their
total) and coupler_iterations.csv with the iterations table of summary.json (coupled
iterations)."""
import os

import numpy as np

from outputs import summary, table


def forces(folder):
    return table(os.path.join(folder, "coupler_forces.csv"))


def iterations(folder):
    """Coupled iterations of a run: mean and max per step, steps not converged, the largest
    final residual, the mean after the first 10 steps; {} when the run had none."""
    path = os.path.join(folder, "coupler_iterations.csv")
    it = summary(folder).get("coupler", {}).get("iterations")
    if not it or not os.path.exists(path):
        return {}
    n = table(path)["iterations"]
    return {"mean": float(np.mean(n)), "max": int(np.max(n)),
            "not_converged_steps": int(it["not_converged_steps"]),
            "largest_final_residual": float(it.get("largest_final_residual", float("nan"))),
            "mean_after_first_10_steps": float(np.mean(n[10:])) if len(n) > 10 else float("nan")}


def iterations_per_step(folder):
    """Mean coupled iterations per step, None when the run had none."""
    return iterations(folder).get("mean")
