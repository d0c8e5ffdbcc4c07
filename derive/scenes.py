"""Scenes: the physics one study needs, and the symbolic functions generated for it.

A scene names a contact law, a damping model, a friction model, a cam motion
and the model kind (non-linear or one of the linearizations).  :func:`build`
turns it into named lists of SymPy expressions in plain symbols (t, alpha,
alpha_dot, parameters): only the laws the scene uses appear, with the cam
motion substituted in (so a constant speed folds Theta_ddot = 0 out).

Regimes.  The non-linear model switches between regimes, each with its own
right-hand side; the discrete state is a set of flags, each tied to the sign
of one switching surface:

  contact   gap psi_i < 0          (Eqs. 10 / 15)
  loading   gap rate psi_i_dot < 0 (D/E only: t_a..t_b impact law, then viscous)
  forward   sliding velocity v_r > 0 (Coulomb only: the sign of mu)

``loading`` and ``forward`` only matter in contact.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass, fields
from functools import lru_cache

import sympy as sp

from . import dynamics, energy, equilibrium, geometry, laws, linear
from . import symbols as S

OPTIONS: dict[str, tuple[str, ...]] = {
    "contact": laws.CONTACT_LAWS,
    "damping": laws.DAMPING_MODELS,
    "friction": laws.FRICTION_MODELS,
    "motion": ("constant", "oscillating", "user"),
    "model": ("nonlinear", "linear_paper", "linear_exact"),
    "sliding_velocity": dynamics.SLIDING_VELOCITY_FORMS,
    "damping_sign": laws.DAMPING_SIGNS,
}

OUTPUTS = ("psi_i", "psi_j", "psi_i_dot", "F_s", "F_n", "F_f", "v_r", "N_x", "alpha_i",
           "energy", "P_in", "D_c", "D_f")

#: Flags of the discrete state: (flag, surface function, sign of the surface where it is True).
FLAG_SURFACES = {"contact": ("gap", -1), "loading": ("gap_rate", -1), "forward": ("slip", +1)}


class SceneSpecError(ValueError):
    """An invalid combination of scene options."""


@dataclass(frozen=True)
class SceneSpec:
    contact: str = "line"
    damping: str = "D"
    friction: str = "coulomb"
    motion: str = "constant"
    model: str = "nonlinear"
    sliding_velocity: str = "kinematic"
    damping_sign: str = "dissipative"

    def __post_init__(self):
        for f in fields(self):
            value = getattr(self, f.name)
            if value not in OPTIONS[f.name]:
                raise SceneSpecError(f"{f.name}={value!r} is not one of {OPTIONS[f.name]}")
        if self.sliding_velocity != "kinematic" and self.friction == "none":
            raise SceneSpecError("sliding_velocity='printed' matters only with friction; "
                                 "set friction='coulomb' or 'tanh'")
        if self.damping_sign != "dissipative" and self.damping not in ("B", "D"):
            raise SceneSpecError("damping_sign='printed' exists only for damping 'B' and 'D' (Eqs. 25, 27a)")
        if self.model != "nonlinear":
            if self.friction == "tanh":
                raise SceneSpecError(f"model={self.model!r} needs friction 'none' or 'coulomb' "
                                     "of fixed sign (Section 8)")
            if self.damping in ("B", "C"):
                raise SceneSpecError(f"model={self.model!r} needs a constant damping coefficient: "
                                     "damping 'none', 'A', or the viscous part of 'D'/'E'")
        if self.model == "linear_paper" and self.contact != "line":
            raise SceneSpecError("model='linear_paper' is the paper's Eqs. 36-38, for line contact only")

    @property
    def slug(self) -> str:
        parts = [self.contact, self.damping.lower(), self.friction, self.motion, self.model]
        if self.sliding_velocity == "printed":
            parts.append("vrprinted")
        if self.damping_sign == "printed":
            parts.append("printedsign")
        return "_".join(parts)

    def as_dict(self) -> dict[str, str]:
        return asdict(self)

    @property
    def flags(self) -> tuple[str, ...]:
        if self.model != "nonlinear":
            return ()
        out = ["contact"]
        if self.damping in ("D", "E"):
            out.append("loading")
        if self.friction == "coulomb":
            out.append("forward")
        return tuple(out)


@dataclass(frozen=True)
class Regime:
    name: str
    key: tuple                     # flag values in SceneSpec.flags order, None where out of scope
    contact: dynamics.ContactRegime | None


def regimes(spec: SceneSpec) -> list[Regime]:
    phases = ("loading", "unloading") if spec.damping in ("D", "E") else (None,)
    directions = (1, -1) if spec.friction == "coulomb" else (0,)
    out = []
    if spec.model == "nonlinear":
        out.append(Regime("free", (False,) + (None,) * (len(spec.flags) - 1), None))
    if spec.model != "nonlinear":  # sliding contact throughout; D/E contribute their viscous part
        phases = ("unloading",) if spec.damping in ("D", "E") else (None,)
    for phase in phases:
        for direction in directions:
            name = "contact"
            key = [True] if spec.model == "nonlinear" else []
            if phase is not None and spec.model == "nonlinear":
                name += "_" + phase
                key.append(phase == "loading")
            if direction:
                name += "_fwd" if direction > 0 else "_bwd"
                key.append(direction > 0)  # linear models: fixed for the run, chosen at the start
            out.append(Regime(name, tuple(key), dynamics.ContactRegime(
                contact=spec.contact, damping=spec.damping, phase=phase or "loading",
                friction=spec.friction, direction=direction, damping_sign=spec.damping_sign,
                sliding_velocity=spec.sliding_velocity)))
    return out


def motion_substitution(motion: str) -> dict:
    """Theta(t) of the cam motions of Section 7 as plain-symbol substitutions."""
    tt = S.t_s
    if motion == "constant":
        return {S.Theta_s: S.theta0 + S.Omega_c * tt, S.Theta_dot: S.Omega_c, S.Theta_ddot: 0}
    if motion == "oscillating":
        half = S.Theta_p / 2
        return {S.Theta_s: S.theta0 + half * sp.sin(S.omega_c * tt),
                S.Theta_dot: half * S.omega_c * sp.cos(S.omega_c * tt),
                S.Theta_ddot: -half * S.omega_c**2 * sp.sin(S.omega_c * tt)}
    if motion == "user":
        return {}
    raise SceneSpecError(f"motion {motion!r} is not one of {OPTIONS['motion']}")


def _plain(expr: sp.Expr, motion: str) -> sp.Expr:
    return S.to_plain(expr).subs(motion_substitution(motion))


def _alpha_ddot(spec: SceneSpec, regime: Regime) -> sp.Expr:
    """alpha_ddot of a regime in plain symbols, before the cam motion is substituted."""
    nonlinear = S.to_plain(dynamics.angular_acceleration(regime.contact))
    if spec.model == "nonlinear" or regime.contact is None:
        return nonlinear
    if spec.model == "linear_exact":
        return linear.exact_linear_rhs(nonlinear)
    c = laws.damping_coefficient(spec.damping, "unloading", 0, 0)
    mu = laws.friction_coefficient(spec.friction, 0, regime.contact.direction)
    return linear.paper_linear_rhs(linear.paper_linear_model(c, mu, "printed"))


def _outputs(regime: Regime) -> list[sp.Expr]:
    f = dynamics.forces(regime.contact)
    if regime.contact is None:
        V_c, P_in, D_c, D_f = 0, 0, 0, 0
    else:
        V_c = energy.contact_potential(regime.contact.contact)
        P_in, D_c, D_f = energy.power_flows(regime.contact)
    E = energy.kinetic() + energy.spring_potential() + V_c
    return [dynamics.gap(), dynamics.psi_j(), dynamics.gap_rate(), f.F_s, f.F_n, f.F_f, f.v_r,
            dynamics.bearing_force_x(f), geometry.rigid_contact_angle(S.Theta), E, P_in, D_c, D_f]


@dataclass(frozen=True)
class Function:
    """One generated function: its name, arguments, documented outputs and expressions."""

    name: str
    args: tuple[str, ...]          # "t", "alpha", "alpha_dot", "Theta", "p", "cam"
    outputs: tuple[str, ...]
    exprs: tuple[sp.Expr, ...]
    doc: str
    vectorised: bool = False


@lru_cache(maxsize=None)
def build(spec: SceneSpec) -> tuple[Function, ...]:
    """All the symbolic functions of a scene, in generation order."""
    state = ("t", "alpha", "alpha_dot", "p") + (("cam",) if spec.motion == "user" else ())
    fns: list[Function] = []
    if spec.motion != "user":
        sub = motion_substitution(spec.motion)
        for vec in (False, True):
            fns.append(Function("cam" + ("_v" if vec else ""), ("t", "p"), ("Theta", "Theta_dot", "Theta_ddot"),
                                tuple(sp.sympify(sub[k]) for k in (S.Theta_s, S.Theta_dot, S.Theta_ddot)),
                                f"Cam angle (rad) and its rates at time t (s): {spec.motion} motion"
                                + (", on arrays." if vec else "."), vectorised=vec))
    for regime in regimes(spec):
        h2 = _alpha_ddot(spec, regime)
        h2m = h2.subs(motion_substitution(spec.motion))
        where = "no contact (Eq. 15)" if regime.contact is None else f"contact regime {regime.name} (Eq. 10)"
        fns.append(Function(f"rhs_{regime.name}", state, ("alpha_ddot",), (h2m,),
                            f"Angular acceleration (rad/s^2) in {where}."))
        fns.append(Function(f"jac_{regime.name}", state, ("dalpha_ddot_dalpha", "dalpha_ddot_dalpha_dot"),
                            (h2m.diff(S.alpha_s), h2m.diff(S.alpha_dot)),
                            f"Second row of the state Jacobian (Eq. 22c-d) in {where}."))
        outs = tuple(_plain(x, spec.motion) for x in _outputs(regime))
        for vec in (False, True):
            fns.append(Function(f"out_{regime.name}" + ("_v" if vec else ""), state, OUTPUTS, outs,
                                f"Output quantities in {where}" + (", on arrays" if vec else "") + ".",
                                vectorised=vec))
    if spec.model == "nonlinear":
        fns.append(Function("gap", state, ("psi_i",), (_plain(dynamics.gap(), spec.motion),),
                            "Gap psi_i (m), Eq. 6: contact where negative."))
        fns.append(Function("gap_rate", state, ("psi_i_dot",), (_plain(dynamics.gap_rate(), spec.motion),),
                            "Gap rate psi_i_dot (m/s), Eq. 8: the D/E switch at maximum compression, and "
                            "the slope that finds a micro-hop hidden inside one step."))
        if "forward" in spec.flags:
            v_r = dynamics.sliding_velocity(spec.sliding_velocity)
            fns.append(Function("slip", state, ("v_r",), (_plain(v_r, spec.motion),),
                                f"Sliding velocity v_r (m/s), {spec.sliding_velocity} form."))
            v = _plain(v_r, spec.motion)
            fns.append(Function("slip_partials", state, ("dv_r_dt", "dv_r_dalpha", "dv_r_dalpha_dot"),
                                (v.diff(S.t_s), v.diff(S.alpha_s), v.diff(S.alpha_dot)),
                                "Partial derivatives of v_r: the Filippov sliding mode on v_r = 0 "
                                "(Coulomb stick) keeps dv_r/dt = 0 with them."))
    M = equilibrium.static_moment(spec.contact)
    Mp = S.to_plain(M)
    psi_i_star, psi_j_star = (S.to_plain(x) for x in equilibrium.static_gap())
    fns.append(Function("static_moment", ("alpha", "p"), ("M", "dM_dalpha", "psi_i", "psi_j", "k_lambda"),
                        (Mp, Mp.diff(S.alpha_s), psi_i_star, psi_j_star,
                         laws.contact_stiffness(spec.contact, psi_i_star)),
                        "Static moment about P (N m) at Theta0, its slope, psi_i*, psi_j* (Eqs. 16-18) "
                        "and the contact stiffness k_lambda(psi_i) (Eq. 13 or 34, secant)."))
    a_i = S.to_plain(geometry.rigid_contact_angle(S.Theta))
    a_i_th = a_i.diff(S.Theta_s)
    F_s_at = laws.spring_force(S.alpha_s).subs(S.alpha_s, a_i) * S.d_x
    fns.append(Function("reach", ("Theta", "p"), ("reach_margin",),
                        (S.to_plain(geometry.reach_margin(S.Theta)),),
                        "|PG_c| - (r_c + w_b/2): where negative, no follower angle touches the cam "
                        "(check it before rigid_contact, whose arcsine needs it positive)."))
    fns.append(Function("rigid_contact", ("Theta", "p"),
                        ("alpha_i", "dalpha_i_dTheta", "d2alpha_i_dTheta2", "spring_moment"),
                        (a_i, a_i_th, a_i_th.diff(S.Theta_s), F_s_at),
                        "Follower angle in rigid contact alpha_i(Theta) (Eq. 29, misprint 10), its "
                        "derivatives in Theta, and the spring moment F_s d_x there."))
    fns.append(Function("spring_potential", ("alpha", "p"), ("V_s", "V_s_printed"),
                        (S.to_plain(energy.spring_potential()), S.to_plain(energy.spring_potential_printed())),
                        "Spring potential of Eq. 10's moment, and (k_s/2) L^2 of Eq. 33."))
    return tuple(fns)
