"""The peers (numbalsoda, SUNDIALS CVODE through scikit-sundae) on the same generated kernels, the
automaton followed without event location."""
from __future__ import annotations

from typing import Callable

import numba
import numpy as np
from numba import njit

from camdyn.engine.kernels import compiled_kernels
from camdyn.engine.tables import tables
from camdyn.model.model import Model

from .cases import ATOL_PER_RTOL, Case, Sample

#: transitions taken in a row within one evaluation of a peer's field, at most
MAX_HOPS = 4


def peer_field(model: Model):
    """A compiled ``field(t, alpha, alpha_dot, p, mem) -> alpha_ddot`` for solvers without event
    location.  ``mem[0]`` is the current mode (-1 at the start: the automaton's initial choice);
    each call first takes any transition of that mode whose surface the state is strictly
    across (direction * value > 0), into the first target whose conditions hold, then evaluates
    the generated rhs in the mode.  The register moves at every evaluation, trial stages
    included: what a solver without events can do with a hybrid model whose mode has memory
    (damping D's impact law lasts from contact to maximum compression, not while the gap closes)."""
    kern = compiled_kernels(model.kernels)
    tab = tables(model.kernels)
    rhs, surface = kern.rhs, kern.surface
    ws, sf, dr, ts, tm, cs, csf, csg = (np.ascontiguousarray(tab.data[offset:]) for offset in (
        tab.watch_start, tab.surface, tab.direction, tab.target_start, tab.target_mode, tab.condition_start,
        tab.condition_surface, tab.condition_sign))
    initial = tab.n_transitions

    @njit(error_model="numpy")
    def target(row, t, a, ad, p):
        for c in range(ts[row], ts[row + 1]):
            holds = True
            for q in range(cs[c], cs[c + 1]):
                if csg[q] * surface(tm[c], csf[q], t, a, ad, p) < 0.0:
                    holds = False
                    break
            if holds:
                return tm[c]
        return tm[ts[row + 1] - 1]

    @njit(error_model="numpy")
    def field(t, a, ad, p, mem):
        m = int(mem[0])
        if m < 0:
            m = target(initial, t, a, ad, p)
        for _ in range(MAX_HOPS):
            hit = -1
            for w in range(ws[m], ws[m + 1]):
                if dr[w] * surface(m, sf[w], t, a, ad, p) > 0.0:
                    hit = w
                    break
            if hit < 0:
                break
            m = target(hit, t, a, ad, p)
        mem[0] = m
        return rhs(m, t, a, ad, p)
    return field


def numbalsoda_rhs(field, n: int):
    """numbalsoda's cfunc: data = the parameter vector followed by the mode register."""
    import numbalsoda

    @numba.cfunc(numbalsoda.lsoda_sig)
    def rhs(t, u, du, data):
        arr = numba.carray(data, (n + 1,))
        du[0] = u[1]
        du[1] = field(t, u[0], u[1], arr[:n], arr[n:])
    return rhs


def numbalsoda_runner(case: Case, model: Model, rhs, method: str, rtol: float) -> Callable[[], Sample]:
    import numbalsoda
    solver = numbalsoda.dop853 if method == "DOP853" else numbalsoda.lsoda
    t_eval, y0 = case.t_eval(), model.static_state()
    data = np.append(model.p, -1.0)

    def run() -> Sample:
        data[-1] = -1.0
        usol, ok = solver(rhs.address, y0, t_eval, data=data, rtol=rtol, atol=rtol * ATOL_PER_RTOL)
        return Sample(usol[:, 0].copy(), None, bool(ok), 0)
    return run


def cvode_runner(case: Case, model: Model, field, method: str, rtol: float) -> Callable[[], Sample]:
    """SUNDIALS CVODE through scikit-sundae: its RHS is a Python callback calling the compiled field."""
    from sksundae.cvode import CVODE
    p, mem = model.p.copy(), np.array([-1.0])

    def rhsfn(t, y, yp):
        yp[0] = y[1]
        yp[1] = field(t, y[0], y[1], p, mem)
    t_eval = case.t_eval()
    solver = CVODE(rhsfn, method=method, rtol=rtol, atol=rtol * ATOL_PER_RTOL, max_num_steps=10**7)

    def run() -> Sample:
        mem[0] = -1.0
        sol = solver.solve(t_eval, model.static_state())
        ok = bool(sol.success) and sol.t.size == t_eval.size
        return Sample(sol.y[:, 0].copy() if ok else np.full(t_eval.size, np.nan), None, ok, 0)
    return run


def peers_available() -> dict[str, bool]:
    out = {}
    for name, module in (("numbalsoda", "numbalsoda"), ("scikit-sundae", "sksundae")):
        try:
            __import__(module)
            out[name] = True
        except Exception:  # noqa: BLE001 - any import failure means "not installed here"
            out[name] = False
    return out
