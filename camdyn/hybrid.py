"""The discrete state of the hybrid model: regimes, their switching surfaces, transitions.

A regime is selected by flags, each tied to the sign of one generated surface:

  contact   gap psi_i < 0                  (Eqs. 10 / 15)
  loading   gap rate psi_i_dot < 0         (damping D/E: impact law until maximum compression)
  forward   sliding velocity v_r > 0       (Coulomb friction: the sign of mu)

Coulomb friction adds a fourth possibility for ``forward``: ``STICK``, the Filippov
sliding mode on v_r = 0 (misprint 12).  When a slip reversal lands where the friction
jump itself would drive v_r straight back (both one-sided vector fields point at the
surface), the follower sticks: dv_r/dt = 0 holds with an equivalent friction
coefficient between -mu_m and +mu_m.  In this one-degree-of-freedom model alpha_ddot is
affine in mu, so the sticking dynamics and every output are the convex combination
lambda * (forward regime) + (1 - lambda) * (backward regime) that keeps dv_r/dt = 0;
sticking ends when lambda leaves [0, 1], i.e. when one side's field turns away.

This module knows nothing of time stepping; :mod:`camdyn.integrate` drives it.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from .events import Event
from .model import Model

STICK = "stick"


@dataclass(frozen=True)
class Regime:
    """One regime, ready to integrate: d(alpha, alpha_dot)/dt, its Jacobian, watched events."""

    name: str
    key: tuple
    fun: Callable
    jac: Callable
    events: tuple[Event, ...]


class Hybrid:
    """Regimes of a model, their events, and what follows each event."""

    def __init__(self, model: Model):
        self.model = model
        K = model.kernels
        self.flags = K.FLAGS
        self.linear = not self.flags
        self.names = dict(model.regimes)          # key -> generated regime name
        self.surfaces = {f: (model.bind(getattr(K, K.FLAG_SURFACES[f][0])), K.FLAG_SURFACES[f][1])
                         for f in self.flags}
        # the gap's exact time derivative finds hops hidden between the samples of a step
        self.rates = {"contact": model.bind(K.gap_rate)} if self.flags else {}
        self.stick_possible = "forward" in self.flags
        if self.stick_possible:
            self._slip_partials = model.bind(K.slip_partials)
        self._cache: dict[tuple, Regime] = {}

    # --- naming ------------------------------------------------------------------
    def name(self, key: tuple) -> str:
        if self.stick_possible and key[-1] == STICK:
            return self.names[key[:-1] + (True,)].replace("_fwd", "_stick")
        return self.names[key]

    def _sides(self, key: tuple) -> tuple[tuple, tuple]:
        """(forward key, backward key) of a sticking key."""
        return key[:-1] + (True,), key[:-1] + (False,)

    # --- the state of a run ----------------------------------------------------------
    def initial(self, t: float, y: np.ndarray) -> tuple:
        if self.linear:
            if len(self.names) == 1:
                return next(iter(self.names))
            v_r = self.model.bind(self.model.kernels.out_contact_fwd)(t, y[0], y[1])[6]
            return (bool(v_r >= 0),)
        return self._entering(t, y, self._side("contact", t, y))

    def _side(self, flag: str, t: float, y, default: bool = True) -> bool:
        """Whether the state is on the flag's side; on the surface itself, where it heads.

        The look-ahead moves alpha by its rate over a tiny time (exact to first order for
        the gap, which depends on t and alpha only; a fair guess for the other surfaces).
        """
        g, true_sign = self.surfaces[flag]
        value = g(t, y[0], y[1])
        if value == 0:
            h = 1e-9 * max(1.0, abs(t))
            value = g(t + h, y[0] + h * y[1], y[1])
        return default if value == 0 else bool(np.sign(value) == true_sign)

    def _entering(self, t, y, contact: bool) -> tuple:
        """Flags when contact starts (the others read off the state) or ends (out of scope)."""
        if not contact:
            return (False,) + (None,) * (len(self.flags) - 1)
        return (True,) + tuple(self._side(f, t, y) for f in self.flags[1:])

    def after(self, key: tuple, event: str, t: float, y: np.ndarray) -> tuple:
        """The key after ``event`` fired at (t, y) in regime ``key``."""
        if event == "contact":
            return self._entering(t, y, not key[0])
        if event in ("unstick_fwd", "unstick_bwd"):
            return key[:-1] + (event == "unstick_fwd",)
        i = self.flags.index(event)
        new = key[:i] + (not key[i],) + key[i + 1:]
        if event == "forward" and self._attracted(new, t, y):
            return new[:-1] + (STICK,)
        return new

    # --- Filippov sliding on v_r = 0 ---------------------------------------------------
    def _slip_rates(self, key: tuple, t: float, y) -> tuple[float, float, float, float, float]:
        """dv_r/dt under the forward and backward fields, their alpha_ddot, and dv_r/d(alpha_dot)."""
        fwd, bwd = self._sides(key)
        a_fwd = self._accel(fwd)(t, y[0], y[1])
        a_bwd = self._accel(bwd)(t, y[0], y[1])
        s_t, s_a, s_ad = self._slip_partials(t, y[0], y[1])
        drift = s_t + s_a * y[1]
        return drift + s_ad * a_fwd, drift + s_ad * a_bwd, a_fwd, a_bwd, s_ad

    def _attracted(self, key: tuple, t: float, y) -> bool:
        """Both fields point at v_r = 0: forward side moving down, backward side moving up."""
        rate_fwd, rate_bwd, *_ = self._slip_rates(key[:-1] + (STICK,), t, y)
        return rate_fwd < 0 < rate_bwd

    def stick_weight(self, key: tuple, t, alpha, alpha_dot):
        """lambda in [0, 1] (1: all forward) and alpha_ddot of the sliding mode."""
        fwd, bwd = self._sides(key)
        a_fwd = self._accel(fwd)(t, alpha, alpha_dot)
        a_bwd = self._accel(bwd)(t, alpha, alpha_dot)
        s_t, s_a, s_ad = self._slip_partials(t, alpha, alpha_dot)
        a_eq = -(s_t + s_a * alpha_dot) / s_ad
        lam = (a_eq - a_bwd) / (a_fwd - a_bwd)
        return lam, a_eq

    # --- regimes ---------------------------------------------------------------------
    def _accel(self, key: tuple):
        return self.model.bind(getattr(self.model.kernels, f"rhs_{self.names[key]}"))

    def regime(self, key: tuple, ledger: bool = False) -> Regime:
        """The regime of ``key``; with ``ledger``, its state carries three more entries, the
        work of the cam drive, of contact damping and of friction (integrals of P_in, D_c, D_f)."""
        if (key, ledger) not in self._cache:
            regime = self._build(key)
            self._cache[key, ledger] = self._with_ledger(regime) if ledger else regime
        return self._cache[key, ledger]

    def _with_ledger(self, regime: Regime) -> Regime:
        powers = self._powers(regime.key)

        def fun(t, y):
            return np.concatenate([regime.fun(t, y[:2]), powers(t, y[0], y[1])])

        def jac(t, y):
            out = np.zeros((5, 5))
            out[:2, :2] = regime.jac(t, y[:2])
            return out

        return Regime(regime.name, regime.key, fun, jac, regime.events)

    def _powers(self, key: tuple):
        """(P_in, D_c, D_f) at a state, from the generated scalar outputs (OUTPUTS[10:13])."""
        K = self.model.kernels
        if self.stick_possible and key[-1] == STICK:
            fwd, bwd = (self.model.bind(getattr(K, f"out_{self.names[k]}")) for k in self._sides(key))

            def powers(t, a, ad):
                try:
                    lam, _ = self.stick_weight(key, t, a, ad)
                    f, b = fwd(t, a, ad)[10:13], bwd(t, a, ad)[10:13]
                except (ValueError, OverflowError):
                    return np.full(3, np.nan)
                return np.array([lam * x + (1 - lam) * z for x, z in zip(f, b)])
            return powers
        out = self.model.bind(getattr(K, f"out_{self.names[key]}"))

        def powers(t, a, ad):
            try:
                return np.array(out(t, a, ad)[10:13])
            except (ValueError, OverflowError):  # a wild trial stage (log of cos < 0): reject it
                return np.full(3, np.nan)
        return powers

    def _build(self, key: tuple) -> Regime:
        m = self.model
        if self.stick_possible and key[-1] == STICK:
            return self._build_stick(key)
        name = self.names[key]
        accel = self._accel(key)
        jf = m.bind(getattr(m.kernels, f"jac_{name}"))

        def fun(t, y):
            try:
                return np.array([y[1], accel(t, y[0], y[1])])
            except (ValueError, OverflowError):  # a wild trial stage (sin of inf): NaN rejects the step
                return np.array([y[1], np.nan])

        def jac(t, y):
            d0, d1 = jf(t, y[0], y[1])
            return np.array([[0.0, 1.0], [d0, d1]])

        return Regime(name, key, fun, jac, self._flag_events(key))

    def _flag_events(self, key: tuple) -> tuple[Event, ...]:
        """Each in-scope flag's surface, watched in the direction that leaves the flag's side."""
        if self.linear:
            return ()
        out = []
        for flag, value in zip(self.flags, key):
            if value is None or value == STICK:
                continue
            g, true_sign = self.surfaces[flag]
            direction = -true_sign if value else true_sign
            rate = self.rates.get(flag)
            out.append(Event(flag, lambda t, y, g=g: g(t, y[0], y[1]), direction,
                             None if rate is None else (lambda t, y, r=rate: r(t, y[0], y[1]))))
        return tuple(out)

    def _build_stick(self, key: tuple) -> Regime:
        fwd, bwd = self._sides(key)
        jf_fwd = self.model.bind(getattr(self.model.kernels, f"jac_{self.names[fwd]}"))

        def fun(t, y):
            try:
                _, a_eq = self.stick_weight(key, t, y[0], y[1])
            except (ValueError, OverflowError, ZeroDivisionError):  # a wild trial stage: reject the step
                a_eq = np.nan
            return np.array([y[1], a_eq])

        def jac(t, y):  # only implicit methods use it; the forward side's is close enough
            d0, d1 = jf_fwd(t, y[0], y[1])
            return np.array([[0.0, 1.0], [d0, d1]])

        def leave_fwd(t, y):  # dv_r/dt under the forward field turns positive: slips forward
            return self._slip_rates(key, t, y)[0]

        def leave_bwd(t, y):  # dv_r/dt under the backward field turns negative: slips backward
            return self._slip_rates(key, t, y)[1]

        events = self._flag_events(key) + (Event("unstick_fwd", leave_fwd, +1),
                                           Event("unstick_bwd", leave_bwd, -1))
        return Regime(self.name(key), key, fun, jac, events)

    # --- outputs ---------------------------------------------------------------------
    def outputs(self, key: tuple, t, alpha, alpha_dot) -> tuple:
        """The generated output quantities (OUTPUTS order) on arrays, for samples in ``key``."""
        K = self.model.kernels
        if self.stick_possible and key[-1] == STICK:
            fwd, bwd = self._sides(key)
            lam, _ = np.vectorize(lambda *a: self.stick_weight(key, *a))(t, alpha, alpha_dot)
            out_f = self.model.bind(getattr(K, f"out_{self.names[fwd]}_v"))(t, alpha, alpha_dot)
            out_b = self.model.bind(getattr(K, f"out_{self.names[bwd]}_v"))(t, alpha, alpha_dot)
            return tuple(lam * f + (1 - lam) * b for f, b in zip(out_f, out_b))
        return self.model.bind(getattr(K, f"out_{self.names[key]}_v"))(t, alpha, alpha_dot)
