"""What validate.py and cost.py share: the published values (reference.csv) and the banded
FSI2 levels."""
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "lib"))
import outputs  # noqa: E402

# The banded FSI2 levels XY<n> (cells of h = 0.41/n over the bands, validate.py): n, columns,
# rows, dt, bar elements (length x thickness; the thickness twice the cells across the bar).
XY_LEVELS = ((82, 255, 70, 5e-4, [140, 8]), (123, 353, 99, 2.5e-4, [210, 12]),
             (164, 446, 128, 2.5e-4, [280, 16]), (246, 627, 182, 1.25e-4, [420, 24]))


def read_reference():
    """{(case, quantity): {mean, amplitude, frequency}} from reference.csv."""
    return {(r["case"], r["quantity"]): {k: float(r[k]) for k in ("mean", "amplitude", "frequency")}
            for r in outputs.commented_rows(os.path.join(HERE, "reference.csv"))}
