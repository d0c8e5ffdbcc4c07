"""What a calibration gives back: the residual of each target, the degrees of freedom the targets
determine, and the fitted rig (:class:`Calibration`).  The public names are those of
:mod:`camdyn.analysis.calibrate`."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np

from ..model.rig import Rig
from .calibration_problem import Target, Unknown


@dataclass(frozen=True)
class TargetResidual:
    """One target after the fit: computed value, difference, residual in sigmas."""

    name: str
    value: float
    computed: float
    sigma: float
    unit: str
    source: str

    @property
    def difference(self) -> float:
        return self.computed - self.value

    @property
    def relative(self) -> float:
        return self.difference / self.value if self.value else math.nan

    @property
    def normalized(self) -> float:
        """Residual in units of sigma (within the stated uncertainty when its abs() <= 1)."""
        return self.difference / self.sigma

    @property
    def within(self) -> bool:
        return abs(self.normalized) <= 1.0 + 1e-9


@dataclass(frozen=True)
class DegreesOfFreedom:
    """What the targets determine.

    ``rank`` is the numerical rank of the weighted Jacobian d(residual)/d(unknown) at the
    solution: the number of independent combinations of the unknowns the targets pin
    down.  ``unknowns - rank`` combinations are left free by the targets (the fit then
    depends on the initial values: fix more by assumption); ``targets - rank`` targets
    are redundant (consistency checks).  ``fixed`` names the parameters fixed by
    assumption, with the reason; ``tied`` those computed from others.
    """

    targets: int
    unknowns: int
    rank: int
    singular_values: tuple[float, ...]
    fixed: Mapping[str, str]
    tied: tuple[str, ...]
    at_bounds: tuple[str, ...]

    @property
    def free(self) -> int:
        return self.unknowns - self.rank

    @property
    def redundant(self) -> int:
        return self.targets - self.rank

    def statement(self) -> str:
        s = (f"{self.targets} target(s), {self.unknowns} unknown(s); the targets determine {self.rank} "
             f"independent combination(s) of the unknowns")
        if self.free:
            s += f", leaving {self.free} combination(s) undetermined (the fit depends on the initial values)"
        if self.redundant:
            s += f"; {self.redundant} target(s) are redundant and act as consistency checks"
        s += "."
        if self.fixed:
            s += f" {len(self.fixed)} parameter(s) fixed by assumption: " + "; ".join(
                f"{k} ({v})" for k, v in self.fixed.items()) + "."
        if self.tied:
            s += f" Tied to others: {', '.join(self.tied)}."
        if self.at_bounds:
            s += f" At a bound (the bound, not the targets, sets it): {', '.join(self.at_bounds)}."
        return s


@dataclass(frozen=True)
class Calibration:
    """The outcome of :func:`calibrate`."""

    rig: Rig                                  # the fitted rig (base settings)
    values: Mapping[str, float]               # fitted value of every unknown (extras included)
    extras: Mapping[str, float]               # fitted extra unknowns (not rig parameters)
    residuals: tuple[TargetResidual, ...]
    dof: DegreesOfFreedom
    unknowns: tuple[Unknown, ...]
    targets: tuple[Target, ...]
    initial: Mapping[str, float]
    sensitivity: np.ndarray                   # d log(computed) / d log(unknown), targets x unknowns
    success: bool
    message: str
    cost: float
    nfev: int

    def residual(self, name: str) -> TargetResidual:
        for r in self.residuals:
            if r.name == name:
                return r
        raise KeyError(f"no target {name!r}; targets: {[r.name for r in self.residuals]}")

    def variant(self, target_or_settings: str | Mapping[str, Any]) -> Rig:
        """The fitted rig with a target's settings (or the given settings) applied."""
        if isinstance(target_or_settings, str):
            for t in self.targets:
                if t.name == target_or_settings:
                    return t.variant(self.rig, self.extras)
            raise KeyError(f"no target {target_or_settings!r}")
        return Target("settings", 1.0, lambda r: 1.0, settings=dict(target_or_settings)).variant(
            self.rig, self.extras)

    @property
    def all_within(self) -> bool:
        return all(r.within for r in self.residuals)

    def report(self) -> str:
        """A plain-text/Markdown report: unknowns, residual per target, degrees of freedom."""
        lines = ["| unknown | initial | fitted | bounds | scale |", "|---|---|---|---|---|"]
        for u in self.unknowns:
            lines.append(f"| {u.name} | {self.initial[u.name]:.6g} | {self.values[u.name]:.6g} | "
                         f"[{u.lower:.4g}, {u.upper:.4g}] | {'log' if u.log else 'linear'} |")
        lines += ["", "| target | value | computed | relative difference | residual / sigma |",
                  "|---|---|---|---|---|"]
        for r in self.residuals:
            lines.append(f"| {r.name} | {r.value:.6g} {r.unit} | {r.computed:.6g} {r.unit} | "
                         f"{r.relative:+.2e} | {r.normalized:+.3f} |")
        lines += ["", self.dof.statement(), "", f"least squares: {self.message} (cost {self.cost:.3g}, "
                                                  f"{self.nfev} evaluations)"]
        return "\n".join(lines)
