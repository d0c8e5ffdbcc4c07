"""The profile evaluators written into the modules of scenes on a cam other than the circle.

A scene's kernels call ``profile(n, phi, p, offset)``, h^(n)(phi) of the cam's support function
(:mod:`derive.profile`), once per distinct call.  Its data is a flat block at the end of the
parameter vector, from ``p[PROFILE_OFFSET]`` on (``pack()`` appends it); the layouts are
those of ``camdyn.model.profiles`` (``Profile.block()``):

- ``spline``: ``[K, phi_0 .. phi_K, c_(0,0..5) .. c_(K-1,0..5)]``, a periodic piecewise
  quintic, h = sum_j c_(k,j) (phi - phi_k)^j on [phi_k, phi_(k+1)), phi_K = phi_0 + 2 pi;
- ``arcs``: ``[K, a_0 .. a_K, rho_0 .. rho_(K-1), cx_0 .., cy_0 ..]``: on [a_k, a_(k+1)) the
  circle of radius rho_k centred at (cx_k, cy_k), h = rho_k + cx_k cos(phi) + cy_k sin(phi).

Only the scene's own family is written (a scene holds only what it uses).  The evaluator is
compiled with numba (``njit``) so that the compiled kernels call it directly; a plain-Python
run calls the same compiled function.
"""
from __future__ import annotations

#: the name of the profile's data among pack()'s inputs (and a Rig's)
PROFILE_BLOCK = "profile"

_SEARCH = '''
@numba.njit(cache=True)
def _piece(x, p, offset):
    """The piece k of the profile holding the body angle phi, and phi reduced into
    [phi_0, phi_0 + 2 pi): a bisection over the K + 1 breakpoints p[offset + 1 ...]."""
    K = int(p[offset])
    start = p[offset + 1]
    x = start + (x - start) % (2.0 * pi)
    lo, hi = 0, K
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if x >= p[offset + 1 + mid]:
            lo = mid
        else:
            hi = mid
    return lo, x
'''

_SPLINE = '''
@numba.njit(cache=True)
def profile(n, phi, p, offset):
    """h^(n)(phi), the n-th derivative of the cam's support function (m; phi in rad): a periodic
    piecewise quintic (derive.profile_code), by Horner's rule on the piece holding phi."""
    k, x = _piece(phi, p, offset)
    K = int(p[offset])
    d = x - p[offset + 1 + k]
    c = offset + K + 2 + 6 * k
    acc = 0.0
    for j in range(5, n - 1, -1):
        weight = 1.0
        for i in range(j - n + 1, j + 1):
            weight *= i
        acc = acc * d + weight * p[c + j]
    return acc
'''

_ARCS = '''
@numba.njit(cache=True)
def profile(n, phi, p, offset):
    """h^(n)(phi), the n-th derivative of the cam's support function (m; phi in rad): the
    circular arc holding phi (derive.profile_code), h = rho_k + cx_k cos(phi) + cy_k sin(phi).
    The derivatives turn (cos, sin) a quarter turn each, so every call takes the sine and cosine
    of phi itself (one pair for all the calls of a kernel, once the compiler has inlined them)."""
    k, x = _piece(phi, p, offset)
    K = int(p[offset])
    base = offset + K + 2
    cx = p[base + K + k]
    cy = p[base + 2 * K + k]
    c = cos(phi)
    s = sin(phi)
    turn = n % 4
    if turn == 0:
        return p[base + k] + cx * c + cy * s if n == 0 else cx * c + cy * s
    if turn == 1:
        return cy * c - cx * s
    if turn == 2:
        return -(cx * c + cy * s)
    return cx * s - cy * c
'''

_JUNCTION = '''
@numba.njit(cache=True)
def junction_indicator(n, phi, p, offset):
    """The n-th derivative of the arcs' junction indicator at phi (derive.profile.JunctionFunction):
    (-1)^k sin(pi (phi - a_k) / (a_(k+1) - a_k)) on arc k, zero at the junctions.  The sine is
    taken of the distance to the nearer junction (accurate near both), and the value is never
    exactly 0 (the smallest float of the arc's sign): a step never starts on the surface."""
    k, x = _piece(phi, p, offset)
    a = p[offset + 1 + k]
    b = p[offset + 2 + k]
    scale = pi / (b - a)
    if x - a <= b - x:
        value = scale ** n * sin(scale * (x - a) + 0.5 * pi * n)
    else:
        value = (-scale) ** n * sin(scale * (b - x) + 0.5 * pi * n)
    if n == 0 and value <= 0.0:
        value = 5e-324
    return value if k % 2 == 0 else -value
'''

EVALUATORS = {"spline": _SEARCH + _SPLINE, "arcs": _SEARCH + _ARCS + _JUNCTION}


def evaluator_source(family: str) -> str:
    """The text of a family's evaluator (``profile`` and its piece search)."""
    try:
        return EVALUATORS[family].strip("\n")
    except KeyError:
        raise ValueError(f"no profile evaluator for {family!r}: one of {tuple(EVALUATORS)}") from None
