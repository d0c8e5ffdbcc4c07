"""The tangent dynamics' augmented system (x, Phi, integral of the divergence) between two
switches, integrated by the engine's Runge-Kutta pair, compiled (numba).

The system: x' = (alpha_dot, alpha_ddot), Phi' = J Phi with J = [[0, 1], [a_alpha,
a_alpha_dot]] from the generated ``jacobian``, and the divergence a_alpha_dot integrated
(:mod:`camdyn.tangent` explains its use).  The step is SciPy's algorithm for n components (the
RMS error norm, DOP853's blended estimate, the same step-size control and initial step as
:mod:`.stepper`, which is specialised to the 2-component state of the loop).  At the segment's
start the Jacobian is taken LOOK_AHEAD along the motion (the limit from inside the segment: a
segment starting on a surface may start on a kink of the law).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..derive.vocabulary import JAC_D_ALPHA, JAC_D_ALPHA_DOT, STATE, STATE_ALPHA, STATE_ALPHA_DOT
from . import cache
from .jit import jitable
from .stepper import accepted_factor, rejected_factor, spacing

cache.install()

#: the augmented state's rows: x in the vocabulary's STATE order, then Phi row by row
#: (Phi[i, j] at PHI_START + 2 i + j), then the integral of the divergence
AUG_ALPHA, AUG_ALPHA_DOT = STATE_ALPHA, STATE_ALPHA_DOT
PHI_START = len(STATE)
AUG_PHI = slice(PHI_START, PHI_START + 4)
AUG_DIVERGENCE = PHI_START + 4
N_AUGMENTED = AUG_DIVERGENCE + 1


@jitable
def fill_augmented(ad, add, jac, y, out):
    """out = the augmented field at y, given x' = (ad, add) and the Jacobian's second row ``jac``
    (JACOBIAN order): Phi' = [[0, 1], [a_alpha, a_alpha_dot]] Phi, column by column, and the
    divergence a_alpha_dot.  Compiled into :func:`augmented_field`; run as Python by camdyn.tangent."""
    j0, j1 = jac[JAC_D_ALPHA], jac[JAC_D_ALPHA_DOT]
    out[AUG_ALPHA], out[AUG_ALPHA_DOT] = ad, add
    for k in range(2):
        top, bottom = y[PHI_START + k], y[PHI_START + 2 + k]
        out[PHI_START + k] = bottom
        out[PHI_START + 2 + k] = j0 * top + j1 * bottom
    out[AUG_DIVERGENCE] = j1


@njit(cache=True, error_model="numpy")
def augmented_field(rhs, jacobian, p, m, t, y, t_start, look_ahead, jac, out):
    """out = the augmented field at (t, y) in mode m (see the module docstring)."""
    a, ad = y[AUG_ALPHA], y[AUG_ALPHA_DOT]
    add = rhs(m, t, a, ad, p)
    if t == t_start:
        jacobian(m, t + look_ahead, a + look_ahead * ad, ad + look_ahead * add, p, jac)
    else:
        jacobian(m, t, a, ad, p, jac)
    fill_augmented(ad, add, jac, y, out)


@njit(cache=True, error_model="numpy")
def _norm(v):
    return math.sqrt(np.sum(v * v) / v.shape[0])


@njit(cache=True, error_model="numpy")
def _initial_step(rhs, jacobian, p, m, t, y, f0, t_end, rtol, atol, exponent, look_ahead, jac, work):
    """SciPy's select_initial_step (Hairer, Norsett & Wanner II.4)."""
    scale = atol + np.abs(y) * rtol
    d0, d1 = _norm(y / scale), _norm(f0 / scale)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    h0 = min(h0, t_end - t)
    augmented_field(rhs, jacobian, p, m, t + h0, y + h0 * f0, t, look_ahead, jac, work)
    d2 = _norm((work - f0) / scale) / h0
    h1 = max(1e-6, h0 * 1e-3) if (d1 <= 1e-15 and d2 <= 1e-15) else (0.01 / max(d1, d2)) ** (-exponent)
    return min(100.0 * h0, h1, t_end - t)


@njit(cache=True, error_model="numpy")
def integrate_segment(rhs, jacobian, p, m, t0, t_end, y, rtol, atol, method, look_ahead):
    """y (N_AUGMENTED) at t_end from y at t0 in mode m; returns (y, ok)."""
    coef, n = method.coef, method.n_stages
    K = np.empty((n + 1, N_AUGMENTED))
    jac, z = np.empty(2), np.empty(N_AUGMENTED)
    y = y.copy()
    t = t0
    augmented_field(rhs, jacobian, p, m, t, y, t0, look_ahead, jac, K[0])
    h_abs = _initial_step(rhs, jacobian, p, m, t, y, K[0].copy(), t_end, rtol, atol, method.exponent,
                          look_ahead, jac, z)
    while t < t_end:
        rejected = False
        while True:
            if h_abs < 10.0 * spacing(t):
                return y, False
            t_new = min(t + h_abs, t_end)
            h = t_new - t
            for s in range(1, n + 1):                 # the stages, then the FSAL stage (row b)
                z[:] = y
                for j in range(s):
                    z += (h * coef[s, j]) * K[j]
                augmented_field(rhs, jacobian, p, m, t + coef[method.c_row, s] * h, z, t0, look_ahead, jac, K[s])
                if s == n:
                    y_new = z.copy()
            scale = atol + np.maximum(np.abs(y), np.abs(y_new)) * rtol
            e5, e3 = np.zeros(N_AUGMENTED), np.zeros(N_AUGMENTED)
            for j in range(n + 1):
                e5 += coef[method.e_row, j] * K[j]
                e3 += coef[method.e3_row, j] * K[j]
            if method.error_kind == 0:
                err = _norm(e5 * h / scale)
            else:
                s5, s3 = np.sum((e5 / scale) ** 2), np.sum((e3 / scale) ** 2)
                err = 0.0 if s5 == 0.0 and s3 == 0.0 else h * s5 / math.sqrt((s5 + 0.01 * s3) * N_AUGMENTED)
            if err < 1.0:  # SciPy's controller (stepper.CONTROLS["scipy"])
                h_abs = h * accepted_factor(err, 1.0, rejected, method.exponent, 1.0, 0.0)
                break
            h_abs = h * rejected_factor(err, method.exponent)
            rejected = True
        t, y = t_new, y_new
        K[0] = K[n]
    return y, True
