"""The energy ledger of the compiled loop: the work of the cam drive, of contact damping and
of friction, integrated along the dense output.

The SciPy backend integrates W_in, W_c, W_f as three extra states (their rates P_in, D_c,
D_f do not depend on them).  Here they are quadratures of the flows along each step's
interpolant (:func:`camdyn.compiled.stepper.dense_eval`): 5-point Gauss-Legendre, exact for
polynomials of degree 9, so its error on a step is that of the interpolant (7th order for
DOP853), the same order as the state's.  The flows are the generated ``power_index``
kernels, through :func:`camdyn.compiled.regimes.flow` (convex combination in a stick mode).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .regimes import flow
from .stepper import dense_eval

_x, _w = np.polynomial.legendre.leggauss(5)
#: Gauss-Legendre nodes and weights on [0, 1]
NODES = 0.5 * (_x + 1.0)
WEIGHTS = 0.5 * _w
#: flows integrated: P_in, D_c, D_f (OUTPUTS[10:13])
N_FLOWS = 3


@njit(cache=True)
def accumulate(fns, tab, nr, r, t, h, y0, y1, Q, p, ta, tb, w):
    """w[i] += integral of flow i over [ta, tb] inside the step [t, t + h]."""
    length = tb - ta
    if length <= 0.0:
        return
    for q in range(NODES.shape[0]):
        tq = ta + NODES[q] * length
        a, ad = dense_eval(tq, t, h, y0, y1, Q)
        for i in range(N_FLOWS):
            w[i] += WEIGHTS[q] * length * flow(fns, tab, nr, r, i, tq, a, ad, p)
