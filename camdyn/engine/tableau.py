"""Explicit Runge-Kutta methods with dense output, as frozen data that checks itself.

A :class:`Tableau` holds the Butcher coefficients in the layout SciPy's ``RK45`` and
``DOP853`` use: ``a``/``c``/``b`` for the ``n_stages`` stages, a first-same-as-last stage
``f(t + h, y_new)`` stored after them, error weights over all ``n_stages + 1`` stages, and
the dense output as a matrix ``P`` with ``y(t0 + theta h) = y0 + h sum_j K_j sum_k P[j, k]
theta^(k+1)`` over the stages (plus, for DOP853, three extra stages ``a_extra``/``c_extra``
computed only when the interpolant is needed).  Construction checks the identities every
such method must satisfy (row sums, the bushy-tree order conditions of ``b``, error weights
summing to zero, the interpolant reproducing ``y_new`` at theta = 1), so a typo in a
coefficient is an error at import, not a silent loss of order.

:func:`arrays` turns a tableau into the :class:`Method` (named arrays) the engine's stepper reads.
"""
from __future__ import annotations

from functools import lru_cache

from dataclasses import dataclass
from fractions import Fraction as Fr
from typing import NamedTuple

import numpy as np

from . import _dop853_coefficients as _d

#: error-norm formulas: the plain embedded difference (RK45), or DOP853's 5th/3rd-order blend
ERROR_KINDS = ("embedded", "dop853")


class TableauError(ValueError):
    """Coefficients that violate a Runge-Kutta identity."""


def _close(x: float, y: float, tol: float) -> bool:
    return abs(x - y) <= tol * max(1.0, abs(y))


@dataclass(frozen=True)
class Tableau:
    """An explicit Runge-Kutta pair with dense output (see the module docstring)."""

    name: str
    order: int                 # order of the propagated solution
    error_order: int           # order of the error estimator (step control exponent -1/(error_order+1))
    c: tuple                   # n_stages
    a: tuple                   # n_stages rows of n_stages (strictly lower triangular)
    b: tuple                   # n_stages
    e: tuple                   # n_stages + 1 error weights ("embedded"), or E5 for "dop853"
    dense: tuple               # (n_stages + 1 + n_extra) rows of interpolant power coefficients
    error_kind: str = "embedded"
    e3: tuple = ()             # DOP853's 3rd-order weights
    c_extra: tuple = ()        # extra stages of the interpolant (DOP853)
    a_extra: tuple = ()        # their rows, over all previous stages
    tol: float = 1e-14         # identities hold to this (relative) in floating point

    def __post_init__(self):
        s = len(self.c)
        if self.error_kind not in ERROR_KINDS:
            raise TableauError(f"{self.name}: error_kind must be one of {ERROR_KINDS}")
        if len(self.a) != s or any(len(row) != s for row in self.a) or len(self.b) != s:
            raise TableauError(f"{self.name}: a must be {s}x{s} and b of length {s}")
        if len(self.e) != s + 1 or (self.error_kind == "dop853" and len(self.e3) != s + 1):
            raise TableauError(f"{self.name}: error weights need {s + 1} entries (stages + FSAL)")
        if len(self.c_extra) != len(self.a_extra) or len(self.dense) != s + 1 + len(self.c_extra):
            raise TableauError(f"{self.name}: the dense output needs one row per stage, FSAL and extra stage")
        self._check_explicit_and_row_sums()
        self._check_order_conditions()
        self._check_error_and_dense()

    @property
    def n_stages(self) -> int:
        return len(self.c)

    @property
    def n_extra(self) -> int:
        return len(self.c_extra)

    def _check_explicit_and_row_sums(self):
        if self.c[0] != 0:
            raise TableauError(f"{self.name}: c[0] must be 0 (explicit method)")
        for i, row in enumerate(self.a):
            if any(x != 0 for x in row[i:]):
                raise TableauError(f"{self.name}: a[{i}] has an entry on or above the diagonal")
        rows = [(f"a[{i}]", r, ci) for i, (r, ci) in enumerate(zip(self.a, self.c))]
        rows += [(f"a_extra[{i}]", r, ci) for i, (r, ci) in enumerate(zip(self.a_extra, self.c_extra))]
        for label, row, ci in rows:
            if not _close(float(sum(row)), float(ci), self.tol):
                raise TableauError(f"{self.name}: {label} sums to {float(sum(row))!r}, not its c = {ci!r}")

    def _check_order_conditions(self):
        """The bushy trees sum b c^k = 1/(k+1), k < order, and the tall-bushy sum b_i a_ij c_j^k
        = 1/((k+1)(k+2)), k < order - 1: necessary conditions of order ``order``."""
        b, c = np.array(self.b, float), np.array(self.c, float)
        A = np.array(self.a, float)
        for k in range(self.order):
            if not _close(float(b @ c**k), 1 / (k + 1), 50 * self.tol):
                raise TableauError(f"{self.name}: order condition sum b c^{k} = 1/{k + 1} fails")
        for k in range(self.order - 1):
            if not _close(float(b @ (A @ c**k)), 1 / ((k + 1) * (k + 2)), 50 * self.tol):
                raise TableauError(f"{self.name}: order condition sum b a c^{k} = 1/{(k + 1) * (k + 2)} fails")

    def _check_error_and_dense(self):
        for label, w in (("e", self.e), ("e3", self.e3)):
            if w and not _close(float(sum(w)), 0.0, 10 * self.tol):
                raise TableauError(f"{self.name}: error weights {label} must sum to 0 (both solutions consistent)")
        at_one = np.array(self.dense, float).sum(axis=1)
        target = np.zeros(len(self.dense))
        target[:self.n_stages] = self.b
        if not np.allclose(at_one, target, rtol=0, atol=100 * self.tol):
            raise TableauError(f"{self.name}: the dense output at theta = 1 is not y_new")
        slope = np.array(self.dense, float)[:, 0]  # d/dtheta at 0 is h f(y0): K_0 only
        if not (_close(slope[0], 1.0, 100 * self.tol) and np.allclose(slope[1:], 0, atol=100 * self.tol)):
            raise TableauError(f"{self.name}: the dense output's slope at theta = 0 is not f(t0, y0)")


def _f(rows):
    return tuple(tuple(float(Fr(x)) for x in r) for r in rows) if isinstance(rows[0], (list, tuple)) \
        else tuple(float(Fr(x)) for x in rows)


#: Dormand & Prince (1980) 5(4) with Shampine's dense output (SciPy's RK45): exact fractions.
DOPRI5 = Tableau(
    name="RK45", order=5, error_order=4,
    c=_f(["0", "1/5", "3/10", "4/5", "8/9", "1"]),
    a=_f([["0", "0", "0", "0", "0", "0"],
          ["1/5", "0", "0", "0", "0", "0"],
          ["3/40", "9/40", "0", "0", "0", "0"],
          ["44/45", "-56/15", "32/9", "0", "0", "0"],
          ["19372/6561", "-25360/2187", "64448/6561", "-212/729", "0", "0"],
          ["9017/3168", "-355/33", "46732/5247", "49/176", "-5103/18656", "0"]]),
    b=_f(["35/384", "0", "500/1113", "125/192", "-2187/6784", "11/84"]),
    e=_f(["-71/57600", "0", "71/16695", "-71/1920", "17253/339200", "-22/525", "1/40"]),
    dense=_f([["1", "-8048581381/2820520608", "8663915743/2820520608", "-12715105075/11282082432"],
              ["0", "0", "0", "0"],
              ["0", "131558114200/32700410799", "-68118460800/10900136933", "87487479700/32700410799"],
              ["0", "-1754552775/470086768", "14199869525/1410260304", "-10690763975/1880347072"],
              ["0", "127303824393/49829197408", "-318862633887/49829197408", "701980252875/199316789632"],
              ["0", "-282668133/205662961", "2019193451/616988883", "-1453857185/822651844"],
              ["0", "40617522/29380423", "-110615467/29380423", "69997945/29380423"]]),
)


def _dop853_dense() -> tuple:
    """DOP853's interpolant in power form over the 16 extended stages.

    SciPy evaluates y(x) = y0 + F0 x + F1 x(1-x) + F2 x^2(1-x) + F3 x^2(1-x)^2 + F4 x^3(1-x)^2
    + F5 x^3(1-x)^3 + F6 x^4(1-x)^3 with F0 = dy, F1 = h K0 - dy, F2 = 2 dy - h (K0 + K12),
    F3.. = h D K; each F is linear in h K, so y - y0 = h sum_j K_j Q_j(x) exactly.
    """
    n, m = _d.N_STAGES, _d.N_STAGES_EXTENDED
    b = np.zeros(m)
    b[:n] = _d.B
    unit = np.eye(m)
    coef = [b, unit[0] - b, 2 * b - unit[0] - unit[n]] + [np.asarray(row, float) for row in _d.D]
    P = np.polynomial.Polynomial
    x, one_minus = P([0, 1]), P([1, -1])
    weights = [x, x * one_minus, x**2 * one_minus, x**2 * one_minus**2, x**3 * one_minus**2,
               x**3 * one_minus**3, x**4 * one_minus**3]
    rows = np.zeros((m, _d.INTERPOLATOR_POWER))
    for ci, w in zip(coef, weights):
        wc = np.zeros(_d.INTERPOLATOR_POWER + 1)
        wc[:len(w.coef)] = w.coef
        rows += np.outer(ci, wc[1:])
    return tuple(tuple(float(v) for v in r) for r in rows)


#: Dormand & Prince's 8(5,3) with its 7th-degree dense output (SciPy's DOP853).
DOP853 = Tableau(
    name="DOP853", order=8, error_order=7, error_kind="dop853",
    c=tuple(_d.C[:_d.N_STAGES]),
    a=tuple(tuple(r[:_d.N_STAGES]) for r in _d.A[:_d.N_STAGES]),
    b=tuple(_d.B), e=tuple(_d.E5), e3=tuple(_d.E3),
    c_extra=tuple(_d.C[_d.N_STAGES + 1:]),
    a_extra=tuple(tuple(r) for r in _d.A[_d.N_STAGES + 1:]),
    dense=_dop853_dense(),
    tol=1e-13,
)

TABLEAUS = {"RK45": DOPRI5, "DOP853": DOP853}


class Method(NamedTuple):
    """A tableau as the one coefficient array the stepper reads (:mod:`camdyn.engine.stepper`).

    ``coef`` rows ``0 .. n_rows - 1`` are the stage matrix A: the stages, then a row for the
    first-same-as-last stage (its row is b), then the extra stages of the interpolant (DOP853);
    rows ``c_row``, ``b_row``, ``e_row``, ``e3_row`` are c (1 for the FSAL stage), b, e and e3;
    rows ``p_row ..`` are the dense output in power form, one row per stage, ``degree`` columns.
    One array, not six: reference-counted compiled code pays an atomic count per array for every
    call that passes the method (a few per step; the engine's helpers are compiled without
    reference counts, :mod:`camdyn.engine.jit`)."""

    coef: np.ndarray
    n_stages: int
    n_extra: int
    n_rows: int        # stages + FSAL + extra stages
    c_row: int
    b_row: int
    e_row: int
    e3_row: int
    p_row: int
    degree: int        # columns of the dense output
    error_kind: int    # position in ERROR_KINDS
    exponent: float    # step-size control exponent, -1 / (error_order + 1)
    order: int         # of the propagated solution


def arrays(tab: Tableau) -> Method:
    """The tableau as the :class:`Method` the stepper takes."""
    s, x = tab.n_stages, tab.n_extra
    total = s + 1 + x
    dense = np.array(tab.dense, float)
    degree = dense.shape[1]
    c_row, b_row, e_row, e3_row, p_row = total, total + 1, total + 2, total + 3, total + 4
    coef = np.zeros((p_row + dense.shape[0], max(total, degree)))
    coef[:s, :s] = tab.a
    coef[s, :s] = tab.b
    for i, row in enumerate(tab.a_extra):
        coef[s + 1 + i, :len(row)] = row
    coef[c_row, :s], coef[c_row, s] = tab.c, 1.0
    coef[c_row, s + 1:total] = tab.c_extra
    coef[b_row, :s] = tab.b
    coef[e_row, :len(tab.e)] = tab.e
    if tab.e3:
        coef[e3_row, :len(tab.e3)] = tab.e3
    coef[p_row:, :degree] = dense
    return Method(coef, s, x, total, c_row, b_row, e_row, e3_row, p_row, degree,
                  ERROR_KINDS.index(tab.error_kind), -1.0 / (tab.error_order + 1), tab.order)


def stages_per_step(tab: Tableau, dense: bool) -> int:
    """RHS evaluations of one attempted step (the FSAL stage reused), plus the dense extras."""
    return tab.n_stages + (tab.n_extra if dense else 0)


__all__ = ["Tableau", "TableauError", "Method", "DOPRI5", "DOP853", "TABLEAUS", "arrays", "stages_per_step"]


@lru_cache(maxsize=None)
def method_of(name: str) -> Method:
    """The :class:`Method` of the tableau named ``name`` in TABLEAUS, built once (the stepper
    only reads it)."""
    return arrays(TABLEAUS[name])
