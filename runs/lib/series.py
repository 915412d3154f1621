"""Time series: zero crossings and periods."""
import numpy as np


def zero_crossings(t, y):
    """Times where y changes sign (linear interpolation)."""
    s = np.signbit(y)
    i = np.nonzero(s[1:] != s[:-1])[0]
    return t[i] + (t[i + 1] - t[i]) * y[i] / (y[i] - y[i + 1])


def period(t, y):
    """Mean period over whole periods between zero crossings (an offset of the mean cancels)."""
    z = zero_crossings(t, y)
    if len(z) < 3:
        return float("nan")
    last = len(z) - 1 - (len(z) - 1) % 2
    return 2 * (z[last] - z[0]) / last
