"""Measures that misbehave at one cam speed, and an executor that is interrupted, for the
sweep's fault tests.

They live in a module of their own (not a test file) so that worker processes, forked or
spawned (dask), can import them by name.  Away from the chosen speed each is ``Summary(1)``,
so a sweep that recovers gives the values of a plain ``Summary(1)`` sweep.
"""
from __future__ import annotations

import ctypes
import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

from camdyn.sweep.api import Summary


@dataclass(frozen=True)
class Faulty:
    """At ``speed_rpm``: ``"raise"`` a ValueError; ``"exit"`` kill the worker process
    (os._exit) every time; ``"exit_once"`` kill it only the first time (it writes the marker
    file); ``"exit_unless"`` kill it every time until someone writes the marker file; ``"mark"``
    write the marker file (the point was measured) and go on."""

    speed_rpm: float
    action: str
    marker: str = ""
    inner: Summary = field(default_factory=lambda: Summary(1))

    def __call__(self, result):
        if result.meta["cam"].speed_rpm == self.speed_rpm:
            if self.action == "raise":
                raise ValueError(f"this measure fails at {self.speed_rpm} rev/min")
            if self.action == "mark":
                Path(self.marker).write_text("measured")
            fixed = bool(self.marker) and Path(self.marker).exists()
            if self.action == "exit" or (self.action in ("exit_once", "exit_unless") and not fixed):
                if self.action == "exit_once":
                    Path(self.marker).write_text(str(os.getpid()))
                os._exit(17)
        return self.inner(result)


@dataclass(frozen=True)
class WithDeathSignal(Faulty):
    """:class:`Faulty`, and ``death_signal``: the signal the worker that measured the point gets
    when its parent dies (Linux ``prctl(PR_GET_PDEATHSIG)``; 0: none)."""

    def __call__(self, result):
        values = super().__call__(result)
        signal = ctypes.c_int(0)
        ctypes.CDLL(None).prctl(2, ctypes.byref(signal), 0, 0, 0)  # PR_GET_PDEATHSIG
        return {**values, "death_signal": float(signal.value)}


class InterruptAfter(ThreadPoolExecutor):
    """One worker thread; Ctrl-C lands in the sweep's loop when it submits task number ``n + 1``."""

    def __init__(self, n: int):
        super().__init__(1)
        self.n = n

    def submit(self, *args, **kwargs):
        if self.n == 0:
            raise KeyboardInterrupt
        self.n -= 1
        return super().submit(*args, **kwargs)
