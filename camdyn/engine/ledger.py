"""The energy ledger: the work of the cam drive, of contact damping and of friction,
integrated along each step's interpolant.

The power flows P_in, D_c, D_f (the generated ``outputs`` kernel; their positions are
``Tables.flows``) do not feed back into the motion, so they are quadratures along the dense
output (:func:`camdyn.engine.stepper.dense_eval`): 5-point Gauss-Legendre, exact for
polynomials of degree 9, so the error on a step is the interpolant's (7th order for DOP853),
the state's own order.  In a stuck mode the generated outputs already use the friction force
that keeps the follower stuck.
"""
from __future__ import annotations

import numpy as np

from .jit import jitable
from .stepper import dense_eval

_x, _w = np.polynomial.legendre.leggauss(5)
#: Gauss-Legendre nodes and weights on [0, 1]
NODES = 0.5 * (_x + 1.0)
WEIGHTS = 0.5 * _w
#: flows integrated: P_in, D_c, D_f (camdyn.vocabulary.FLOWS)
N_FLOWS = 3


@jitable
def accumulate(prob, m, t, h, y0, y1, Q, ta, tb, buf, work):
    """work[i] += the integral of flow i over [ta, tb] inside the step [t, t + h]; ``buf`` holds
    the outputs at a node."""
    length = tb - ta
    if length <= 0.0:
        return
    tab = prob.tables
    for q in range(NODES.shape[0]):
        tq = ta + NODES[q] * length
        a, ad = dense_eval(tq, t, h, y0, y1, Q)
        prob.kernels.outputs(m, tq, a, ad, prob.p, buf)
        for i in range(N_FLOWS):
            work[i] += WEIGHTS[q] * length * buf[tab.data[tab.flows + i]]
