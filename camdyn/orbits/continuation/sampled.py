"""The extremes of a periodic sampled curve (an orbit's gap, its contact force), refined between
samples."""
from __future__ import annotations

import numpy as np


def refined_max(v: np.ndarray) -> float:
    """The largest value of a periodic sampled curve, refined by a parabola through its neighbours."""
    v = v[:-1]                              # the last sample repeats the first (one period)
    k = int(np.argmax(v))
    a, b, c = v[k - 1], v[k], v[(k + 1) % v.size]
    curvature = a - 2 * b + c
    return float(b - (a - c) ** 2 / (8 * curvature)) if curvature < 0 else float(b)
