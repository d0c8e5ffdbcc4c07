"""The scene options: what a scene derives, by name, and its slug (shared by derive/ and the
runtime; plain Python, no SymPy)."""
from __future__ import annotations

from dataclasses import asdict, dataclass, fields

# --- scene options ------------------------------------------------------------------------
CONTACT_LAWS = ("line", "point", "rigid")               # Eq. 13 (line), Eq. 34 (point, Hertz); rigid: impacts
#: the compliant contact laws (a contact stiffness, a deflection); the others are rigid (Newton's impacts)
COMPLIANT = ("line", "point")
DAMPING_MODELS = ("none", "A", "B", "C", "D", "E")      # Eqs. 24-28
FRICTION_MODELS = ("none", "coulomb", "tanh")           # model I (Coulomb), model II (tanh)
MOTIONS = ("constant", "oscillating", "user")           # Section 7
MODELS = ("nonlinear", "linear_paper", "linear_exact")  # Eq. 10; Eqs. 36-38 as printed; Jacobian
SLIDING_VELOCITY_FORMS = ("kinematic", "printed")       # misprint 8
DAMPING_SIGNS = ("dissipative", "printed")              # misprint 2
DAMPING_SWITCHES = ("episode", "memoryless")            # Sec. 3.4, models D and E (see SceneSpec)
FOLLOWERS = ("oscillating", "translating")              # the paper's rocker (Fig. 1); a flat face on a guide
RESPONSES = ("dynamic", "quasistatic")                  # the hybrid model; the quasi-static contact orbit
FACES = ("unbounded", "bounded")                        # the follower's face: long enough; ends at face_start/_end
#: the cam's shape: the paper's eccentric circle (Eq. 3-4), or a convex cam given by its support
#: function h(phi) (docs/model-editing.md, "a new cam"): a periodic piecewise quintic, or circular arcs
ECCENTRIC = "eccentric"
PROFILES = (ECCENTRIC, "spline", "arcs")

OPTIONS: dict[str, tuple[str, ...]] = {
    "contact": CONTACT_LAWS,
    "damping": DAMPING_MODELS,
    "friction": FRICTION_MODELS,
    "motion": MOTIONS,
    "model": MODELS,
    "sliding_velocity": SLIDING_VELOCITY_FORMS,
    "damping_sign": DAMPING_SIGNS,
    "damping_switch": DAMPING_SWITCHES,
    "follower": FOLLOWERS,
    "profile": PROFILES,
    "face": FACES,
    "response": RESPONSES,
}

#: options that say how the runtime uses a derived model rather than what is derived: they have
#: no kernels of their own (the scene's kernels are those of its ``derived`` spec)
RUNTIME_OPTIONS = ("response",)

#: the slug's suffix word of each non-default misprint or switch option
SLUG_SUFFIXES: dict[str, tuple[str, str]] = {
    "vrprinted": ("sliding_velocity", "printed"),
    "printedsign": ("damping_sign", "printed"),
    "memoryless": ("damping_switch", "memoryless"),
    "quasistatic": ("response", "quasistatic"),
    "translating": ("follower", "translating"),
    "bounded": ("face", "bounded"),
    "spline": ("profile", "spline"),
    "arcs": ("profile", "arcs"),
}

#: damping models with an impact law until maximum compression, then a viscous one (Eqs. 27-28)
SWITCHED_DAMPING = ("D", "E")


class SceneOptionError(ValueError):
    """An unknown scene option value, or options that make no sense together."""


@dataclass(frozen=True)
class SceneSpec:
    """The physics of one study: which laws, which cam motion, which model.

    Its options::

        contact:  "line" (Eq. 13), "point" (Eq. 34) or "rigid" (no deflection: Newton's impact law with
                  the rig's restitution xi, the follower riding the cam in a constrained mode, chatter
                  ended at its accumulation point; derive.rigid)
        damping:  "none" or "A".."E" (Eqs. 24-28)
        friction: "none", "coulomb" (model I) or "tanh" (model II)
        motion:   "constant", "oscillating" or "user" (Section 7)
        model:    "nonlinear", "linear_paper" (Eqs. 36-38 as printed) or "linear_exact"
        sliding_velocity: "kinematic" (derived) or "printed" (misprint 8; Figs. 12-15)
        damping_sign:     "dissipative" (derived) or "printed" (misprint 2; B and D only)
        damping_switch:   models D and E: "episode" (Sec. 3.4: the impact law from first contact
                          t_a to maximum compression t_b, where psi_i_dot = 0, then the viscous law
                          until separation t_c: one switch per contact episode) or "memoryless"
                          (the law follows the sign of psi_i_dot at every instant: loading while
                          psi_i_dot < 0, viscous otherwise)
        follower: "oscillating" (the paper's flat-faced rocker on the pivot P, Fig. 1: its
                  coordinate is the angle alpha) or "translating" (a flat face normal to a guide, mass
                  m_f, spring and preload along the guide: its coordinate is the face's distance y
                  from the cam's centre; derive.translating)
        profile:  "eccentric" (the paper's circle, Eqs. 3-4), "spline" (a convex cam given by its
                  support function h(phi) as a periodic piecewise quintic) or "arcs" (a cam of
                  circular arcs, whose junctions are switching surfaces); the profile's data
                  travels with the rig (camdyn.model.profiles)
        face:     "unbounded" (the face is long enough wherever the contact goes) or "bounded" (it ends
                  at the rig's face_start and face_end: a contact that reaches an end, or an impact
                  that would land beyond one, ends the run with Outcome.OFF_FACE)
        response: "dynamic" (the hybrid model: free flight, impacts, contact) or "quasistatic"
                  (no integration: Eq. 10 solved for alpha with alpha_dot, alpha_ddot of the rigid
                  kinematics, Eq. 29, for a follower that never leaves the cam; camdyn.runs.quasistatic)
    """

    contact: str = "line"
    damping: str = "D"
    friction: str = "coulomb"
    motion: str = "constant"
    model: str = "nonlinear"
    sliding_velocity: str = "kinematic"
    damping_sign: str = "dissipative"
    damping_switch: str = "episode"
    follower: str = "oscillating"
    profile: str = ECCENTRIC
    face: str = "unbounded"
    response: str = "dynamic"

    def __post_init__(self):
        if self.follower in RESPONSES:
            raise SceneOptionError(f"scene option follower={self.follower!r}: the choice between the hybrid model "
                                   f"and the quasi-static contact orbit is the option response={self.follower!r} "
                                   f"now; follower names the follower's type, one of {FOLLOWERS}")
        for f in fields(self):
            value = getattr(self, f.name)
            if value not in OPTIONS[f.name]:
                raise SceneOptionError(f"scene option {f.name}={value!r} is not one of {OPTIONS[f.name]}")
        problem = combination_problem(self)
        if problem:
            raise SceneOptionError(problem)

    @property
    def slug(self) -> str:
        """The scene's key: ``<contact>_<damping>_<friction>_<motion>_<model>`` and a suffix per
        non-default misprint or switch option (``vrprinted``, ``printedsign``, ``memoryless``)."""
        parts = [self.contact, self.damping.lower(), self.friction, self.motion, self.model]
        parts += [word for word, (name, value) in SLUG_SUFFIXES.items() if getattr(self, name) == value]
        return "_".join(parts)

    @classmethod
    def from_slug(cls, slug: str):
        """The scene of a slug (the inverse of :attr:`slug`)."""
        words = slug.split("_")
        options = dict(SLUG_SUFFIXES[w] for w in words if w in SLUG_SUFFIXES)
        core = [w for w in words if w not in SLUG_SUFFIXES]
        if len(core) < 5:
            raise SceneOptionError(f"{slug!r} is not a scene slug (contact_damping_friction_motion_model[_suffix])")
        damping = {d.lower(): d for d in DAMPING_MODELS}.get(core[1], core[1])
        return cls(contact=core[0], damping=damping, friction=core[2], motion=core[3],
                   model="_".join(core[4:]), **options)

    def as_dict(self) -> dict[str, str]:
        return asdict(self)

    def derived_options(self) -> dict[str, str]:
        """The options that choose what is derived (all but RUNTIME_OPTIONS)."""
        return {k: v for k, v in asdict(self).items() if k not in RUNTIME_OPTIONS}

    @property
    def derived(self) -> "SceneSpec":
        """The spec whose generated module this scene runs: RUNTIME_OPTIONS at their defaults."""
        return SceneSpec(**self.derived_options())

    def options_text(self) -> str:
        """The options that differ from the defaults, as keyword arguments (for messages)."""
        defaults = DEFAULTS
        return ", ".join(f"{k}={v!r}" for k, v in self.as_dict().items() if v != defaults[k])

    @property
    def switched_damping(self) -> bool:
        """Damping D or E in the non-linear model: an impact law and a viscous law, switched."""
        return self.damping in SWITCHED_DAMPING and self.model == "nonlinear"


def combination_problem(spec: SceneSpec) -> str:
    """Why a combination of (individually valid) options makes no sense, or ``""``."""
    if spec.sliding_velocity != "kinematic" and spec.friction == "none":
        return "sliding_velocity='printed' matters only with friction; set friction='coulomb' or 'tanh'"
    if spec.damping_sign != "dissipative" and spec.damping not in ("B", "D"):
        return "damping_sign='printed' exists only for damping 'B' and 'D' (Eqs. 25, 27a)"
    if spec.damping_switch != "episode" and not (spec.damping in SWITCHED_DAMPING and spec.model == "nonlinear"):
        return ("damping_switch='memoryless' exists only for damping 'D' and 'E' in the non-linear model "
                "(the switch between their impact and viscous laws)")
    if spec.model != "nonlinear":
        if spec.friction == "tanh":
            return f"model={spec.model!r} needs friction 'none' or 'coulomb' of fixed sign (Section 8)"
        if spec.damping in ("B", "C"):
            return (f"model={spec.model!r} needs a constant damping coefficient: damping 'none', 'A', "
                    "or the viscous part of 'D'/'E'")
    if spec.profile != ECCENTRIC:
        if spec.model != "nonlinear":
            return f"profile={spec.profile!r} needs model='nonlinear' (the linear models are the paper's, Section 8)"
        if spec.sliding_velocity != "kinematic":
            return f"profile={spec.profile!r} needs sliding_velocity='kinematic' (the printed form is the paper's circle)"
    if spec.contact == "rigid":
        for name, allowed in (("damping", "none"), ("friction", "none"), ("model", "nonlinear"), ("face", "unbounded"),
                              ("response", "dynamic"), ("motion", "constant")):
            if getattr(spec, name) != allowed:
                return (f"contact='rigid' needs {name}={allowed!r}: the impact law (restitution xi) takes the place of "
                        "the compliant damping laws" if name == "damping" else
                        f"contact='rigid' needs {name}={allowed!r} (not derived for the rigid law yet)")
    if spec.face == "bounded" and spec.model != "nonlinear":
        return "face='bounded' needs model='nonlinear' (the contact's ends are switching surfaces of the hybrid model)"
    if spec.follower == "translating":
        if spec.model != "nonlinear":
            return "follower='translating' needs model='nonlinear' (the linear models are the paper's, Section 8)"
        if spec.sliding_velocity != "kinematic":
            return "follower='translating' needs sliding_velocity='kinematic' (the printed form is the paper's rocker)"

    if spec.model == "linear_paper" and spec.contact != "line":
        return "model='linear_paper' is the paper's Eqs. 36-38, for line contact only"
    return ""


DEFAULTS: dict[str, str] = {f.name: f.default for f in fields(SceneSpec)}


