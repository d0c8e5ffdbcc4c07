"""What each mode of a scene computes, as named definitions in plain symbols.

For one mode of the automaton (:mod:`derive.automaton`) this module derives

* :func:`field`: alpha_ddot, the second component of the vector field (Eqs. 10, 15; the
  Filippov sliding mode on v_r = 0 for a stuck follower; Eqs. 36-38 for the linear models);
* :func:`surface`: the value of one switching surface under the mode's laws;
* :func:`outputs`: the output quantities of :data:`derive.vocabulary.OUTPUTS`;
* :func:`jacobian`: d(alpha_ddot)/d(alpha, alpha_dot), by the chain rule through the named
  quantities (Eqs. 21-22);
* :func:`field_sensitivity`: d(alpha_ddot)/d(continuation parameter), total derivatives with
  the static equilibrium's quantities (alpha*, chi*, vartheta) following the parameter;
* :func:`surface_gradient`: dh/d(alpha, alpha_dot) and dh/dt of a surface's value h (the
  saltation matrices of the tangent dynamics, ``camdyn.engine.saltation``).

Each is a :class:`Kernel`: definitions (``psi_i = ...``, ``F_n = ...``) in the order they are
computed, and the results.  Expressions are in the plain symbols t, alpha, alpha_dot and the
parameters, with the scene's cam motion substituted (a constant speed folds Theta_ddot = 0
out); a user cam motion keeps Theta, Theta_dot, Theta_ddot as inputs.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import sympy as sp

from . import dynamics, energy, equilibrium, geometry, laws, linear, profile, rigid, translating
from . import symbols as S
from .automaton import Mode
from .dynamics import Q
from .graph import Definition, derivatives, derivative_symbol, flatten, quantity, used
from camdyn.vocabulary import CONTINUATION_PARAMETERS, JACOBIAN, RIGID_OUTPUT, SURFACE_GRADIENT, SceneSpec, outputs_of


@dataclass(frozen=True)
class Kernel:
    """Definitions in computation order, and the results (expressions in their symbols)."""

    definitions: tuple[Definition, ...]
    results: tuple[sp.Expr, ...]

    def pruned(self) -> "Kernel":
        """Only the definitions the results need."""
        return Kernel(used(self.definitions, self.results), self.results)

    def flat(self) -> tuple[sp.Expr, ...]:
        """The results with every named quantity substituted (for oracles and tests)."""
        return tuple(flatten(r, self.definitions) for r in self.results)


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
    raise ValueError(f"motion {motion!r} is not a cam motion of Section 7")


@lru_cache(maxsize=None)  # pure; the scenes of a worker share most expressions
def plain(expr: sp.Expr, motion: str) -> sp.Expr:
    """An expression of alpha(t), Theta(t) in plain symbols, with the cam motion substituted."""
    return S.to_plain(expr).subs(motion_substitution(motion))


def _plain_all(defs, motion: str) -> tuple[Definition, ...]:
    return tuple(Definition(d.symbol, plain(d.expr, motion), d.note) for d in defs)


def regime(spec: SceneSpec, mode: Mode, direction: int | None = None) -> dynamics.ContactRegime | None:
    """The laws of a mode (None in free flight).  ``direction`` overrides the friction sign
    (the one-sided fields of a stuck follower)."""
    if not mode.contact:
        return None
    phase = "unloading" if mode.phase == "viscous" or spec.model != "nonlinear" else "loading"
    if direction is None:
        direction = {"fwd": 1, "bwd": -1}.get(mode.slip, 0)
    return dynamics.ContactRegime(contact=spec.contact, damping=spec.damping, phase=phase,
                                  friction=spec.friction, direction=direction,
                                  damping_sign=spec.damping_sign, sliding_velocity=spec.sliding_velocity,
                                  profile=spec.profile, follower=spec.follower)


def coordinate(spec: SceneSpec) -> S.Coordinate:
    """The scene's follower coordinate: alpha, or the translating follower's y (derive.symbols)."""
    return S.COORDINATES[spec.follower]


# --- the pieces ---------------------------------------------------------------------------
V_R_PARTIALS = tuple(quantity(n) for n in ("dv_r_dt", "dv_r_dalpha", "dv_r_dalpha_dot"))


def _slip_partials(spec: SceneSpec) -> tuple[Definition, ...]:
    """v_r and its partial derivatives in t, alpha, alpha_dot (the sliding mode's ingredients)."""
    v = plain(dynamics.sliding_velocity(spec.sliding_velocity, spec.profile, spec.follower), spec.motion)
    q = coordinate(spec)
    notes = ("dv_r/dt at fixed state", "dv_r/dalpha", "dv_r/dalpha_dot")
    return (Definition(Q.v_r, v, f"sliding velocity ({spec.sliding_velocity} form)"),) + tuple(
        Definition(sym, v.diff(x), note) for sym, x, note in zip(V_R_PARTIALS, (S.t_s, q.plain, q.rate), notes))


def _sliding_mode(spec: SceneSpec) -> tuple[Definition, ...]:
    """alpha_ddot of a follower stuck on v_r = 0 (Filippov sliding mode, misprint 12): the
    acceleration that keeps dv_r/dt = v_t + v_a alpha_dot + v_ad alpha_ddot = 0."""
    v_t, v_a, v_ad = V_R_PARTIALS
    return _slip_partials(spec) + (
        Definition(Q.alpha_ddot, -(v_t + v_a * S.alpha_dot) / v_ad, "stuck: keeps dv_r/dt = 0 (Filippov)"),)


def _mechanics(spec: SceneSpec, mode: Mode, direction: int | None = None) -> tuple[Definition, ...]:
    """The named forces of a mode and its (non-linear) alpha_ddot."""
    r = regime(spec, mode, direction)
    return _plain_all(dynamics.mechanics(r, spec.follower, spec.profile) + (dynamics.acceleration(r, spec.follower),),
                      spec.motion)


def _linear_field(spec: SceneSpec, mode: Mode) -> Definition:
    """alpha_ddot of the linear models (Section 8) in a sliding mode."""
    if spec.model == "linear_exact":
        nonlinear = flatten(Q.alpha_ddot, _mechanics(spec, mode))
        return Definition(Q.alpha_ddot, linear.exact_linear_rhs(nonlinear), "exact linearization about alpha*")
    r = regime(spec, mode)
    c = laws.damping_coefficient(spec.damping, "unloading", 0, 0)
    mu = laws.friction_coefficient(spec.friction, 0, r.direction)
    rhs = linear.paper_linear_rhs(linear.paper_linear_model(c, mu, "printed"))
    return Definition(Q.alpha_ddot, rhs.subs(motion_substitution(spec.motion)), "Eqs. 36-38 as printed")


# --- the kernels --------------------------------------------------------------------------
def _rigid_field(spec: SceneSpec) -> tuple[Definition, ...]:
    """The rigid law's constrained mode: the gap rate's partials and the acceleration that keeps the
    follower on the cam (derive.rigid.constrained_acceleration)."""
    q = coordinate(spec)
    psi = plain(dynamics.gap(spec.profile, spec.follower), spec.motion)
    psi_dot = plain(dynamics.gap_rate(spec.profile, spec.follower), spec.motion)
    return (Definition(Q.psi_i, psi, "gap (Eq. 6)"), Definition(Q.psi_i_dot, psi_dot, "gap rate (Eq. 8)")) + \
        rigid.gap_rate_partials(psi_dot, q) + (
        Definition(q.acceleration, rigid.constrained_acceleration(q, Q.psi_i, Q.psi_i_dot),
                   "riding the cam: psi_i_ddot = 0, stabilized (rigid contact)"),)


def _rigid_contact_force(spec: SceneSpec, mode: Mode) -> tuple[Definition, ...]:
    """The rigid law's constrained mode with its contact force: the geometry (Eqs. 6-8, 2), the spring
    (Eq. 11), the constrained acceleration and the normal force that produces it (derive.rigid)."""
    r = regime(spec, mode)
    q = coordinate(spec)
    geometry = _plain_all(dynamics._contact_geometry(r) + [Definition(Q.F_s, dynamics.spring_force(
        spec.follower, spec.profile), "spring force (Eq. 11)")], spec.motion)
    force = Definition(Q.F_n, plain(rigid.contact_force(r, q.acceleration), spec.motion),
                       "normal force of the rigid contact: keeps the follower on the cam")
    defined = {d.symbol for d in geometry}
    return geometry + tuple(d for d in _rigid_field(spec) if d.symbol not in defined) + (force,)


def field(spec: SceneSpec, mode: Mode) -> Kernel:
    """alpha_ddot of the mode."""
    if spec.model != "nonlinear":
        return Kernel((_linear_field(spec, mode),), (Q.alpha_ddot,))
    if spec.contact == "rigid" and mode.contact:
        return Kernel(_rigid_field(spec), (coordinate(spec).acceleration,)).pruned()
    defs = _sliding_mode(spec) if mode.slip == "stick" else _mechanics(spec, mode)
    return Kernel(defs, (coordinate(spec).acceleration,)).pruned()


def jacobian(spec: SceneSpec, mode: Mode) -> Kernel:
    """d(alpha_ddot)/d(alpha) and d(alpha_ddot)/d(alpha_dot) of the mode's field (Eqs. 21-22)."""
    f, q = field(spec, mode), coordinate(spec)
    by_alpha = derivatives(f.definitions, q.plain)
    by_rate = derivatives(f.definitions, q.rate)
    by = {"d_alpha": (q.plain, by_alpha), "d_alpha_dot": (q.rate, by_rate)}  # JACOBIAN's entries, by position
    results = tuple(derivative_symbol(q.acceleration.name, *by[name]) for name in JACOBIAN)
    return Kernel(f.definitions + by_alpha + by_rate, results).pruned()


def timed_surfaces(spec: SceneSpec, modes, surfaces: tuple[str, ...]) -> tuple[str, ...]:
    """The surfaces whose value is a function of time alone: free of the follower's state in every
    mode where it has a meaning (e.g. a cam of arcs' junction indicator under a translating
    follower, whose contact angle is Theta(t)'s alone).  Judged under the first mode where it has a
    meaning: a surface is the same function in every mode that watches it."""
    q = coordinate(spec)
    state = {q.plain, q.rate}

    def free_of_state(name: str) -> bool:
        kernel = next((k for k in (surface(spec, mode, name) for mode in modes) if k is not None), None)
        return kernel is not None and not any(sp.sympify(d.expr).free_symbols & state for d in kernel.definitions)

    return tuple(s for s in surfaces if free_of_state(s))


def surface(spec: SceneSpec, mode: Mode, name: str) -> Kernel | None:
    """The value of surface ``name`` under the mode's laws (None where it has no meaning)."""
    if name == "gap":
        return Kernel((Definition(Q.psi_i, plain(dynamics.gap(spec.profile, spec.follower), spec.motion),
                                  "gap (Eq. 6)"),), (Q.psi_i,))
    if name == "gap_rate":
        return Kernel((Definition(Q.psi_i_dot, plain(dynamics.gap_rate(spec.profile, spec.follower), spec.motion),
                                  "gap rate (Eq. 8)"),),
                      (Q.psi_i_dot,))
    if name == "slip":
        return Kernel(_slip_partials(spec)[:1], (Q.v_r,))
    if name == "junction":
        value = quantity("junction")
        phi = plain(translating.phi_contact() if spec.follower == dynamics.TRANSLATING else geometry.phi_contact(),
                    spec.motion)
        return Kernel((Definition(value, profile.junction(phi), "the arcs' junction indicator"),), (value,))
    if name == "face":
        return _face_margin(spec)
    if name == "contact_force":
        if not mode.contact:
            return None
        return Kernel(_rigid_contact_force(spec, mode), (Q.F_n,)).pruned()
    if name in ("slip_rate_fwd", "slip_rate_bwd") and mode.contact:
        side = _mechanics(spec, mode, direction=1 if name == "slip_rate_fwd" else -1)
        v_t, v_a, v_ad = V_R_PARTIALS
        q = coordinate(spec)
        rate = v_t + v_a * q.rate + v_ad * q.acceleration
        return Kernel(side + _slip_partials(spec)[1:], (rate,)).pruned()
    return None


def _face_margin(spec: SceneSpec) -> Kernel:
    """The surface of a bounded face: (s - face_start)(face_end - s), s the contact's position along the
    face (the rocker's moment arm chi = chi0 - psi_j, Eq. 2; the translating follower's distance from its
    guide's axis, derive.translating.on_face), wherever the follower is (in flight: where an impact
    would land)."""
    if spec.follower == dynamics.TRANSLATING:
        position = dynamics._on_cam(spec.profile, translating.on_face())
    else:
        position = S.chi0 - dynamics.psi_j(spec.profile)
    s_face, margin = quantity("s_face"), quantity("face_margin")
    return Kernel((Definition(s_face, plain(position, spec.motion), "the contact's position along the face"),
                   Definition(margin, (s_face - S.face_start) * (S.face_end - s_face),
                              "positive while the contact is on the face")), (margin,))


def continuation_parameters(spec: SceneSpec, modes) -> tuple[str, ...]:
    """The CONTINUATION_PARAMETERS the fields of ``modes`` read, in that order."""
    read = set().union(*(sp.sympify(d.expr).free_symbols for m in modes for d in field(spec, m).definitions))
    return tuple(n for n in CONTINUATION_PARAMETERS if S.PARAMS[n].symbol in read)


#: the static equilibrium's quantities the kernels read, by follower type: the coordinate at rest, the
#: rocker's moment arm chi* there, the natural frequency vartheta (vocabulary.EQUILIBRIUM_QUANTITIES)
_AT_REST = {"oscillating": ("alpha_star", "chi_star"), "translating": ("y_star",)}


@lru_cache(maxsize=None)  # shared by the scenes of a contact law, cam and follower
def _equilibrium_rates(contact: str, profile: str, follower: str, name: str) -> tuple[tuple[sp.Symbol, sp.Expr], ...]:
    """(quantity, its derivative by parameter ``name``) for the equilibrium's q* (alpha* or y*), chi*
    (the rocker) and vartheta, where not zero: M(q*) = 0 (Eq. 18) gives dq*/dp = -M_p / M_q (implicit
    function theorem), chi* = chi0 - psi_j*(alpha*) (Eq. 17) and vartheta = sqrt(-M_q / I) (Eq. 23,
    I = I_Pb or m_f), all at q = q*, as the runtime solves them (camdyn.model.model)."""
    p = S.PARAMS[name].symbol
    c = S.COORDINATES[follower]
    M = S.to_plain(equilibrium.static_load(contact, profile, follower))
    star = S.PARAMS[_AT_REST[follower][0]].symbol
    inertia = S.I_Pb if follower == "oscillating" else S.m_f
    at = {c.plain: star}
    M_q = M.diff(c.plain)
    d_q = (-M.diff(p) / M_q).subs(at)
    d_vartheta = (-(M_q.diff(p) + M_q.diff(c.plain) * d_q) / (2 * inertia * S.vartheta)).subs(at)
    rates = [(star, d_q), (S.vartheta, d_vartheta)]
    if follower == "oscillating":
        psi_j = S.to_plain(equilibrium.static_gap(profile)[1])
        rates.insert(1, (S.chi_star, -(psi_j.diff(c.plain) * d_q + psi_j.diff(p)).subs(at)))
    return tuple((sym, rate) for sym, rate in rates if rate != 0)


def field_sensitivity(spec: SceneSpec, mode: Mode, names: tuple[str, ...]) -> Kernel:
    """d(alpha_ddot)/dq of the mode's field for each continuation parameter q in ``names``: the
    total derivative, at a fixed state and time, through the parameter's direct appearances
    and through the static equilibrium's alpha*, chi*, vartheta (:func:`_equilibrium_rates`),
    which the runtime computes from the rig."""
    f = field(spec, mode)
    acceleration = coordinate(spec).acceleration.name
    defs, results, done = list(f.definitions), [], {}
    for name in names:
        q = S.PARAMS[name].symbol
        direct = derivatives(f.definitions, q)
        defs += direct
        total = derivative_symbol(acceleration, q, direct)
        for sym, rate in _equilibrium_rates(spec.contact, spec.profile, spec.follower, name):
            if sym not in done:
                done[sym] = derivatives(f.definitions, sym)
                defs += done[sym]
            part = derivative_symbol(acceleration, sym, done[sym])
            if part != 0:
                rate_symbol = quantity(f"d{sym.name}_d{name}")
                defs.append(Definition(rate_symbol, rate, f"d({sym.name})/d({name}) of the static equilibrium"))
                total += part * rate_symbol
        results.append(total)
    return Kernel(tuple(defs), tuple(results)).pruned()


#: the name of a surface's value in :func:`surface_gradient`'s definitions
SURFACE_VALUE = quantity("surface_value")


def surface_gradient(spec: SceneSpec, mode: Mode, name: str) -> Kernel | None:
    """dh/dalpha, dh/dalpha_dot and dh/dt (SURFACE_GRADIENT order) of surface ``name``'s value
    h under the mode's laws, by the chain rule through the named quantities (a slip_rate
    surface through the alpha_ddot it contains).  dh/dt is the derivative at a fixed state:
    through Theta(t) = theta0 + Omega_c t (constant speed) or the oscillating motion; a user's
    motion gives Theta_dot and Theta_ddot, so dh/dt = h_t + Theta_dot h_Theta + Theta_ddot
    h_Theta_dot, and None where h needs Theta_ddot (its derivative is not given)."""
    h = surface(spec, mode, name)
    if h is None:
        return None
    defs = h.definitions + (Definition(SURFACE_VALUE, h.results[0], f"the value of surface {name}"),)
    q = coordinate(spec)
    by = {x: derivatives(defs, x) for x in (q.plain, q.rate, S.t_s, S.Theta_s, S.Theta_dot)}
    grad = {x: derivative_symbol(SURFACE_VALUE.name, x, d) for x, d in by.items()}
    d_t = grad[S.t_s]
    if spec.motion == "user":
        if any(sp.sympify(d.expr).has(S.Theta_ddot) for d in defs):
            return None
        d_t = d_t + S.Theta_dot * grad[S.Theta_s] + S.Theta_ddot * grad[S.Theta_dot]
    results = dict(zip(SURFACE_GRADIENT, (grad[q.plain], grad[q.rate], d_t)))
    return Kernel(defs + sum(by.values(), ()), tuple(results[n] for n in SURFACE_GRADIENT)).pruned()


def _stuck_friction(spec: SceneSpec, mode: Mode) -> tuple[Definition, ...]:
    """A stuck follower: alpha_ddot of the sliding mode and the friction force that produces it
    (Eq. 10 solved for F_f; F_f / F_n is the equivalent friction coefficient, inside +-mu_m
    while stuck)."""
    stuck = _sliding_mode(spec)[1:]  # the partials and alpha_ddot (v_r is already defined)
    free_f = plain(dynamics.acceleration(regime(spec, mode, direction=1), spec.follower).expr, spec.motion)
    a0, a1 = free_f.subs(Q.F_f, 0), free_f.diff(Q.F_f)
    return stuck + (Definition(Q.F_f, (Q.alpha_ddot - a0) / a1, "friction force that keeps the follower stuck"),)


def _identically_zero(expr: sp.Expr) -> bool:
    """Whether an expression of alpha is 0 for every alpha: as a rational function of
    sin(alpha) and cos(alpha) whose numerator vanishes modulo sin^2 + cos^2 - 1 (exact, and
    quick for a polynomial spring law), else by ``sp.simplify``."""
    sn, cs = sp.Dummy("sin"), sp.Dummy("cos")
    x = S.alpha_s
    rational = expr.subs({sp.tan(x): sn / cs, sp.sec(x): 1 / cs}).subs({sp.sin(x): sn, sp.cos(x): cs})
    if rational.has(x):  # other functions of alpha: let SymPy decide
        return sp.simplify(expr) == 0
    numerator = sp.expand(sp.numer(sp.together(rational)))
    return sp.rem(numerator, sn**2 + cs**2 - 1, sn) == 0


def checked_potential(V: sp.Expr, moment: sp.Expr) -> sp.Expr:
    """A potential of ``moment`` (plain symbols) as generated code computes it, after checking
    that it is real (no complex number), 0 at alpha = 0 and that its derivative is ``moment``,
    symbolically (log|u| differentiates as du/u: :class:`derive.energy.LogAbs`); its log|u| is
    written log(Abs(u)) (:func:`derive.energy.printable`)."""
    if not _identically_zero(V.diff(S.alpha_s) - moment):
        raise RuntimeError(f"dV/dalpha is not the moment {moment}: check derive.energy.moment_potential")
    at_0 = sp.simplify(V.subs(S.alpha_s, 0))
    if V.has(sp.I) or at_0 != 0:
        raise RuntimeError(f"the potential is not real and 0 at alpha = 0 (there: {at_0}): check "
                           "derive.energy.moment_potential")
    return energy.printable(V)


@lru_cache(maxsize=None)
def spring_potential() -> sp.Expr:
    """V_s(alpha) in plain symbols, as generated code computes it: the integral of the spring
    moment d_x F_s (derive.energy), checked (:func:`checked_potential`)."""
    return checked_potential(S.to_plain(energy.spring_potential()), S.d_x * laws.spring_force(S.alpha_s))


@lru_cache(maxsize=None)
def _energy_terms(contact: str, profile: str, follower: str):
    """T's inertia, V_s(q), its derivative in the named form (d_x F_s; the translating follower's F_s),
    and in contact V_c(psi_i), in plain symbols (psi_i named; a point contact on a cam other than the
    circle: rho named)."""
    radius = Q.rho if contact == "point" and profile != dynamics.ECCENTRIC else S.r_c
    V_c = sp.Integer(0) if contact == "rigid" else laws.contact_potential(contact, Q.psi_i, radius)
    if follower == dynamics.TRANSLATING:
        V_s = dynamics._on_cam(profile, translating.spring_potential(S.y_s))
        if sp.expand(V_s.diff(S.y_s) - dynamics._on_cam(profile, translating.spring_force(S.y_s))) != 0:
            raise RuntimeError("dV_s/dy is not F_s: check derive.translating.spring_potential")
        return S.m_f, V_s, Q.F_s, V_c
    return S.I_Pb, spring_potential(), S.d_x * Q.F_s, V_c


def outputs(spec: SceneSpec, mode: Mode) -> Kernel:
    """The output quantities (vocabulary.OUTPUTS order) in the mode."""
    r = regime(spec, mode)
    zero = sp.Integer(0)
    rigid_law = spec.contact == "rigid"
    if rigid_law and mode.contact:
        defs = _rigid_contact_force(spec, mode)
    elif mode.slip == "stick":
        defs = _mechanics(spec, mode, direction=1)[:-1]  # the forces without Coulomb's F_f, alpha_ddot
        defs = tuple(d for d in defs if d.symbol not in (Q.mu, Q.F_f)) + _stuck_friction(spec, mode)
    else:
        defs = _mechanics(spec, mode)
    geometry_defs = []
    profile, follower = spec.profile, spec.follower
    for sym, expr, note in ((Q.psi_i, dynamics.gap(profile, follower), "gap (Eq. 6)"),
                            (Q.psi_i_dot, dynamics.gap_rate(profile, follower), "Eq. 8"),
                            (Q.psi_j, dynamics.psi_j(profile, follower), "Eq. 7")):
        if sym not in {d.symbol for d in defs}:
            geometry_defs.append(Definition(sym, plain(expr, spec.motion), note))
    defs = tuple(geometry_defs) + defs
    names = {d.symbol for d in defs}
    kinematic = plain(dynamics.sliding_velocity("kinematic", profile, follower), spec.motion)
    if Q.v_r in names and spec.sliding_velocity == "kinematic":
        v_kin = Q.v_r
    else:
        v_kin = quantity("v_r_kinematic")
        defs += (Definition(v_kin, kinematic, "relative velocity of the contact points along the bar"),)
    v_r_out = Q.v_r if Q.v_r in names else v_kin
    forces = dynamics.Forces(Q.F_s, Q.F_n if r else zero, Q.F_f if Q.F_f in names else zero, v_r_out)
    inertia, V_s, dV_s, V_c = _energy_terms(spec.contact, profile, follower)
    q = coordinate(spec)
    E = inertia * q.rate**2 / 2 + V_s + (V_c if r else zero)
    if r is None:  # free flight: no contact force, nothing delivered or dissipated
        dE_dt = D_c = D_f = zero
    elif rigid_law:  # no deflection, no damping law: the impacts' losses are jumps of the energy, not flows
        D_c, D_f = zero, forces.F_f * v_kin
        dE_dt = (inertia * q.acceleration + dV_s) * q.rate
    else:
        F_d = -Q.c_lambda * Q.psi_i_dot  # the damping part of F_n (Eq. 12)
        D_c, D_f = -F_d * Q.psi_i_dot, forces.F_f * v_kin
        dE_dt = (inertia * q.acceleration + dV_s) * q.rate + V_c.diff(Q.psi_i) * Q.psi_i_dot
    outputs_names = tuple(outputs_of(follower))
    rigid = RIGID_OUTPUT[follower]
    named = [(quantity("N_x"), plain(dynamics.bearing_force_x(forces, follower), spec.motion),
              "bearing force (Eq. 35)" if follower == dynamics.OSCILLATING else "the guide's reaction across it"),
             (quantity(rigid), _rigid_contact_output(spec), "follower angle in rigid contact (Eq. 29)"
              if follower == dynamics.OSCILLATING else "the follower in rigid contact, h(gamma - Theta)"),
             (quantity("energy"), E, "T + V_s + V_c (Section 5)"),
             (quantity("D_c"), D_c, "power dissipated by contact damping"),
             (quantity("D_f"), D_f, "power dissipated by friction"),
             (quantity("P_in"), dE_dt + quantity("D_c") + quantity("D_f"),
              "power of the cam drive: dE/dt + D_c + D_f")]
    defs += tuple(Definition(sym, expr, note) for sym, expr, note in named)
    values = {"psi_i": Q.psi_i, "psi_j": Q.psi_j, "psi_i_dot": Q.psi_i_dot, "F_s": Q.F_s, "F_n": forces.F_n,
              "F_f": forces.F_f, "v_r": v_r_out}
    results = tuple(values.get(name, quantity(name)) for name in outputs_names)
    return Kernel(defs, results).pruned()


def _rigid_contact_output(spec: SceneSpec) -> sp.Expr:
    """alpha_i (Eq. 29, misprint 10) on the paper's circle; NaN on any other cam, where the
    rigid contact angle is the root of psi_i(alpha, Theta) = 0, with no closed form (the
    OUTPUTS entry says so).  The translating follower's y_i = h(gamma - Theta) on any cam."""
    if spec.follower == dynamics.TRANSLATING:
        return plain(dynamics._on_cam(spec.profile, translating.rigid_coordinate()), spec.motion)
    if spec.profile == dynamics.ECCENTRIC:
        return plain(geometry.rigid_contact_angle(S.Theta), spec.motion)
    return sp.nan
