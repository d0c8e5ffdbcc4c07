"""The engine's settings: validated options for users, named tuples for the loop.

Users set :class:`SolverOptions` (method, tolerances, :class:`EventSettings`, the energy
ledger); the driver turns them, with the rules' own constants below, into a :class:`Settings`
named tuple that crosses into compiled code as it is (named fields, no positional arrays).

The constants of the hybrid rules are defined here, once, whatever runs the loop.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from ..errors import ParameterError
from .._checks import integer, real
from .tableau import TABLEAUS

_EPS = float(np.finfo(float).eps)


class StepControl(NamedTuple):
    """A step-size controller as data: after an accepted attempt the next step is the accepted
    one times SAFETY err^(-a/k) err_prev^(b/k), k the error estimate's order + 1 (the method's
    exponent is -1/k) and err_prev the previous accepted attempt's error
    (:func:`camdyn.engine.stepper.accepted_factor`)."""

    name: str
    a: float
    b: float


#: SciPy's integral controller (the accepted step's error alone: the steps are ``solve_ivp``'s)
SCIPY_CONTROL = StepControl("scipy", 1.0, 0.0)
#: the proportional-integral controller (Gustafsson, ACM TOMS 17, 1991; Hairer & Wanner, Solving
#: ODEs II, Sec. IV.2), which also reads the previous accepted step's error and so damps the growth
#: after a step whose estimate dipped
PI_CONTROL = StepControl("pi", 0.7, 0.4)
#: the controllers by name (the names SolverOptions accepts besides the objects)
CONTROLS = {c.name: c for c in (SCIPY_CONTROL, PI_CONTROL)}

#: this many switches within CHATTER_WINDOW (relative) of time is chatter, not dynamics
CHATTER_SWITCHES = 20
CHATTER_WINDOW = 1e-9
#: steps in a row that may end short of a crossing their interpolant placed early, when one step
#: of the method to the located time is not yet across the surface (then the interpolant's state,
#: across by construction, is taken); with 100, tests/test_bad_input.py ran for over 10 minutes
CROSSING_RETRIES = 1
#: the first step after contact starts is at most this many radians of the contact mode
#: (a free-flight step size would blow up on the stiff contact)
CONTACT_STEP_RADIANS = 0.1
#: exactly on a surface, the side is read this long (relative) later along the motion
LOOK_AHEAD = 1e-9
#: a watched surface is out of reach of zero over a span of time T when |value| > this * |rate| * T
#: at both ends (EventSettings.reach_factor): 2 lets the rate inside the span reach twice its
#: values at the ends
REACH_FACTOR = 2.0
#: |alpha| beyond this is the singular 90 degrees of Eq. 11 (tan, sec)
ANGLE_LIMIT = math.pi / 2 - 0.02
METHODS = tuple(TABLEAUS)
#: the step-size controller by default (a StepControl): the PI controller, which at equal
#: error takes less time than SciPy's on the contact ring-downs of docs/performance.md (fewer
#: rejected attempts where DOP853's error estimate jumps with the vibration's phase)
STEP_CONTROL = PI_CONTROL
#: who runs the loop: numba-compiled (cfunc kernels, cached on disk) or the same code in Python
BACKENDS = ("compiled", "python")


def step_control(value) -> StepControl:
    """A step-size controller: a :class:`~camdyn.engine.stepper.StepControl` as it is, or one by
    its name (``"pi"``, ``"scipy"``)."""
    if isinstance(value, StepControl):
        return value
    if isinstance(value, str) and value in CONTROLS:
        return CONTROLS[value]
    raise ParameterError("step_control", value, f"a camdyn.engine.StepControl or one of {tuple(CONTROLS)} "
                         "(SciPy's integral controller, or the proportional-integral one)")


@dataclass(frozen=True)
class EventSettings:
    """Tolerances of event location.

    ``xtol``: relative time tolerance of a located switch, ``|t_found - t_root| <= xtol *
    max(1, |t|)``; ``4 eps <= xtol < 1``.  ``interior_points``: equally spaced samples of each
    watched surface inside every step besides its ends, so that an excursion out and back
    within one step (a micro-hop) is still seen when a sample falls inside it; ``>= 0``.
    ``max_events``: the most regime switches one run may have; ``>= 1``.

    ``reach_factor``: the interior samples are taken only in a step where some watched surface
    may reach zero, and an excursion's extremum is located only where it may: a surface of value
    g moving at rate r at both ends of a span of time T is out of reach when ``|g| >
    reach_factor * |r| * T`` at both (with a rate that stays between its values at the ends, 1
    would be exact; the factor allows the rate to overshoot them); ``>= 1``, ``math.inf`` to
    sample every step (camdyn.engine.rules, *Reach*).
    """

    xtol: float = 1e-14
    interior_points: int = 3
    max_events: int = 1_000_000
    reach_factor: float = REACH_FACTOR

    def __post_init__(self) -> None:
        real("xtol", self.xtol, f"4*eps = {4 * _EPS:.3g} <= xtol < 1", lambda v: 4 * _EPS <= v < 1)
        for name, low in (("interior_points", 0), ("max_events", 1)):
            integer(name, getattr(self, name), f"an integer >= {low}", lambda n: n >= low)
        real("reach_factor", self.reach_factor, "a number >= 1 (math.inf: interior samples in every step)",
             lambda v: v >= 1)


@dataclass(frozen=True)
class SolverOptions:
    """Method and tolerances of a run (rtol, atol as in ``scipy.integrate.solve_ivp``)."""

    method: str = "DOP853"
    rtol: float = 1e-8
    atol: float = 1e-12
    max_step: float = math.inf
    events: EventSettings = field(default_factory=EventSettings)
    ledger: bool = False   # integrate the work of the drive, contact damping and friction
    step_control: StepControl = STEP_CONTROL   # a StepControl, or its name ("pi", "scipy")

    def __post_init__(self):
        if self.method not in METHODS:
            raise ParameterError("method", self.method, f"one of {METHODS} (explicit Runge-Kutta pairs with "
                                 "dense output; implicit methods do not pay on this model: docs/performance.md)")
        real("rtol", self.rtol, "1e-14 <= rtol <= 1e-2", lambda v: 1e-14 <= v <= 1e-2)
        real("atol", self.atol, "0 < atol <= 1e-2", lambda v: 0 < v <= 1e-2)
        real("max_step", self.max_step, "max_step > 0 (s)", lambda v: v > 0)
        if not isinstance(self.events, EventSettings):
            raise ParameterError("events", self.events, "an EventSettings")
        object.__setattr__(self, "step_control", step_control(self.step_control))


#: the tolerances of the periodic analyses (the stroboscopic map, shooting, continuation, tangent
#: dynamics, Lyapunov exponents): their Newton tolerance and finite-difference steps are chosen
#: from them (camdyn.orbits.shooting, camdyn.orbits.derivatives); the command line's default for them too
MAP_OPTIONS = SolverOptions(rtol=1e-10, atol=1e-13)


class Settings(NamedTuple):
    """Everything the loop reads besides the model and the method (see :func:`settings`)."""

    rtol: float
    atol: float
    max_step: float
    control_a: float        # the step-size controller's coefficients (StepControl.a, .b)
    control_b: float
    xtol: float
    interior_points: int
    reach_factor: float
    max_events: int
    angle_limit: float
    chatter_switches: int
    chatter_window: float
    contact_step: float     # s; 0 for no cap
    crossing_retries: int
    look_ahead: float
    ledger: bool


def settings(options: SolverOptions, contact_frequency: float, coordinate_limit: float = ANGLE_LIMIT,
             step_cap: float = math.inf) -> Settings:
    """The loop's settings for ``options`` on a model whose contact mode has ``contact_frequency``
    (rad/s: the undamped linearized frequency vartheta, Eq. 23) and whose follower's coordinate must
    stay within +-``coordinate_limit`` (the model's ``coordinate_limit``: ANGLE_LIMIT for the paper's
    follower, where Eq. 11 is singular at 90 degrees; inf for a coordinate without a singularity), its
    steps no longer than ``step_cap`` (s; the model's ``step_cap``) nor ``options.max_step``."""
    ev = options.events
    step = CONTACT_STEP_RADIANS / contact_frequency if contact_frequency > 0 else 0.0
    a, b = options.step_control.a, options.step_control.b
    return Settings(rtol=float(options.rtol), atol=float(options.atol), max_step=float(min(options.max_step, step_cap)),
                    control_a=a, control_b=b, xtol=float(ev.xtol), interior_points=int(ev.interior_points),
                    reach_factor=float(ev.reach_factor), max_events=int(ev.max_events), angle_limit=float(coordinate_limit),
                    chatter_switches=CHATTER_SWITCHES, chatter_window=CHATTER_WINDOW, contact_step=step,
                    crossing_retries=CROSSING_RETRIES, look_ahead=LOOK_AHEAD, ledger=bool(options.ledger))
