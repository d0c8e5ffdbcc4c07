"""The model's constants, declared once: name, SI unit, meaning, equation, valid range.

Standard library only (no SymPy), like :mod:`camdyn.vocabulary`: the derivation makes
its SymPy symbols from these rows (:mod:`camdyn.derive.symbols`: a lower bound of 0 becomes
the ``positive`` or ``nonnegative`` assumption), and the runtime's :class:`camdyn.Rig` reads
them for its fields, its validation, its error messages, its TOML files and its documentation.
A model edit that adds a constant (a cubic spring coefficient, say) adds a row to
:data:`RIG_PARAMETERS`, with the value that gives the paper's law back (``neutral=``), and
uses the symbol in a law; nothing in ``camdyn/`` changes.

Three groups:

- :data:`RIG_PARAMETERS`: what a rig gives (Sec. 3, Fig. 1); the "0-state" is the follower
  just touching the cam at Theta = theta0, alpha = alpha0;
- :data:`EQUILIBRIUM_QUANTITIES`: computed by the runtime from the rig before a run;
- :data:`CAM_CONSTANTS`: the constants of the cam motion.
"""
from __future__ import annotations

import math
import operator
from dataclasses import dataclass
from typing import Union

__all__ = ["Rule", "Constant", "RigParameter", "FOLLOWER_TYPES", "RIG_PARAMETERS", "EQUILIBRIUM_QUANTITIES", "CAM_CONSTANTS",
           "RIG_NAMES", "EQUILIBRIUM_NAMES", "CAM_NAMES"]

#: the comparisons a rule may make; ``abs<``: |x| < bound, ``abs<=``: |x| <= bound
OPERATORS = (">", ">=", "<", "<=", "abs<", "abs<=")
_COMPARE = {">": operator.gt, ">=": operator.ge, "<": operator.lt, "<=": operator.le}


@dataclass(frozen=True)
class Rule:
    """One condition on a parameter's value: ``x <op> bound``.

    ``bound`` is a number, or the name of a parameter declared before this one (``e < r_c``);
    ``shown`` writes the bound for people (``"pi/2 - 0.05"``) where the number would not say
    it; ``hint`` explains a failure; ``guard`` marks a unit-plausibility check (a cam radius of
    50 m was meant as 50 mm), not a physical range.
    """

    op: str
    bound: Union[float, str]
    hint: str = ""
    guard: bool = False
    shown: str = ""

    def __post_init__(self):
        if self.op not in OPERATORS:
            raise ValueError(f"Rule op {self.op!r} is not one of {OPERATORS}")

    @property
    def text(self) -> str:
        """What the value must be, e.g. ``"> 0"``, ``"< r_c"``, ``"in (-pi/2, pi/2)"``."""
        b = self.shown or (self.bound if isinstance(self.bound, str) else f"{self.bound:g}")
        if self.op.startswith("abs"):
            low = f"-({b})" if " - " in b or " + " in b else f"-{b}"
            return f"in ({low}, {b})" if self.op == "abs<" else f"in [{low}, {b}]"
        return f"{self.op} {b}"

    def holds(self, x: float, known: dict) -> bool:
        """Whether ``x`` satisfies the rule; ``known``: the parameters validated before it."""
        b = known[self.bound] if isinstance(self.bound, str) else self.bound
        if b is None:  # an optional bound not given: a scene that reads both demands it (Rig.require)
            return True
        compare = _COMPARE[self.op.removeprefix("abs")]
        return compare(abs(x) if self.op.startswith("abs") else x, b)


@dataclass(frozen=True)
class Constant:
    """A constant of the model that the rig does not give (an equilibrium result, a cam constant)."""

    name: str
    unit: str
    description: str
    sign: str = ""  # "positive", "nonnegative" or "": the SymPy assumption of its symbol


@dataclass(frozen=True)
class RigParameter:
    """One rig parameter: ``required`` ones every scene reads; the others (None: not given)
    only the scenes whose laws use them, which demand them by name.

    ``follower``: the follower type the parameter belongs to (``"oscillating"``: the paper's
    rocker, ``"translating"``: the flat face on a guide), or ``""`` for both; ``required`` holds
    for the rigs of that type, and a rig of the other type may not give it.

    ``neutral``: for a constant that a model edit adds to one of the paper's laws (a cubic
    spring coefficient), the value that reduces the law to the paper's (0 for an added term).
    ``camdyn regenerate`` writes it into the shipped rig files that lack the parameter, and
    says so; a rig that does not give the parameter is still refused by the scenes that read
    it (the message names this value), so no rig runs an edited law on a value it never gave.
    """

    name: str
    unit: str
    description: str
    required: bool
    ref: str
    rules: tuple[Rule, ...] = ()
    neutral: Union[float, None] = None
    follower: str = ""

    def __post_init__(self):
        if self.neutral is not None and self.required:
            raise ValueError(f"RigParameter {self.name!r}: a neutral value is for an optional parameter "
                             "(a required one is in every rig file)")
        broken = [r.text for r in self.rules if self.neutral is not None and not isinstance(r.bound, str)
                  and not r.holds(self.neutral, {})]
        if broken:
            raise ValueError(f"RigParameter {self.name!r}: its neutral value {self.neutral!r} must be {broken[0]}")
        if self.follower not in ("",) + FOLLOWER_TYPES:
            raise ValueError(f"RigParameter {self.name!r}: follower {self.follower!r} is not '' or one of "
                             f"{FOLLOWER_TYPES}")

    def required_for(self, follower: str) -> bool:
        """Whether a rig of the follower type ``follower`` must give the parameter."""
        return self.required and self.follower in ("", follower)

    def belongs_to(self, follower: str) -> bool:
        """Whether a rig of the follower type ``follower`` may give the parameter."""
        return self.follower in ("", follower)

    @property
    def sign(self) -> str:
        """``"positive"``, ``"nonnegative"`` or ``""``: the sign its physical rules give (the
        SymPy assumption of its symbol)."""
        for r in self.rules:
            if not r.guard and r.bound == 0 and r.op in (">", ">="):
                return "positive" if r.op == ">" else "nonnegative"
        return ""


#: the follower types (camdyn.vocabulary.scenes.FOLLOWERS: the scene option that derives each)
FOLLOWER_TYPES = ("oscillating", "translating")
_OSC, _TRANS = FOLLOWER_TYPES

_MM = "given in mm? camdyn uses SI metres"
_DEGREES = "given in degrees? camdyn uses radians"
_POSITIVE = Rule(">", 0.0)
_NON_NEGATIVE = Rule(">=", 0.0)
_LENGTH = (_POSITIVE, Rule("<=", 10.0, _MM, guard=True))
_MODULUS = (_POSITIVE, Rule(">=", 1e6, "given in GPa or MPa? camdyn uses SI pascals", guard=True))
_POISSON = (_NON_NEGATIVE, Rule("<", 0.5))
_HALF_PI = math.pi / 2

#: every parameter of a rig, in the order of its TOML files and of camdyn.Rig's fields
RIG_PARAMETERS: tuple[RigParameter, ...] = (
    # required: the geometry (Eqs. 1-5), the spring (Eq. 11), the follower (Eq. 10), the materials (Eq. 14)
    RigParameter("r_c", "m", "cam radius", True, "Eq. 4", _LENGTH),
    RigParameter("e", "m", "cam eccentricity, distance from the cam pivot E to the cam centre", True, "Eq. 3", (
        _NON_NEGATIVE, Rule("<", "r_c", "the cam pivot E must lie inside the cam disk"))),
    RigParameter("w_b", "m", "follower bar width", True, "Eq. 2", _LENGTH, follower=_OSC),
    RigParameter("chi0", "m", "distance from the follower pivot P to the contact along the bar in the 0-state",
                 True, "Eq. 2, 5", _LENGTH, follower=_OSC),
    RigParameter("alpha0", "rad", "follower angle from the horizontal, clockwise, in the 0-state", True, "Eq. 5", (
        Rule("abs<=", _HALF_PI, _DEGREES, guard=True, shown="pi/2"),
        Rule("abs<", _HALF_PI - 0.05, "tan and sec in Eq. 11 blow up near 90 degrees", shown="pi/2 - 0.05")), follower=_OSC),
    RigParameter("theta0", "rad", "cam angle in the 0-state, counter-clockwise from the horizontal", True, "Eq. 5", (
        Rule("abs<=", 2 * math.pi, _DEGREES, guard=True, shown="2 pi"),)),
    RigParameter("d_x", "m", "horizontal distance from the follower pivot P to the spring", True, "Eq. 10, 11",
                 _LENGTH, follower=_OSC),
    RigParameter("d_y", "m", "height of the follower pivot P above the ground", True, "Eq. 11", (
        Rule("abs<=", 10.0, _MM, guard=True),), follower=_OSC),
    RigParameter("L_us", "m", "free length of the follower spring", True, "Eq. 11", _LENGTH, follower=_OSC),
    RigParameter("k_s", "N/m", "follower spring stiffness", True, "Eq. 11", (_POSITIVE,)),
    RigParameter("I_Pb", "kg m^2", "moment of inertia of the follower about its pivot P", True, "Eq. 10", (
        _POSITIVE, Rule(">=", 1e-9, "given in g mm^2 or kg mm^2? camdyn uses SI kg m^2 (a follower lighter "
                                    "than 1e-9 kg m^2 has a contact mode too fast to integrate)", guard=True)), follower=_OSC),
    RigParameter("Y_c", "Pa", "Young's modulus of the cam", True, "Eq. 14", _MODULUS),
    RigParameter("Y_b", "Pa", "Young's modulus of the follower", True, "Eq. 14", _MODULUS),
    RigParameter("nu_c", "1", "Poisson's ratio of the cam", True, "Eq. 14", _POISSON),
    RigParameter("nu_b", "1", "Poisson's ratio of the follower", True, "Eq. 14", _POISSON),
    # the translating follower (Scene(follower="translating"), derive.translating): required for its rigs
    RigParameter("m_f", "kg", "mass of the translating follower (its parts that move along the guide)", True,
                 "translating follower", (_POSITIVE, Rule(">=", 1e-6, "given in g? camdyn uses SI kg", guard=True)),
                 follower=_TRANS),
    RigParameter("gamma", "rad", "angle of the translating follower's guide from the horizontal, counter-clockwise "
                 "(pi/2: the follower above the cam); its face is normal to the guide", True, "translating follower",
                 (Rule("abs<=", 2 * math.pi, _DEGREES, guard=True, shown="2 pi"),), follower=_TRANS),
    RigParameter("offset", "m", "offset of the translating follower's guide axis from the cam's centre E, along "
                 "its face", True, "translating follower", (Rule("abs<=", 10.0, _MM, guard=True),), follower=_TRANS),
    RigParameter("F_p", "N", "spring force on the translating follower in the 0-state (its face touching the cam "
                 "at theta0): the preload there", True, "translating follower", (_POSITIVE,), follower=_TRANS),
    # optional: the follower's face ends (Scene(face="bounded")), the contact length, the friction laws, the
    # damping models, each used by some scenes
    RigParameter("face_start", "m", "where the follower's face begins, as the contact's position along it: the "
                 "oscillating follower's distance chi from P along the bar, the translating follower's from its guide's "
                 "axis along the face", False, "Eq. 2; translating follower", (Rule("abs<=", 10.0, _MM, guard=True),)),
    RigParameter("face_end", "m", "where the follower's face ends, as face_start measures it", False,
                 "Eq. 2; translating follower", (Rule(">", "face_start", "the face ends after it begins"),
                                                 Rule("abs<=", 10.0, _MM, guard=True))),
    RigParameter("l_lambda", "m", "length of the line contact", False, "Eq. 13", _LENGTH),
    RigParameter("xi", "1", "coefficient of restitution of the rigid contact's impacts: the normal relative velocity "
                 "leaves at -xi times its arrival (Newton's law)", False, "Eq. 31; contact 'rigid'",
                 (_NON_NEGATIVE, Rule("<=", 1.0, "a restitution above 1 would add energy at each impact"))),
    RigParameter("mu_m", "1", "friction coefficient", False, "Sec. 3.2, friction models I and II",
                 (_NON_NEGATIVE,)),
    RigParameter("s", "s/m", "smoothing factor of the tanh friction model", False,
                 "Sec. 3.2, friction model II", (_POSITIVE,)),
    RigParameter("zeta_A", "1", "viscous damping ratio of damping model A", False, "Eq. 24", (_NON_NEGATIVE,)),
    RigParameter("beta_B", "s/m", "impact damping factor of damping model B", False, "Eq. 25", (_NON_NEGATIVE,)),
    RigParameter("beta_C", "N s/m^1.25", "impact damping coefficient of damping model C", False, "Eq. 26",
                 (_NON_NEGATIVE,)),
    RigParameter("zeta_D", "1", "viscous damping ratio of damping model D after maximum compression", False,
                 "Eq. 27", (_NON_NEGATIVE,)),
    RigParameter("beta_D", "s/m", "impact damping factor of damping model D up to maximum compression", False,
                 "Eq. 27", (_NON_NEGATIVE,)),
    RigParameter("zeta_E", "1", "viscous damping ratio of damping model E after maximum compression", False,
                 "Eq. 28", (_NON_NEGATIVE,)),
    RigParameter("beta_E", "N s/m^1.25", "impact damping coefficient of damping model E up to maximum compression",
                 False, "Eq. 28", (_NON_NEGATIVE,)),
)

#: the results of the static equilibrium that the laws read (computed once per rig)
EQUILIBRIUM_QUANTITIES: tuple[Constant, ...] = (
    Constant("alpha_star", "rad", "static equilibrium angle alpha* (Eqs. 16-18)"),
    Constant("chi_star", "m", "chi* = chi0 - psi_j* at static equilibrium", "positive"),
    Constant("vartheta", "rad/s", "undamped linearized natural frequency (Eq. 23, misprint 4)",
             "positive"),
    Constant("y_star", "m", "static equilibrium position y* of the translating follower (its face's distance "
             "from E along the guide)"),
)

#: the constants of a cam motion (its speed or its oscillation), set per run
CAM_CONSTANTS: tuple[Constant, ...] = (
    Constant("Omega_c", "rad/s", "constant cam speed (>0 counter-clockwise, de-energizing)"),
    Constant("Theta_p", "rad", "peak-to-peak cam angle of the oscillating cam (Section 7.2)"),
    Constant("omega_c", "rad/s", "frequency of the oscillating cam (Section 7.2)"),
)

#: the names of RIG_PARAMETERS, EQUILIBRIUM_QUANTITIES and CAM_CONSTANTS, in order
RIG_NAMES = tuple(p.name for p in RIG_PARAMETERS)
#: (see RIG_NAMES)
EQUILIBRIUM_NAMES = tuple(c.name for c in EQUILIBRIUM_QUANTITIES)
#: (see RIG_NAMES)
CAM_NAMES = tuple(c.name for c in CAM_CONSTANTS)
