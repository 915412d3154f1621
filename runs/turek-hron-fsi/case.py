"""What validate.py and cost.py share: the published values (reference.csv) and the banded
FSI2 levels."""
import os

HERE = os.path.dirname(os.path.abspath(__file__))

# The banded FSI2 levels XY<n> (cells of h = 0.41/n over the bands, validate.py): n, columns,
# rows, dt, bar elements (length x thickness; the thickness twice the cells across the bar).
XY_LEVELS = ((82, 255, 70, 5e-4, [140, 8]), (123, 353, 99, 2.5e-4, [210, 12]),
             (164, 446, 128, 2.5e-4, [280, 16]), (246, 627, 182, 1.25e-4, [420, 24]))


def read_reference():
    """{(case, quantity): {mean, amplitude, frequency}} from reference.csv."""
    rows = [ln for ln in open(os.path.join(HERE, "reference.csv")) if not ln.startswith("#")]
    head = rows[0].strip().split(",")
    ref = {}
    for ln in rows[1:]:
        r = dict(zip(head, ln.strip().split(",")))
        ref[(r["case"], r["quantity"])] = {k: float(r[k]) for k in ("mean", "amplitude", "frequency")}
    return ref
