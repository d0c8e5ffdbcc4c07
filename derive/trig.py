"""Fewer trigonometric calls in the emitted code: exact identities, applied after the derivation.

Sines and cosines dominate the cost of a kernel (about two thirds of a contact RHS
evaluation, measured with ``perf``: ``__sincos`` alone was a quarter of a compiled run).  The
angles a kernel needs are integer combinations of a few *basis angles* plus a
parameter-only phase:

- V, the angle of the state with the smallest coefficient of alpha: the half angle
  (alpha - alpha0)/2 that the well-conditioned gap brings (geometry.psi_i_conditioned), so
  alpha = 2 V + alpha0;
- W, per family of time-dependent terms that are rational multiples of each other, the one
  of which all the others are integer multiples: Omega_c t / 2 for a constant speed,
  Theta_p sin(omega_c t) / 4 for the oscillating cam;
- a phase c made of parameters only (alpha0, theta0, alpha0 + theta0, alpha_star, ...).

:func:`economise` rewrites sin(n V + m W + c) and cos(...) as polynomials in sin V, cos V,
sin W, cos W (one sin/cos pair per basis angle, which compilers fuse into one ``sincos``)
and in sin c, cos c, which become *constants*: symbols of the parameter vector that
``pack()`` computes once (:func:`economise` returns their definitions).  A trigonometric call of a
parameter-only argument becomes such a constant too.  Every rewrite is an exact identity
(angle addition, double angles as 2 sin v cos v and 1 - 2 sin^2 v, accurate near v = 0),
so the emitted code agrees with the derivation to a few ulp; tests/test_generated.py
checks the kernels of six scenes against their lambdified derivation.

An angle is left as it is when it is itself a basis angle, when it is not linear in alpha
with a rational coefficient, or when its multiples are not integers.
"""
from __future__ import annotations

import re

import sympy as sp

from . import symbols as S

#: symbols whose terms make an angle time-dependent
_TIME = (S.t_s, S.Theta_s)
#: the state angle
_ALPHA = S.alpha_s
#: sympy's name of each function, for the constants' names
_FUNCS = {sp.sin: "sin", sp.cos: "cos"}


def _slug(c: sp.Expr) -> str:
    text = str(c).replace("+", " p ").replace("-", " m ").replace("/", " d ").replace("*", " ")
    return re.sub(r"[^0-9A-Za-z]+", "_", text).strip("_")


def constant(func, c: sp.Expr) -> sp.Symbol:
    """The parameter-vector symbol standing for func(c), c parameter-only (e.g. sin_alpha0)."""
    return sp.Symbol(f"{_FUNCS[func]}_{_slug(c)}", real=True)


def _parts(u: sp.Expr):
    """(a, T, c) with u = a alpha + T + c: a a Rational, T the time-dependent terms, c the
    parameter-only rest; None if u is not of that form."""
    u = sp.expand(u)
    a = sp.diff(u, _ALPHA)
    if not a.is_Rational:
        return None
    rest = sp.expand(u - a * _ALPHA)
    if rest.has(_ALPHA):
        return None
    terms = sp.Add.make_args(rest)
    T = sp.Add(*[x for x in terms if x.has(*_TIME)])
    return a, T, sp.expand(rest - T)


#: two points of the parameter space (positive, away from 0 and 1), one value per symbol in
#: sorted order, at which a ratio is evaluated before it is simplified (:func:`_varies`)
_PROBES = ((0.3141, 0.2718, 0.1618, 0.5772, 0.4142, 0.7071, 0.3333, 0.6931, 0.2357, 0.8660),
           (0.6180, 0.4473, 0.7320, 0.1234, 0.8888, 0.3030, 0.5555, 0.2222, 0.6666, 0.1414))


def _varies(q: sp.Expr) -> bool:
    """True when q surely is not a constant: it takes clearly different values at the two
    probe points.  Simplification preserves values, so ``sp.simplify(q)`` cannot be a number
    then, and the (slow: seconds for an arcsine of the geometry) simplification is skipped.
    False when unsure (no symbols, a symbol not positive-compatible, a value not finite, values
    close): the caller simplifies as before, so the decisions and the output are unchanged."""
    syms = sorted(q.free_symbols, key=sp.default_sort_key)
    if not syms or any(s.is_nonpositive or s.is_integer for s in syms):
        return False
    values = []
    for probe in _PROBES:
        point = {s: sp.Float(probe[i % len(probe)] * (1 + i // len(probe)), 30) for i, s in enumerate(syms)}
        v = sp.N(q.xreplace(point), 30)
        if not v.is_number or v.has(sp.nan, sp.zoo, sp.oo, -sp.oo):
            return False
        values.append(complex(v))
    a, b = values
    return abs(a - b) > 1e-9 * (abs(a) + abs(b))


def _ratio(x: sp.Expr, base: sp.Expr):
    """x / base if it is a non-zero integer, else None."""
    q = x / base
    if _varies(q):
        return None
    q = sp.simplify(q)
    return int(q) if q.is_Integer and q != 0 else None


def _rational_multiple(x: sp.Expr, base: sp.Expr) -> bool:
    """Whether x / base is a rational number."""
    q = x / base
    return not _varies(q) and sp.simplify(q).is_Rational


def _time_bases(Ts: list[sp.Expr]) -> dict[sp.Expr, tuple[sp.Expr, int]]:
    """For each time-dependent part T, (W, m) with T = m W and W a basis angle, where one exists."""
    out = {}
    for T in Ts:
        for W in Ts:
            m = _ratio(T, W)
            family = [other for other in Ts if _rational_multiple(other, W)]
            if m is not None and all(_ratio(other, W) is not None for other in family):
                out[T] = (W, m)
                break
    return out


def _multiple(n: int, s: sp.Expr, c: sp.Expr) -> tuple[sp.Expr, sp.Expr]:
    """(sin(n v), cos(n v)) from s = sin v, c = cos v; double angles as 2 s c and 1 - 2 s^2."""
    if n < 0:
        sn, cn = _multiple(-n, s, c)
        return -sn, cn
    if n == 0:
        return sp.Integer(0), sp.Integer(1)
    if n == 1:
        return s, c
    if n % 2 == 0:
        sh, ch = _multiple(n // 2, s, c)
        return 2 * sh * ch, 1 - 2 * sh ** 2
    sm, cm = _multiple(n - 1, s, c)
    return sm * c + cm * s, cm * c - sm * s


def _phase(c: sp.Expr, constants: dict) -> tuple[sp.Expr, sp.Expr]:
    """(sin c, cos c) as constants, with the sign taken out of c (sin(-c) = -sin c);
    records their definitions in ``constants``."""
    if c == 0:
        return sp.Integer(0), sp.Integer(1)
    if c.could_extract_minus_sign():
        s, co = _phase(-c, constants)
        return -s, co
    for func in _FUNCS:
        constants[constant(func, c)] = func(c)
    return constant(sp.sin, c), constant(sp.cos, c)


def _add(a, b):
    """(sin, cos) of a sum from the (sin, cos) of its parts."""
    return a[0] * b[1] + a[1] * b[0], a[1] * b[1] - a[0] * b[0]


def economise(exprs: list[sp.Expr]) -> tuple[list[sp.Expr], dict[sp.Symbol, sp.Expr]]:
    """The same expressions with fewer distinct trigonometric calls (see the module
    docstring), and the constants they use: {symbol: its parameter-only definition}.

    tan(u) and sec(u) first become sin(u)/cos(u) and 1/cos(u).
    """
    exprs = [sp.sympify(x).replace(sp.tan, lambda u: sp.sin(u) / sp.cos(u))
             .replace(sp.sec, lambda u: 1 / sp.cos(u)) for x in exprs]
    args = sorted({call.args[0] for x in exprs for call in x.atoms(sp.sin, sp.cos)}, key=sp.default_sort_key)
    parts = {u: _parts(u) for u in args}
    parts = {u: p for u, p in parts.items() if p is not None}
    state = sorted((u for u, (a, T, _) in parts.items() if a != 0 and T == 0),
                   key=lambda u: (abs(parts[u][0]), sp.default_sort_key(u)))
    V = state[0] if state else None
    times = _time_bases(sorted({T for _, T, _ in parts.values() if T != 0}, key=sp.default_sort_key))
    subs, constants = {}, {}
    for u, (a, T, c) in parts.items():
        if u == V or (a == 0 and c == 0 and T in times and times[T][1] == 1):
            continue  # a basis angle: computed as it is
        if a == 0 and T == 0:
            pieces = [_phase(c, constants)]
        else:
            if (a != 0 and V is None) or (T != 0 and T not in times):
                continue
            pieces = []
            if a != 0:
                aV, _, cV = parts[V]
                n = a / aV
                if not n.is_Integer:
                    continue
                pieces.append(_multiple(int(n), sp.sin(V), sp.cos(V)))
                c = sp.expand(c - n * cV)
            if T != 0:
                W, m = times[T]
                pieces.append(_multiple(m, sp.sin(W), sp.cos(W)))
            pieces.append(_phase(c, constants))
        s, co = pieces[0]
        for piece in pieces[1:]:
            s, co = _add((s, co), piece)
        subs[sp.sin(u)], subs[sp.cos(u)] = s, co
    out = [x.xreplace(subs) for x in exprs]
    if _angles(out) >= _angles(exprs):  # no fewer calls: keep the derivation's form
        return exprs, {}
    used = set().union(*(x.free_symbols for x in out))
    return out, {sym: d for sym, d in constants.items() if sym in used}


def _angles(exprs) -> int:
    """The number of distinct angles whose sine or cosine the expressions compute."""
    return len({call.args[0] for x in exprs for call in x.atoms(sp.sin, sp.cos)})
