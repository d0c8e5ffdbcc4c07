"""The vocabulary the derivation and the runtime share: scene options, the slug rule, the names
of the hybrid automaton's modes and surfaces, and the output quantities.

Standard library only (no SymPy): ``camdyn.derive`` builds its SymPy model from these names and
the runtime (``camdyn.scene``, the engine, the results) reads them, so neither holds a copy.
A new option value (a new friction law, say) is added here, in ``derive/``, and nowhere in
``camdyn/``.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass, fields

# --- scene options ------------------------------------------------------------------------
CONTACT_LAWS = ("line", "point")                        # Eq. 13 (line), Eq. 34 (point, Hertz)
DAMPING_MODELS = ("none", "A", "B", "C", "D", "E")      # Eqs. 24-28
FRICTION_MODELS = ("none", "coulomb", "tanh")           # model I (Coulomb), model II (tanh)
MOTIONS = ("constant", "oscillating", "user")           # Section 7
MODELS = ("nonlinear", "linear_paper", "linear_exact")  # Eq. 10; Eqs. 36-38 as printed; Jacobian
SLIDING_VELOCITY_FORMS = ("kinematic", "printed")       # misprint 8
DAMPING_SIGNS = ("dissipative", "printed")              # misprint 2
DAMPING_SWITCHES = ("episode", "memoryless")            # Sec. 3.4, models D and E (see SceneSpec)
FOLLOWERS = ("dynamic", "quasistatic")                  # the hybrid model; the quasi-static contact orbit

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
}

#: options that say how the runtime uses a derived model rather than what is derived: they have
#: no kernels of their own (the scene's kernels are those of its ``derived`` spec)
RUNTIME_OPTIONS = ("follower",)

#: the slug's suffix word of each non-default misprint or switch option
SLUG_SUFFIXES: dict[str, tuple[str, str]] = {
    "vrprinted": ("sliding_velocity", "printed"),
    "printedsign": ("damping_sign", "printed"),
    "memoryless": ("damping_switch", "memoryless"),
    "quasistatic": ("follower", "quasistatic"),
}

#: damping models with an impact law until maximum compression, then a viscous one (Eqs. 27-28)
SWITCHED_DAMPING = ("D", "E")


class SceneOptionError(ValueError):
    """An unknown scene option value, or options that make no sense together."""


@dataclass(frozen=True)
class SceneSpec:
    """The physics of one study: which laws, which cam motion, which model.

    Its options::

        contact:  "line" (Eq. 13) or "point" (Eq. 34)
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
        follower: "dynamic" (the hybrid model: free flight, impacts, contact) or "quasistatic"
                  (no integration: Eq. 10 solved for alpha with alpha_dot, alpha_ddot of the rigid
                  kinematics, Eq. 29, for a follower that never leaves the cam; camdyn.quasistatic)
    """

    contact: str = "line"
    damping: str = "D"
    friction: str = "coulomb"
    motion: str = "constant"
    model: str = "nonlinear"
    sliding_velocity: str = "kinematic"
    damping_sign: str = "dissipative"
    damping_switch: str = "episode"
    follower: str = "dynamic"

    def __post_init__(self):
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
    if spec.model == "linear_paper" and spec.contact != "line":
        return "model='linear_paper' is the paper's Eqs. 36-38, for line contact only"
    return ""


DEFAULTS: dict[str, str] = {f.name: f.default for f in fields(SceneSpec)}


# --- the hybrid automaton: mode and surface names -------------------------------------------
#: the damping law a contact mode uses (models D, E: "impact" from t_a to t_b, then "viscous")
DAMPING_PHASES = ("impact", "viscous")
#: Coulomb friction: the direction of sliding (v_r > 0 forward), or stuck on v_r = 0
SLIP_STATES = ("fwd", "bwd", "stick")


def mode_name(contact: bool, phase: str | None = None, slip: str | None = None) -> str:
    """The name of a mode: ``free``, or ``contact`` with ``_loading``/``_unloading`` (models D, E:
    the impact and the viscous law) and ``_fwd``/``_bwd``/``_stick`` (Coulomb friction)."""
    if not contact:
        return "free"
    name = "contact"
    if phase is not None:
        name += {"impact": "_loading", "viscous": "_unloading"}[phase]
    if slip is not None:
        name += "_" + slip
    return name


#: Switching surfaces: name -> (unit, meaning).  A surface's value is a function of the state
#: (t, alpha, alpha_dot) under a mode's laws; its sign selects modes (see derive.automaton).
SURFACES: dict[str, tuple[str, str]] = {
    "gap": ("m", "gap psi_i (Eq. 6): the follower touches the cam where it is negative"),
    "gap_rate": ("m/s", "gap rate psi_i_dot (Eq. 8): zero at maximum compression (t_b of Eqs. 27-28)"),
    "slip": ("m/s", "sliding velocity v_r: the direction of Coulomb friction"),
    "slip_rate_fwd": ("m/s^2", "dv_r/dt under the forward-sliding field: the stuck follower slips "
                               "forward where it turns positive"),
    "slip_rate_bwd": ("m/s^2", "dv_r/dt under the backward-sliding field: the stuck follower slips "
                               "backward where it turns negative"),
}

# --- output quantities ------------------------------------------------------------------------
#: Output quantities of every scene, in the order of the generated ``outputs`` kernel:
#: name -> (unit, meaning with the paper's equation).
OUTPUTS: dict[str, tuple[str, str]] = {
    "psi_i": ("m", "gap; negative: contact deflection (Eq. 6)"),
    "psi_j": ("m", "sliding of the contact point along the follower (Eq. 7)"),
    "psi_i_dot": ("m/s", "gap rate (Eq. 8)"),
    "F_s": ("N", "spring force (Eq. 11)"),
    "F_n": ("N", "normal contact force (Eq. 12)"),
    "F_f": ("N", "friction force F_f = mu F_n"),
    "v_r": ("m/s", "sliding velocity used by the friction law"),
    "N_x": ("N", "horizontal bearing force at the pivot (Eq. 35)"),
    "alpha_i": ("rad", "follower angle in rigid contact (Eq. 29)"),
    "energy": ("J", "mechanical energy T + V_s + V_c (Section 5)"),
    "P_in": ("W", "power delivered by the cam drive"),
    "D_c": ("W", "power dissipated by contact damping"),
    "D_f": ("W", "power dissipated by friction"),
}
#: the continuous state, in order: as a reset writes it to ``out``, as the engine samples it
STATE = ("alpha", "alpha_dot")
STATE_ALPHA, STATE_ALPHA_DOT = range(len(STATE))
#: the entries the generated ``jacobian`` kernel writes to ``out``, in order: the partial
#: derivatives of alpha_ddot by alpha and by alpha_dot (Eqs. 21-22), in the order of STATE
JACOBIAN = tuple(f"d_{name}" for name in STATE)
JAC_D_ALPHA, JAC_D_ALPHA_DOT = range(len(JACOBIAN))
#: the entries the generated ``surface_gradient`` kernel writes to ``out``, in order: the
#: partial derivatives of a surface's value h by the state (in the order of STATE) and the
#: total derivative by t at a fixed state (through the cam angle Theta(t)); a slip_rate surface
#: is differentiated through the alpha_ddot it contains
SURFACE_GRADIENT = JACOBIAN + ("d_t",)
GRAD_D_ALPHA, GRAD_D_ALPHA_DOT, GRAD_D_T = range(len(SURFACE_GRADIENT))
#: the entries the generated ``surface_with_rate`` kernel writes to ``out``, in order: a
#: surface's value and the value of its declared rate (the scene module's RATE_OF_SURFACE)
SURFACE_WITH_RATE = ("value", "rate")
WITH_RATE_VALUE, WITH_RATE_RATE = range(len(SURFACE_WITH_RATE))
#: the continuation parameters, in the order the generated ``field_sensitivity`` kernel writes
#: d(alpha_ddot)/d(parameter) to ``out`` (each scene: those its fields read, listed in the
#: SENSITIVITY of its companion module of variational kernels): the cam's speed (Omega_c at
#: constant speed, omega_c for the oscillating cam), the spring stiffness k_s, the
#: eccentricity e, then the damping constants
CONTINUATION_PARAMETERS = ("Omega_c", "omega_c", "k_s", "e", "zeta_A", "beta_B", "beta_C", "zeta_D", "beta_D",
                           "zeta_E", "beta_E")
#: the cam's state as the generated ``cam`` kernel and a user's cam motion return it
CAM_STATE = ("Theta", "Theta_dot", "Theta_ddot")
CAM_THETA, CAM_THETA_DOT, CAM_THETA_DDOT = range(len(CAM_STATE))
#: the power flows integrated by the energy ledger (work of the drive, contact damping, friction)
FLOWS = ("P_in", "D_c", "D_f")
