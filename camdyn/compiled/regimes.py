"""The discrete state of the compiled loop: regimes, their vector fields, surfaces and switches.

The compiled twin of :mod:`camdyn.hybrid`.  A regime is an index r.  Generated regimes are
``0 <= r < nr`` (``REGIME_NAMES``); with Coulomb friction, ``nr + r`` is the Filippov stick
mode on v_r = 0 whose forward side is generated regime r (misprint 12, :mod:`camdyn.hybrid`).

``fns = (rhs, surf, aux, power)`` are a scene's compiled kernels (:mod:`.kernels`):
``rhs(r, ...)`` the generated regime's alpha_ddot, ``surf(k, ...)`` flag k's surface,
``aux(j, ...)`` the gap rate (j = 0) and the partials of v_r (j = 1, 2, 3), ``power(3 r + i,
...)`` the ledger's flows.  ``tab = (flags_of, signs, lookup, partner)`` are the tables of
:func:`camdyn.compiled.backend.tables`: ``flags_of[r, k]`` is -1 (out of scope), 0, 1, or
STICK for the forward flag of a stick mode; ``lookup`` maps a flag combination (base-3 code
of flag + 1) to r; ``signs[k]`` is the sign of flag k's surface where the flag is True;
``partner[r]`` is the generated regime with the forward flag flipped (-1 without one).

The small functions on the hot path (accel, value, ...) are inlined at numba's IR level:
a call that passes the kernels as first-class function values costs ~15 ns by itself,
as much as a fifth of a kernel evaluation.

Value indices: ``0 <= k < nf`` are the flags' surfaces, ``nf`` (UNSTICK_FWD) and ``nf + 1``
(UNSTICK_BWD) the stick mode's exits, ``nf + 2`` (GAP_RATE) the gap rate, which finds an
excursion across the contact surface hidden between two samples of a step.
"""
from __future__ import annotations

import numpy as np
from numba import njit

#: flags_of value of the forward flag in a stick mode
STICK = 2
#: value indices past the flags' surfaces (offsets from nf)
UNSTICK_FWD, UNSTICK_BWD, GAP_RATE = 0, 1, 2
N_EXTRA = 3


@njit(cache=True, inline="always")
def accel(fns, nr, r, t, a, ad, p):
    """alpha_ddot in regime r: the generated regime's, or the stick mode's, which keeps
    dv_r/dt = v_t + v_a alpha_dot + v_ad alpha_ddot = 0."""
    if r < nr:
        return fns[0](r, t, a, ad, p)
    return -(fns[2](1, t, a, ad, p) + fns[2](2, t, a, ad, p) * ad) / fns[2](3, t, a, ad, p)


@njit(cache=True, inline="always")
def slip_rates(fns, fwd, bwd, t, a, ad, p):
    """dv_r/dt under the forward and under the backward regime's field."""
    drift = fns[2](1, t, a, ad, p) + fns[2](2, t, a, ad, p) * ad
    s_ad = fns[2](3, t, a, ad, p)
    return drift + s_ad * fns[0](fwd, t, a, ad, p), drift + s_ad * fns[0](bwd, t, a, ad, p)


@njit(cache=True, inline="always")
def value(fns, tab, nr, r, k, t, a, ad, p):
    """Surface or auxiliary value k (see the module docstring) in regime r."""
    nf = tab[1].shape[0]
    if k < nf:
        return fns[1](k, t, a, ad, p)
    if k == nf + GAP_RATE:
        return fns[2](0, t, a, ad, p)
    fwd = r - nr
    rate_fwd, rate_bwd = slip_rates(fns, fwd, tab[3][fwd], t, a, ad, p)
    return rate_fwd if k == nf + UNSTICK_FWD else rate_bwd


@njit(cache=True, inline="always")
def flow(fns, tab, nr, r, i, t, a, ad, p):
    """Power flow i (P_in, D_c, D_f) in regime r; in a stick mode the convex combination
    lambda fwd + (1 - lambda) bwd that keeps v_r = 0 (camdyn.hybrid.Hybrid.stick_weight)."""
    if r < nr:
        return fns[3](3 * r + i, t, a, ad, p)
    fwd = r - nr
    bwd = tab[3][fwd]
    a_fwd = fns[0](fwd, t, a, ad, p)
    a_bwd = fns[0](bwd, t, a, ad, p)
    lam = (accel(fns, nr, r, t, a, ad, p) - a_bwd) / (a_fwd - a_bwd)
    return lam * fns[3](3 * fwd + i, t, a, ad, p) + (1.0 - lam) * fns[3](3 * bwd + i, t, a, ad, p)


@njit(cache=True)
def on_true_side(fns, tab, k, t, a, ad, p, default):
    """Whether the state is on the side of surface k where its flag is True; exactly on
    the surface, where it is heading (a look-ahead of alpha by its rate over 1e-9 s)."""
    g = fns[1](k, t, a, ad, p)
    if g == 0.0:
        h = 1e-9 * max(1.0, abs(t))
        g = fns[1](k, t + h, a + h * ad, ad, p)
    if g == 0.0:
        return default
    return (g > 0.0) == (tab[1][k] > 0)


@njit(cache=True)
def regime_of(flags, lookup):
    code = 0
    scale = 1
    for k in range(flags.shape[0]):
        code += (flags[k] + 1) * scale
        scale *= 3
    return lookup[code]


@njit(cache=True)
def entering(fns, tab, t, a, ad, p, contact):
    """The regime when contact starts (other flags from the state) or ends (out of scope)."""
    nf = tab[1].shape[0]
    flags = np.full(nf, -1, dtype=np.int64)
    flags[0] = 1 if contact else 0
    if contact:
        for k in range(1, nf):
            flags[k] = 1 if on_true_side(fns, tab, k, t, a, ad, p, True) else 0
    return regime_of(flags, tab[2])


@njit(cache=True)
def attracted(fns, tab, r, t, a, ad, p):
    """Both one-sided fields of regime r's pair point at v_r = 0 (forward side decelerating,
    backward side accelerating): the follower sticks."""
    nf = tab[1].shape[0]
    fwd = r if tab[0][r, nf - 1] == 1 else tab[3][r]
    rate_fwd, rate_bwd = slip_rates(fns, fwd, tab[3][fwd], t, a, ad, p)
    return rate_fwd < 0.0 < rate_bwd


@njit(cache=True)
def after(fns, tab, nr, stick, r, k, t, a, ad, p):
    """The regime after value k's surface is crossed in regime r."""
    flags_of, lookup = tab[0], tab[2]
    nf = tab[1].shape[0]
    if k == 0:
        return entering(fns, tab, t, a, ad, p, flags_of[r, 0] == 0)
    if k == nf + UNSTICK_FWD:
        return r - nr
    if k == nf + UNSTICK_BWD:
        return tab[3][r - nr]
    flags = flags_of[r].copy()
    if r >= nr:  # a stick mode's loading flag flipped: still sticking
        flags[nf - 1] = 1
        flags[k] = 1 - flags[k]
        return nr + regime_of(flags, lookup)
    flags[k] = 1 - flags[k]
    new = regime_of(flags, lookup)
    if stick and k == nf - 1 and attracted(fns, tab, new, t, a, ad, p):
        return nr + (new if flags[k] == 1 else tab[3][new])
    return new


@njit(cache=True)
def watch(tab, nr, r, dirs):
    """Directions in which regime r watches each value: leaving the flag's side (0 if out
    of scope); a stick mode watches its two exits instead of the forward flag.  Returns
    the number of values watched."""
    flags_of, signs = tab[0], tab[1]
    nf = signs.shape[0]
    n = 0
    for k in range(dirs.shape[0]):
        dirs[k] = 0
    for k in range(nf):
        v = flags_of[r, k]
        if v == 0 or v == 1:
            dirs[k] = -signs[k] if v == 1 else signs[k]
            n += 1
    if r >= nr:
        dirs[nf + UNSTICK_FWD] = 1   # forward field's dv_r/dt turns positive: slips forward
        dirs[nf + UNSTICK_BWD] = -1  # backward field's dv_r/dt turns negative: slips backward
        n += 2
    return n

