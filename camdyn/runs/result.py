"""The result of a simulation: time histories, regimes, switches, outcome."""
from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field

import numpy as np

from ..engine import Switches
from ..outcome import Outcome
from ..vocabulary import RIGID_OUTPUT


class Outputs(Mapping):
    """A run's output quantities by name, computed on first use, all at once.

    The names are known at once; the values come from ``compute()`` (a dict of arrays) the
    first time one is read.  A run whose outputs nobody reads never compiles the scene's
    ``outputs`` kernel: about a second of a cold start (docs/performance.md, Start-up).
    Pickled (a sweep's worker) or copied, it is the plain dict of its values."""

    def __init__(self, names, compute: Callable[[], dict]):
        self._names = tuple(names)
        self._compute = compute
        self._values: dict | None = None

    def _all(self) -> dict:
        if self._values is None:
            values = self._compute()
            self._values = {name: values[name] for name in self._names}
            self._compute = None  # let go of the model and the samples it held
        return self._values

    def __getitem__(self, name: str) -> np.ndarray:
        if name not in self._names:
            raise KeyError(name)
        return self._all()[name]

    def __contains__(self, name) -> bool:
        return name in self._names

    def __iter__(self) -> Iterator[str]:
        return iter(self._names)

    def __len__(self) -> int:
        return len(self._names)

    def __reduce__(self):
        return dict, (self._all(),)

    def __repr__(self) -> str:
        state = "computed" if self._values is not None else "not computed yet"
        return f"Outputs({', '.join(self._names)}; {state})"


@dataclass
class Result:
    """Time histories of one run (SI units), sampled uniformly at ``t``.

    Arrays: t, the follower's coordinate ``q`` and its rate ``q_dot`` under their names (the
    paper's oscillating follower: alpha, alpha_dot, rad; the translating follower: y, y_dot, m),
    Theta, the coordinate in rigid contact (alpha_i, Eq. 29; y_i) and the residual response
    alpha_r = alpha - alpha_i (Section 4; y_r), psi_i, psi_j, psi_i_dot, F_s, F_n, F_f, v_r, N_x,
    energy, P_in, D_c, D_f, and ``regime`` (the name of the regime active at each sample).
    ``switches`` lists every regime switch (:class:`~camdyn.engine.switches.Switches`: each a
    ``Switch``, the times as ``switches.t``); ``outcome`` says how the run ended (check ``result.ok``).
    ``q_star`` is the coordinate at the static equilibrium (alpha*, y*).
    """

    t: np.ndarray
    q: np.ndarray
    q_dot: np.ndarray
    Theta: np.ndarray
    regime: np.ndarray
    outputs: Mapping[str, np.ndarray]    # a dict, or Outputs (computed when first read)
    switches: Switches
    outcome: Outcome
    stats: dict
    period: float
    scene: str
    q_star: float
    meta: dict = field(default_factory=dict)

    def __getattr__(self, name):
        outputs = self.__dict__.get("outputs", {})
        if name in outputs:
            return outputs[name]
        coordinate = self.__dict__.get("meta", {}).get("coordinate", "alpha")
        if name in _NAMED and _NAMED[name][0] != coordinate:
            raise AttributeError(f"Result has no attribute {name!r}: the follower's coordinate is {coordinate!r} "
                                 f"(result.{coordinate}, or result.q)")
        raise AttributeError(f"Result has no attribute {name!r}")

    def _named(self, name: str):
        """The state quantity ``name`` (alpha, alpha_dot, ... or y, y_dot, ...) where it is this run's."""
        coordinate, attribute = _NAMED[name]
        if self.meta.get("coordinate", "alpha") != coordinate:
            raise AttributeError(name)  # __getattr__ says why
        return attribute(self)

    alpha = property(lambda self: self._named("alpha"), doc="The oscillating follower's angle q (rad).")
    alpha_dot = property(lambda self: self._named("alpha_dot"), doc="Its rate q_dot (rad/s).")
    alpha_star = property(lambda self: self._named("alpha_star"), doc="alpha* (rad), the static equilibrium.")
    alpha_r = property(lambda self: self._named("alpha_r"), doc="alpha - alpha_i, the residual response (Section 4).")
    y = property(lambda self: self._named("y"), doc="The translating follower's position q (m).")
    y_dot = property(lambda self: self._named("y_dot"), doc="Its velocity q_dot (m/s).")
    y_star = property(lambda self: self._named("y_star"), doc="y* (m), the static equilibrium.")
    y_r = property(lambda self: self._named("y_r"), doc="y - y_i, the residual response.")

    @property
    def residual(self) -> np.ndarray:
        """The residual response: the coordinate less its value in rigid contact (alpha_r, y_r)."""
        return self.q - self.outputs[RIGID_OUTPUT[self.meta.get("follower", "oscillating")]]

    @property
    def ok(self) -> bool:
        return self.outcome.ok

    @property
    def in_contact(self) -> np.ndarray:
        """Whether the follower touches the cam at each sample (the generated CONTACT_OF_MODE)."""
        contact = self.meta["contact"]
        return np.array([contact[name] for name in self.regime], dtype=bool)

    def impacts(self) -> np.ndarray:
        """Times at which contact starts (a switch from a free mode to a contact mode), and the rigid
        contact's impacts (a switch whose reset is Newton's impact law, back into free flight: the
        bounce; ``meta["impact_transitions"]``, camdyn.engine.impact_transitions)."""
        before, after = self._contact_across_switches()
        bounce = np.isin(self.switches.records["transition"], self.meta.get("impact_transitions", ()))
        return self.switches.t[(~before & after) | bounce]

    def separations(self) -> np.ndarray:
        """Times at which contact ends."""
        before, after = self._contact_across_switches()
        return self.switches.t[before & ~after]

    def _contact_across_switches(self) -> tuple[np.ndarray, np.ndarray]:
        """Whether the follower touches the cam before and after each switch (CONTACT_OF_MODE)."""
        sw = self.switches
        contact = np.array([self.meta["contact"][name] for name in sw.modes], dtype=bool)
        return contact[sw.before], contact[sw.after]

    def after(self, t0: float) -> "Result":
        """The samples at t >= t0 (e.g. to drop a transient)."""
        keep = self.t >= t0
        return Result(self.t[keep], self.q[keep], self.q_dot[keep], self.Theta[keep],
                      self.regime[keep], {k: v[keep] for k, v in self.outputs.items()},
                      self.switches[self.switches.t >= t0], self.outcome, self.stats,
                      self.period, self.scene, self.q_star, self.meta)

    def summary(self) -> str:
        lines = [f"scene {self.scene}: {self.outcome.name} ({self.outcome.message})",
                 f"  t = {self.t[0]:.6g} .. {self.t[-1]:.6g} s, {self.t.size} samples" if self.t.size else "  no samples",
                 f"  {len(self.switches)} regime switches, {self.impacts().size} impacts, "
                 f"{self.stats.get('steps', 0)} steps, {self.stats.get('nfev', 0)} RHS evaluations"]
        return "\n".join(lines)

#: the state quantities by their names: (the coordinate they belong to, how to read them)
_NAMED = {"alpha": ("alpha", lambda r: r.q), "alpha_dot": ("alpha", lambda r: r.q_dot),
          "alpha_star": ("alpha", lambda r: r.q_star), "alpha_r": ("alpha", lambda r: r.residual),
          "y": ("y", lambda r: r.q), "y_dot": ("y", lambda r: r.q_dot), "y_star": ("y", lambda r: r.q_star),
          "y_r": ("y", lambda r: r.residual)}
