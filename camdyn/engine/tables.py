"""The hybrid automaton of a generated scene module, as the integer tables the loop reads.

A generated module states its automaton as data (``MODES``, ``SURFACES``, ``INITIAL``,
``TRANSITIONS``, ``RESETS``, ``RATE_OF_SURFACE``, ``CONTACT_OF_MODE``; see
``camdyn.derive.automaton`` for the rules).  :func:`tables` packs it into :class:`Tables`:
compressed rows, so that mode m's transitions are ``watch_start[m]:watch_start[m + 1]`` and a
transition's candidate targets are ``target_start[w]:target_start[w + 1]``; the initial choice
is the candidate row after the last transition.  Nothing is found by name at run time.
"""
from __future__ import annotations

from types import ModuleType
from typing import NamedTuple

import numpy as np

from ..derive.vocabulary import FLOWS

#: reset index of the identity (no call to a reset kernel)
IDENTITY = -1


class Tables(NamedTuple):
    mode_contact: np.ndarray       # per mode: 1 in contact, 0 in free flight
    watch_start: np.ndarray        # per mode, and one past the end: its transitions (rows)
    surface: np.ndarray            # per transition: the surface it watches
    direction: np.ndarray          # per transition: +1 (upward crossing) or -1 (downward)
    reset: np.ndarray              # per transition: the reset kernel's index, IDENTITY for none
    target_start: np.ndarray       # per transition, then the initial choice, then the end: candidates
    target_mode: np.ndarray        # per candidate: the mode entered
    condition_start: np.ndarray    # per candidate, and the end: its conditions
    condition_surface: np.ndarray  # per condition: the surface
    condition_sign: np.ndarray     # per condition: holds where sign * value >= 0
    surface_rate: np.ndarray       # per surface: the surface that is its time derivative, or -1
    flows: np.ndarray              # the outputs integrated by the energy ledger (P_in, D_c, D_f)
    n_outputs: int


def _int(values) -> np.ndarray:
    return np.ascontiguousarray(values, dtype=np.int64)


def tables(K: ModuleType) -> Tables:
    """The tables of a generated scene module ``K``."""
    transitions = sorted(K.TRANSITIONS, key=lambda tr: tr[0])  # grouped by source, order kept
    n_modes = len(K.MODES)
    watch_start = np.searchsorted([tr[0] for tr in transitions], np.arange(n_modes + 1), side="left")
    target_start, target_mode, condition_start, condition_surface, condition_sign = [0], [], [0], [], []
    for candidates in [tr[3] for tr in transitions] + [K.INITIAL]:
        for mode, conditions in candidates:
            target_mode.append(mode)
            for surface, sign in conditions:
                condition_surface.append(surface)
                condition_sign.append(sign)
            condition_start.append(len(condition_surface))
        target_start.append(len(target_mode))
    resets = [IDENTITY if K.RESETS[tr[4]] == "identity" else tr[4] for tr in transitions]
    return Tables(_int(K.CONTACT_OF_MODE), _int(watch_start), _int([tr[1] for tr in transitions]),
                  _int([tr[2] for tr in transitions]), _int(resets), _int(target_start), _int(target_mode),
                  _int(condition_start), _int(condition_surface), _int(condition_sign),
                  _int(K.RATE_OF_SURFACE), _int([K.OUTPUTS.index(f) for f in FLOWS]), len(K.OUTPUTS))


def transition_rows(K: ModuleType) -> list[tuple]:
    """The module's transitions in the order of :class:`Tables` (to name a switch's surface)."""
    return sorted(K.TRANSITIONS, key=lambda tr: tr[0])
