"""The saltation matrix of a switch: how a perturbation of the state crosses a switching surface.

Between switches a perturbation dx of the state x = (alpha, alpha_dot) follows the variational
equation dx' = J(t, x) dx of the mode's field f = (alpha_dot, alpha_ddot).  At a switch from
mode m- to m+ on the surface h(t, x) = 0 (the identity reset of this model: the state is
continuous), a perturbed trajectory reaches the surface earlier or later by
dt = -grad_h . dx / (grad_h . f- + dh/dt), and spends that time under the other field, so

    dx+ = S dx-,   S = I + (f+ - f-) grad_h^T / (grad_h . f- + dh/dt)

(Aizerman & Gantmakher 1958; Leine & Nijmeijer 2004, Sec. 3.5; di Bernardo et al. 2008,
Sec. 2.5), with f- the field of the mode before and f+ the field of the mode after, both at
the switching state, and grad_h, dh/dt the gradient of the surface's value under the mode
before's laws (the generated ``surface_gradient`` kernel, in the scene's companion module of
variational kernels).  The same formula covers the entry into the Filippov sliding mode of a
stuck follower (f+ = the stick field, which keeps h = v_r at 0: then grad_h^T S = 0, the
perturbation is projected onto the surface) and the exit from it (f+ = f- where the one-sided
field turns away: S = I).

Why it is assembled at run time, not generated: the target mode of a transition is chosen at
run time among candidates (``derive.automaton``: the first whose conditions hold), so the pair
(f-, f+) is known only at the switch.  The symbolic, generated parts are the fields (``rhs``)
and the surface gradients (``surface_gradient``); this module only combines them.
"""
from __future__ import annotations

import numpy as np

from ..vocabulary import GRAD_D_ALPHA, GRAD_D_ALPHA_DOT, GRAD_D_T, STATE_ALPHA, STATE_ALPHA_DOT
from .tables import transition_surface_indices


def saltation_matrix(f_before, f_after, gradient) -> np.ndarray:
    """S = I + (f+ - f-) grad_h^T / (grad_h . f- + dh/dt) (see the module docstring).

    ``f_before``, ``f_after``: the fields (alpha_dot, alpha_ddot) of the modes before and after
    at the switching state; ``gradient``: (dh/dalpha, dh/dalpha_dot, dh/dt) in the order of
    ``SURFACE_GRADIENT``.  A grazing switch (denominator 0) gives a non-finite S."""
    f_before, f_after = np.asarray(f_before, dtype=float), np.asarray(f_after, dtype=float)
    g = np.array([gradient[GRAD_D_ALPHA], gradient[GRAD_D_ALPHA_DOT]], dtype=float)
    rate = float(g @ f_before + gradient[GRAD_D_T])
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.eye(2) + np.outer(f_after - f_before, g) / rate


def switch_saltation(model, before: int, after: int, surface: int, t: float, x) -> np.ndarray:
    """The saltation matrix of a switch of ``model`` (a :class:`camdyn.Model`) from mode
    ``before`` to mode ``after`` across ``surface`` at time t and state x (indices into the
    scene's MODES and SURFACES)."""
    a, ad = float(x[STATE_ALPHA]), float(x[STATE_ALPHA_DOT])
    f_before = (ad, model.rhs(before, t, a, ad))
    f_after = (ad, model.rhs(after, t, a, ad))
    return saltation_matrix(f_before, f_after, model.surface_gradient(before, surface, t, a, ad))


def record_saltation(model, record) -> tuple[np.ndarray, int]:
    """The saltation matrix of one of a run's switches (a record of
    :attr:`camdyn.engine.Switches.records`) and the index of the surface it crossed."""
    surface = transition_surface_indices(model.kernels)[int(record["transition"])]
    x = (float(record["alpha"]), float(record["alpha_dot"]))
    return switch_saltation(model, int(record["before"]), int(record["after"]), surface, float(record["t"]), x), surface
