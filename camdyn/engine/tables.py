"""The hybrid automaton of a generated scene module, as the integer tables the loop reads.

A generated module states its automaton as data (``MODES``, ``SURFACES``, ``INITIAL``,
``TRANSITIONS``, ``RESETS``, ``RATE_OF_SURFACE``, ``CONTACT_OF_MODE``, ``TERMINAL_OF_MODE`` where a
mode ends the run, ``TIMED_SURFACES`` where a surface's value is of time alone; see
``camdyn.derive.automaton`` for the rules).  :func:`tables` packs it into :class:`Tables`:
compressed rows, so that mode m's transitions are ``watch_start[m]:watch_start[m + 1]`` and a
transition's candidate targets are ``target_start[w]:target_start[w + 1]``; the initial choice
is the candidate row after the last transition.  Nothing is found by name at run time.

All the tables are one integer array, ``data``, and each field of :class:`Tables` is where its
table starts in it: table ``surface``'s entry w is ``tab.data[tab.surface + w]``.  One array,
not twelve (docs/design-notes.md, *One integer array for the automaton's tables*).
"""
from __future__ import annotations

from functools import lru_cache

from types import ModuleType
from typing import NamedTuple

import numpy as np

from ..vocabulary import FLOWS, TRANSITION_DIRECTION as DIRECTION, TRANSITION_RESET as RESET
from ..vocabulary import TRANSITION_SOURCE as SOURCE, TRANSITION_SURFACE as SURFACE, TRANSITION_TARGETS as TARGETS

#: reset index of the identity (no call to a reset kernel)
IDENTITY = -1


class Tables(NamedTuple):
    data: np.ndarray               # every table below, one after the other (int64)
    mode_contact: int              # per mode: 1 in contact, 0 in free flight
    mode_terminal: int             # per mode: 1 where the run ends on entering it (a bounded face's off_face)
    watch_start: int               # per mode, and one past the end: its transitions (rows)
    surface: int                   # per transition: the surface it watches
    direction: int                 # per transition: +1 (upward crossing) or -1 (downward)
    reset: int                     # per transition: the reset kernel's index, IDENTITY for none
    target_start: int              # per transition, then the initial choice, then the end: candidates
    target_mode: int               # per candidate: the mode entered
    condition_start: int           # per candidate, and the end: its conditions
    condition_surface: int         # per condition: the surface
    condition_sign: int            # per condition: holds where sign * value >= 0
    surface_rate: int              # per surface: the surface that is its time derivative, or -1
    flows: int                     # the outputs integrated by the energy ledger (P_in, D_c, D_f)
    sampled_start: int             # per mode, and one past the end: its sampled surfaces (rows)
    sampled: int                   # per row: a surface mode m samples, once, with its rate if it has one
    surface_timed: int             # per surface: 1 where its value is of time alone (stepped to, rules.time_bound)
    n_modes: int
    n_transitions: int
    n_surfaces: int
    n_outputs: int
    chatter: int = -1              # the impact transition a chatter end replaces (-1: none); its candidates
    chatter_reset: int = IDENTITY  # are the target row n_transitions + 1, its reset this


def tables(K: ModuleType) -> Tables:
    """The tables of a generated scene module ``K``, built once per module (the loop only reads
    them; like the compiled kernels, a module reloaded in place keeps them); a stand-in that is
    not a module (a test's namespace) has them built each call."""
    return _module_tables(K) if isinstance(K, ModuleType) else _tables(K)


@lru_cache(maxsize=None)
def _module_tables(K: ModuleType) -> Tables:
    return _tables(K)


def _tables(K) -> Tables:
    transitions = transition_rows(K)
    n_modes = len(K.MODES)
    chatter = getattr(K, "CHATTER", None)  # the rigid law's chatter end (derive.automaton)
    watch_start = np.searchsorted([tr[SOURCE] for tr in transitions], np.arange(n_modes + 1), side="left")
    target_start, target_mode, condition_start, condition_surface, condition_sign = [0], [], [0], [], []
    rows = [tr[TARGETS] for tr in transitions] + [K.INITIAL] + ([chatter[TARGETS]] if chatter is not None else [])
    for candidates in rows:
        for mode, conditions in candidates:
            target_mode.append(mode)
            for surface, sign in conditions:
                condition_surface.append(surface)
                condition_sign.append(sign)
            condition_start.append(len(condition_surface))
        target_start.append(len(target_mode))
    resets = [IDENTITY if K.RESETS[tr[RESET]] == "identity" else tr[RESET] for tr in transitions]
    sampled_start, sampled = sampled_surfaces(K, transitions, watch_start)
    terminal = getattr(K, "TERMINAL_OF_MODE", (False,) * n_modes)  # declared by a scene that has one
    timed = getattr(K, "TIMED_SURFACES", ())  # likewise
    parts = [K.CONTACT_OF_MODE, terminal, watch_start, [tr[SURFACE] for tr in transitions], [tr[DIRECTION] for tr in transitions],
             resets,
             target_start, target_mode, condition_start, condition_surface, condition_sign, K.RATE_OF_SURFACE,
             [K.OUTPUTS.index(f) for f in FLOWS], sampled_start, sampled, [int(s in timed) for s in range(len(K.SURFACES))]]
    starts = np.cumsum([0] + [len(part) for part in parts])[:-1]
    data = np.ascontiguousarray(np.concatenate([np.asarray(part, dtype=np.int64) for part in parts]), dtype=np.int64)
    replaced, reset = _chatter(K, transitions, chatter)
    return Tables(data, *map(int, starts), n_modes, len(transitions), len(K.SURFACES), len(K.OUTPUTS), replaced, reset)


def _chatter(K, transitions: list[tuple], chatter) -> tuple[int, int]:
    """The index of the transition a chatter end replaces (its source, surface and direction) and the
    chatter end's reset kernel index; (-1, IDENTITY) for a scene without one."""
    if chatter is None:
        return -1, IDENTITY
    key = (chatter[SOURCE], chatter[SURFACE], chatter[DIRECTION])
    replaced = next(w for w, tr in enumerate(transitions) if (tr[SOURCE], tr[SURFACE], tr[DIRECTION]) == key)
    return replaced, IDENTITY if K.RESETS[chatter[RESET]] == "identity" else int(chatter[RESET])


def sampled_surfaces(K: ModuleType, transitions: list[tuple], watch_start) -> tuple[list[int], list[int]]:
    """Per mode, the kernel calls of its crossing check at a sample: the surfaces its transitions
    watch, each once, in the order of first use, where one with a declared rate is evaluated with
    that rate in one call (``surface_with_rate``), and a watched rate already so evaluated is not
    called again (compressed rows: mode m's are ``sampled[sampled_start[m]:sampled_start[m + 1]]``)."""
    start, sampled = [0], []
    for m in range(len(K.MODES)):
        watched = [tr[SURFACE] for tr in transitions[watch_start[m]:watch_start[m + 1]]]
        covered = {K.RATE_OF_SURFACE[s] for s in watched} - {-1}
        mine: list[int] = []
        for s in watched:
            if s not in mine and (s not in covered or K.RATE_OF_SURFACE[s] >= 0):
                mine.append(s)
        sampled += mine
        start.append(len(sampled))
    return start, sampled


def transition_rows(K: ModuleType) -> list[tuple]:
    """The module's transitions in the order of :class:`Tables` (to name a switch's surface)."""
    return sorted(K.TRANSITIONS, key=lambda tr: tr[SOURCE])


@lru_cache(maxsize=None)
def transition_surface_indices(K: ModuleType) -> tuple[int, ...]:
    """The surface (an index into SURFACES) of each row a switch record's ``transition`` names:
    the transitions in the loop's order, then, in a scene with a chatter end, -1 for the initial
    mode's row (n_transitions, never recorded) and the impact's surface for the chatter end's row
    (n_transitions + 1: the impact that ended a chatter, recorded as its own row)."""
    surfaces = [int(row[SURFACE]) for row in transition_rows(K)]
    chatter = getattr(K, "CHATTER", None)
    return tuple(surfaces + ([-1, int(chatter[SURFACE])] if chatter is not None else []))


@lru_cache(maxsize=None)
def impact_transitions(K: ModuleType) -> tuple[int, ...]:
    """The transitions (switch records' ``transition``) whose reset is Newton's impact law (the
    module's RESET_IMPACT: the rigid contact's bounce); none in a scene without it."""
    impact = getattr(K, "RESET_IMPACT", None)
    return tuple(i for i, row in enumerate(transition_rows(K)) if impact is not None and row[RESET] == impact)


def transition_surfaces(K: ModuleType) -> tuple[str, ...]:
    """The name of the surface each transition crosses, by the transition's index (a switch
    record's ``transition``), once per scene module."""
    return tuple(K.SURFACES[s] if s >= 0 else "" for s in transition_surface_indices(K))
