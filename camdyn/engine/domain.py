"""A scene's modes seen from a state, by the automaton's own rules (:mod:`.rules`), for callers
outside the loop: which mode a run from a state starts in, and whether a state lies inside a
given mode's domain (the side of every surface the mode watches that the mode is valid on)."""
from __future__ import annotations

import numpy as np

from .config import LOOK_AHEAD
from .kernels import python_kernels
from .problem import Problem
from .rules import across, initial_mode
from .tables import tables


class Domain:
    """The modes of ``model``'s scene, read from states (the Python kernels, as the rules run
    in :func:`camdyn.engine.integrate`'s python backend)."""

    def __init__(self, model):
        K = model.kernels
        self.modes, self.surfaces = tuple(K.MODES), tuple(K.SURFACES)
        self._problem = Problem(python_kernels(K), tables(K), np.ascontiguousarray(model.p, dtype=float))
        self._bounds = [_bounding(self._problem.tables, m) for m in range(len(self.modes))]

    def initial_mode(self, t: float, alpha: float, alpha_dot: float) -> int:
        """The mode a run from (t, alpha, alpha_dot) starts in: the automaton's initial rule
        (looked ahead along the motion where a surface's value is exactly 0)."""
        return int(initial_mode(self._problem, float(t), float(alpha), float(alpha_dot), LOOK_AHEAD))

    def surface_crossed(self, mode: int, t: float, alpha: float, alpha_dot: float) -> int:
        """The first surface that bounds ``mode`` (:func:`_bounding`) whose far side (in its
        transition's direction) the state is on, or on it: outside the mode's domain; -1 inside it."""
        tab = self._problem.tables
        for w in self._bounds[mode]:
            if across(self._problem, mode, w, float(t), float(alpha), float(alpha_dot)):
                return int(tab.data[tab.surface + w])
        return -1


def _bounding(tab, mode: int) -> tuple[int, ...]:
    """The transitions of ``mode`` whose surfaces bound its domain: those it watches, less a
    surface it watches in both directions (a cam of arcs' junction indicator, whose sign
    alternates from arc to arc: a restart of the mode, not a side of its domain; every state is
    on the far side of one of its two transitions)."""
    watched = range(tab.data[tab.watch_start + mode], tab.data[tab.watch_start + mode + 1])
    surfaces = [int(tab.data[tab.surface + w]) for w in watched]
    return tuple(w for w, surface in zip(watched, surfaces) if surfaces.count(surface) == 1)
