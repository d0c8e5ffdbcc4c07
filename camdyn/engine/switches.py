"""The switches of a run: the engine's records, read as :class:`Switch` objects on demand.

The loop returns its switches as records (:data:`~camdyn.engine.loop.SWITCH`: time, transition,
modes before and after by index, the state the run continued from).  :class:`Switches` keeps
them as that array and names them (the surface of each transition, the modes) only when one is
read.  A long impacting run has a switch per impact and per law change, thousands per second
of motion: building a Python object for each, and again for each piece of a run joined from
pieces, was a fifth of a bifurcation sweep's time (docs/performance.md), spent on switches no
sweep reads.  Shifting, joining and selecting work on the array.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .loop import SWITCH


@dataclass(frozen=True)
class Switch:
    """One switch of mode: when, which surface was crossed, the modes before and after, and the
    state the run continued from: the follower's coordinate and its rate, in the fields ``alpha``
    and ``alpha_dot`` whatever the follower (the translating follower's y, m, and y_dot, m/s)."""

    t: float
    surface: str
    before: str
    after: str
    alpha: float
    alpha_dot: float


class Switches(Sequence):
    """A run's switches in time order: a sequence of :class:`Switch`, held as ``records`` (an
    array of :data:`~camdyn.engine.loop.SWITCH`) with the names to read them by: ``surfaces``,
    the surface of each transition (by the transition's index), and ``modes``, the scene's MODES.

    Indexing by an integer gives a :class:`Switch`, by a slice or a boolean mask another
    ``Switches``; ``t``, ``before`` and ``after`` are the columns as arrays (modes by index)."""

    __slots__ = ("records", "surfaces", "modes")

    def __init__(self, records: np.ndarray, surfaces: tuple[str, ...], modes: tuple[str, ...]):
        if records.dtype != SWITCH:
            raise TypeError(f"switch records must be of dtype loop.SWITCH, got {records.dtype}")
        self.records, self.surfaces, self.modes = records, tuple(surfaces), tuple(modes)

    @classmethod
    def none(cls, surfaces: tuple[str, ...] = (), modes: tuple[str, ...] = ()) -> "Switches":
        """No switches (a run without any, or without integration)."""
        return cls(np.empty(0, dtype=SWITCH), surfaces, modes)

    def __len__(self) -> int:
        return int(self.records.size)

    def __getitem__(self, key):
        if isinstance(key, (int, np.integer)):
            return self._switch(self.records[key])
        return Switches(np.atleast_1d(self.records[key]), self.surfaces, self.modes)

    def __iter__(self):
        r = self.records
        columns = zip(*(r[name].tolist() for name in SWITCH.names))   # by column (docs/design-notes.md)
        for t, w, b, a, x, v in columns:
            yield Switch(t, self.surfaces[w], self.modes[b], self.modes[a], x, v)

    def _switch(self, rec) -> Switch:
        return Switch(float(rec["t"]), self.surfaces[int(rec["transition"])], self.modes[int(rec["before"])],
                      self.modes[int(rec["after"])], float(rec["alpha"]), float(rec["alpha_dot"]))

    def __eq__(self, other) -> bool:
        if isinstance(other, Switches):
            return (self.surfaces, self.modes) == (other.surfaces, other.modes) and \
                np.array_equal(self.records, other.records)
        return list(self) == list(other) if isinstance(other, Sequence) else NotImplemented

    __hash__ = None

    def __repr__(self) -> str:
        return f"Switches({len(self)} switches)"

    @property
    def t(self) -> np.ndarray:
        return self.records["t"]

    @property
    def before(self) -> np.ndarray:
        """The mode before each switch (an index into ``modes``)."""
        return self.records["before"]

    @property
    def after(self) -> np.ndarray:
        """The mode after each switch (an index into ``modes``)."""
        return self.records["after"]

    @property
    def surface(self) -> np.ndarray:
        """The surface each switch crossed, by name (from its transition)."""
        return np.array([self.surfaces[int(w)] for w in self.records["transition"]], dtype=object)

    def shifted(self, dt: float) -> "Switches":
        """The same switches ``dt`` later (a piece of a run put in absolute time)."""
        out = self.records.copy()
        out["t"] += dt
        return Switches(out, self.surfaces, self.modes)

    def repeated(self, cycle: float, count: int) -> "Switches":
        """These switches ``count`` times more, the k-th copy k ``cycle`` later (k = 1..count):
        the switches of a periodic run continued by whole cycles."""
        out = np.tile(self.records, count)
        out["t"] += np.repeat(cycle * np.arange(1, count + 1), self.records.size)
        return Switches(out, self.surfaces, self.modes)

    @staticmethod
    def joined(parts: Sequence["Switches"]) -> "Switches":
        """The switches of consecutive parts of one run, in order (parts of one scene)."""
        first = parts[0]
        return Switches(np.concatenate([p.records for p in parts]), first.surfaces, first.modes)
