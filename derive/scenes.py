"""A scene's generated module, as data: its automaton and the functions to emit.

:func:`build` turns a :class:`SceneSpec` into a :class:`SceneModule`: the hybrid automaton
(:mod:`derive.automaton`) and one :class:`Function` per generated kernel, each a set of
:class:`Case`\\ s (one per mode, or per surface and mode) holding named definitions
(:mod:`derive.fields`).  :mod:`derive.codegen` writes the text.

Kernels (arguments in the order of the generated module's docstring), in the scene's module
``scene_<slug>``, the one a run imports:

  rhs(m, t, alpha, alpha_dot, p)              alpha_ddot in mode m
  surface(m, s, t, alpha, alpha_dot, p)       the value of surface s under mode m's laws
  surface_with_rate(m, s, t, alpha, alpha_dot, p, out)
                                              out[:] = the values of surface s and of its declared
                                              rate, each computed as surface computes it
  jacobian(m, t, alpha, alpha_dot, p, out)    out[:] = d(alpha_ddot)/d(alpha, alpha_dot)
  outputs(m, t, alpha, alpha_dot, p, out)     out[:] = the OUTPUTS
  cam(t, p)                                   Theta and its rates (built-in motions; arrays too)
  static_moment, reach, rigid_contact, spring_potential: run-independent (equilibrium, Eq. 29)

and the variational kernels, in its companion module ``variational_<slug>``, which only the
tangent dynamics and the parameter continuation import (:attr:`SceneModule.variational`):

  field_sensitivity(m, t, alpha, alpha_dot, p, out)
                                              out[:] = d(alpha_ddot)/d(SENSITIVITY), the continuation
                                              parameters (non-linear model)
  surface_gradient(m, s, t, alpha, alpha_dot, p, out)
                                              out[:] = dh/d(alpha, alpha_dot), dh/dt of surface s
                                              under mode m's laws, for the surfaces m watches
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from functools import lru_cache

import sympy as sp

from . import dynamics, energy, equilibrium, fields, geometry, laws, rigid, translating
from .dynamics import Q
from . import symbols as S
from .automaton import Automaton, build as build_automaton
from .fields import Kernel, motion_substitution
from .graph import Definition, derivative_symbol, derivatives, quantity
from camdyn.vocabulary import (ECCENTRIC, CAM_STATE, OPTIONS, OUTPUTS, RESET_JACOBIAN, STATIC_LOAD, SURFACE_WITH_RATE,
                               SceneOptionError,
                               SceneSpec, outputs_of, state_names)

SceneSpecError = SceneOptionError  # the name derive used before the shared vocabulary


@dataclass(frozen=True)
class Case:
    """The kernel of one value of the dispatch arguments (a mode; a surface and a mode)."""

    key: tuple[int, ...]
    kernel: Kernel


@dataclass(frozen=True)
class Function:
    """One generated function.

    ``dispatch``: the arguments that select a case (e.g. ``("m",)``), in ``args``;
    ``style``: how results come back: "return" (one float), "fill" (written to ``out``),
    "tuple" (a tuple of floats), "numpy" (a tuple of arrays or floats, NumPy-printed),
    "separate" (written to ``out``, each result computed from the definitions it needs alone,
    with its own common subexpressions: the same arithmetic as a function returning it alone).
    """

    name: str
    args: tuple[str, ...]
    dispatch: tuple[str, ...]
    results: tuple[str, ...]
    cases: tuple[Case, ...]
    doc: str
    style: str = "return"


@dataclass(frozen=True)
class SceneModule:
    """A scene's kernels: ``functions`` for its module, ``variational`` for its companion
    module (empty for a scene without them: the linear models)."""

    spec: SceneSpec
    automaton: Automaton
    functions: tuple[Function, ...]
    variational: tuple[Function, ...] = ()


def _state_args(spec: SceneSpec, *dispatch: str, out: bool = False) -> tuple[str, ...]:
    """A kernel's arguments: ``dispatch``, t, the state (the follower's coordinate and its rate:
    alpha, alpha_dot or y, y_dot), p, the user's cam state and ``out``."""
    cam = ("cam",) if spec.motion == "user" else ()
    return dispatch + ("t",) + state_names(spec.follower) + ("p",) + cam + (("out",) if out else ())


def _mode_cases(automaton: Automaton, kernel_of) -> tuple[Case, ...]:
    return tuple(Case((i,), kernel_of(mode)) for i, mode in enumerate(automaton.modes))


def _surface_cases(spec: SceneSpec, automaton: Automaton) -> tuple[Case, ...]:
    out = []
    for m, mode in enumerate(automaton.modes):
        for s, name in enumerate(automaton.surfaces):
            kernel = fields.surface(spec, mode, name)
            if kernel is not None:
                out.append(Case((m, s), kernel))
    return tuple(out)


def _rate_cases(spec: SceneSpec, automaton: Automaton) -> tuple[Case, ...]:
    """Each surface with a declared rate (``automaton.rates``) with that rate, under each mode's
    laws where both have a meaning: the results of the two surface kernels, in one case."""
    out = []
    for m, mode in enumerate(automaton.modes):
        for s, name in enumerate(automaton.surfaces):
            value = fields.surface(spec, mode, name) if name in automaton.rates else None
            rate = fields.surface(spec, mode, automaton.rates[name]) if value is not None else None
            if rate is not None:
                out.append(Case((m, s), Kernel(value.definitions + rate.definitions, value.results + rate.results)))
    return tuple(out)


def _gradient_cases(spec: SceneSpec, automaton: Automaton) -> tuple[Case, ...]:
    """The gradient of each surface a mode watches (its transitions'), under the mode's laws."""
    out = []
    for m, mode in enumerate(automaton.modes):
        watched = {tr.surface for tr in automaton.watched(mode.name)}
        for s, name in enumerate(automaton.surfaces):
            kernel = fields.surface_gradient(spec, mode, name) if name in watched else None
            if kernel is not None:
                out.append(Case((m, s), kernel))
    return tuple(out)


def _single(*results: sp.Expr) -> tuple[Case, ...]:
    return (Case((), Kernel((), tuple(results))),)


def _stiffness_at_rest(spec: SceneSpec, psi_i: sp.Expr, radius: sp.Expr) -> sp.Expr:
    """k_lambda(psi_i*) (Eq. 13 or 34, secant); infinite for the rigid law."""
    return sp.oo if spec.contact == "rigid" else laws.contact_stiffness(spec.contact, psi_i, radius)


def _reset_cases(spec: SceneSpec, A: Automaton) -> tuple[Case, ...]:
    """Each reset of the automaton (RESETS): the state after it, (q, q_dot+): the identity, or the rigid
    law's impact (Newton's law) and plastic impact (derive.rigid)."""
    q = fields.coordinate(spec)
    psi_dot = fields.plain(dynamics.gap_rate(spec.profile, spec.follower), spec.motion)
    cases = []
    for j, name in enumerate(A.resets):
        if name == "identity":
            cases.append(Case((j,), Kernel((), (q.plain, q.rate))))
            continue
        rate = rigid.impact_rate(Q.psi_i_dot, q) if name == "impact" else rigid.plastic_rate(Q.psi_i_dot, q)
        after = sp.Symbol(f"{q.rate.name}_after", real=True)
        defs = (Definition(Q.psi_i_dot, psi_dot, "gap rate before the impact (Eq. 8)"),
                rigid.gap_rate_partials(psi_dot, q)[2],
                Definition(after, rate, "Newton's impact law: psi_i_dot leaves at -xi times its arrival"
                           if name == "impact" else "a plastic impact: psi_i_dot leaves at 0 (a chatter's end)"))
        cases.append(Case((j,), Kernel(defs, (q.plain, after))))
    return tuple(cases)


def _reset_jacobian_cases(spec: SceneSpec, A: Automaton) -> tuple[Case, ...]:
    """Each reset's Jacobian: the derivatives of the state after it, (q+, q_dot+), by q, q_dot and t (at a
    fixed state, through the cam's motion), by the chain rule through its named quantities, in the order
    of RESET_JACOBIAN."""
    q = fields.coordinate(spec)
    cases = []
    for case in _reset_cases(spec, A):
        after = tuple(Definition(quantity(f"state_{k}_after"), r, "the state after the reset")
                      for k, r in enumerate(case.kernel.results))
        named = case.kernel.definitions + after
        by = {x: derivatives(named, x) for x in (q.plain, q.rate, S.t_s)}
        out = tuple(derivative_symbol(d.name, x, by[x]) for d in after for x in (q.plain, q.rate)) + tuple(
            derivative_symbol(d.name, S.t_s, by[S.t_s]) for d in after)
        cases.append(Case(case.key, Kernel(named + sum(by.values(), ()), out).pruned()))
    return tuple(cases)


def _translating_static_functions(spec: SceneSpec) -> list[Function]:
    """The translating follower's kernels that do not depend on a run: the static force along the
    guide at Theta0 (its zero is the equilibrium, as Eqs. 16-18), the follower in rigid contact
    y_i = h(gamma - Theta) with its derivatives in Theta, and the spring's potential."""
    F = S.to_plain(equilibrium.static_load(spec.contact, spec.profile, spec.follower))
    psi_i_star, psi_j_star = (S.to_plain(x) for x in equilibrium.static_gap(spec.profile, spec.follower))
    on_cam = lambda expr: dynamics._on_cam(spec.profile, expr)  # noqa: E731
    radius = S.r_c if spec.profile == ECCENTRIC else S.to_plain(equilibrium.at_rest(
        dynamics.curvature_radius_at_contact(spec.profile, spec.follower)))
    y_i = S.to_plain(on_cam(translating.rigid_coordinate()))
    y_i_th = y_i.diff(S.Theta_s)
    name = STATIC_LOAD[spec.follower]
    return [
        Function(name, ("y", "p"), (), ("F", "dF_dy", "psi_i", "psi_j", "k_lambda"),
                 _single(F, F.diff(S.y_s), psi_i_star, psi_j_star, _stiffness_at_rest(spec, psi_i_star, radius)),
                 "Static force along the guide at Theta0 (F_n - F_s; its zero is the equilibrium y*), its slope, "
                 "psi_i*, psi_j* and the contact stiffness k_lambda(psi_i) (Eq. 13 or 34, secant).", "tuple"),
        Function("rigid_contact", ("Theta", "p"), (), ("y_i", "dy_i_dTheta", "d2y_i_dTheta2", "spring_force"),
                 _single(y_i, y_i_th, y_i_th.diff(S.Theta_s), S.to_plain(on_cam(translating.spring_force(y_i)))),
                 "The follower in rigid contact y_i(Theta) = h(gamma - Theta), its derivatives in Theta, and "
                 "the spring force F_s there.", "tuple"),
        Function("spring_potential", ("y", "p"), (), ("V_s",),
                 _single(S.to_plain(on_cam(translating.spring_potential(S.y_s)))),
                 "The spring's potential F_p (y - y0) + k_s (y - y0)^2 / 2.", "tuple"),
    ]


def _static_functions(spec: SceneSpec) -> list[Function]:
    """Kernels that do not depend on a run: the equilibrium's moment (Eqs. 16-18), the rigid
    contact angle (Eq. 29) and the spring's potentials."""
    if spec.follower != "oscillating":
        return _translating_static_functions(spec)
    M = S.to_plain(equilibrium.static_moment(spec.contact, spec.profile))
    psi_i_star, psi_j_star = (S.to_plain(x) for x in equilibrium.static_gap(spec.profile))
    radius = S.r_c if spec.profile == ECCENTRIC else S.to_plain(
        equilibrium.at_rest(geometry.curvature_radius()))
    static = [
        Function("static_moment", ("alpha", "p"), (), ("M", "dM_dalpha", "psi_i", "psi_j", "k_lambda"),
                 _single(M, M.diff(S.alpha_s), psi_i_star, psi_j_star, _stiffness_at_rest(spec, psi_i_star, radius)),
                 "Static moment about P at Theta0, its slope, psi_i*, psi_j* (Eqs. 16-18) and the contact "
                 "stiffness k_lambda(psi_i) (Eq. 13 or 34, secant).", "tuple"),
        Function("spring_potential", ("alpha", "p"), (), ("V_s", "V_s_printed"),
                 _single(fields.spring_potential(), S.to_plain(energy.spring_potential_printed())),
                 "Spring potential of Eq. 10's moment, and (k_s/2) L^2 of Eq. 33.", "tuple"),
    ]
    if spec.profile != ECCENTRIC:  # no closed form of the rigid contact angle on another cam:
        # the runtime solves it (camdyn.model.followers) and reads the spring's moment here
        return static + [Function("spring_moment", ("alpha", "p"), (), ("spring_moment",),
                                  _single(laws.spring_force(S.alpha_s) * S.d_x),
                                  "The spring's moment F_s d_x about P at the follower angle alpha (Eq. 11).",
                                  "tuple")]
    a_i = S.to_plain(geometry.rigid_contact_angle(S.Theta))
    a_i_th = a_i.diff(S.Theta_s)
    spring_moment = laws.spring_force(S.alpha_s).subs(S.alpha_s, a_i) * S.d_x
    return static[:1] + [
        Function("reach", ("Theta", "p"), (), ("reach_margin",), _single(S.to_plain(geometry.reach_margin(S.Theta))),
                 "|PG_c| - (r_c + w_b/2): where negative, no follower angle touches the cam (check it before "
                 "rigid_contact, whose arcsine needs it positive).", "tuple"),
        Function("rigid_contact", ("Theta", "p"), (), ("alpha_i", "dalpha_i_dTheta", "d2alpha_i_dTheta2",
                                                         "spring_moment"),
                 _single(a_i, a_i_th, a_i_th.diff(S.Theta_s), spring_moment),
                 "Follower angle in rigid contact alpha_i(Theta) (Eq. 29, misprint 10), its derivatives in "
                 "Theta, and the spring moment F_s d_x there.", "tuple"),
    ] + static[1:]


@lru_cache(maxsize=None)
def build(spec: SceneSpec) -> SceneModule:
    """Everything a scene's module holds (see the module docstring)."""
    A = build_automaton(spec)
    A = dataclasses.replace(A, timed=fields.timed_surfaces(spec, A.modes, A.surfaces))
    functions = []
    if spec.motion != "user":
        sub = motion_substitution(spec.motion)
        functions.append(Function("cam", ("t", "p"), (), CAM_STATE,
                                  _single(*(sp.sympify(sub[k]) for k in (S.Theta_s, S.Theta_dot, S.Theta_ddot))),
                                  f"Cam angle and its rates at time t: {spec.motion} motion (Section 7); "
                                  "t may be an array.", "numpy"))
    q, q_dot = state_names(spec.follower)
    functions.append(Function("rhs", _state_args(spec, "m"), ("m",), (f"{q}_ddot",),
                              _mode_cases(A, lambda mode: fields.field(spec, mode)),
                              "Angular acceleration alpha_ddot in mode m: Eq. 10 in contact, Eq. 15 in free "
                              "flight, the Filippov sliding mode on v_r = 0 for a stuck follower." if q == "alpha" else
                              "Acceleration y_ddot along the guide in mode m: m_f y_ddot = F_n - F_s in contact, "
                              "-F_s in free flight (derive.translating)."))
    if A.surfaces:
        functions.append(Function("surface", _state_args(spec, "m", "s"), ("m", "s"), ("value",),
                                  _surface_cases(spec, A),
                                  "The value of switching surface s under mode m's laws (SURFACES); nan where "
                                  "the surface has no meaning in the mode."))
        if A.rates:
            functions.append(Function("surface_with_rate", _state_args(spec, "m", "s", out=True), ("m", "s"),
                                      SURFACE_WITH_RATE, _rate_cases(spec, A),
                                      "Switching surface s's value and its declared rate's (RATE_OF_SURFACE[s]) "
                                      "under mode m's laws, bitwise as surface computes each, in one call: "
                                      "out[WITH_RATE_VALUE] = value, out[WITH_RATE_RATE] = rate "
                                      "(camdyn.vocabulary); nan for a surface without a rate.",
                                      "separate"))
    functions.append(Function("jacobian", _state_args(spec, "m", out=True), ("m",),
                              (f"d{q}_ddot_d{q}", f"d{q}_ddot_d{q_dot}"),
                              _mode_cases(A, lambda mode: fields.jacobian(spec, mode)),
                              f"Second row of the state Jacobian in mode m (Eqs. 21-22): out[0] = "
                              f"d({q}_ddot)/d({q}), out[1] = d({q}_ddot)/d({q_dot}).", "fill"))
    functions.append(Function("outputs", _state_args(spec, "m", out=True), ("m",), tuple(outputs_of(spec.follower)),
                              _mode_cases(A, lambda mode: fields.outputs(spec, mode)),
                              "The output quantities in mode m: out[OUT_<NAME>] for each name of OUTPUTS.",
                              "fill"))
    if len(A.resets) > 1:
        functions.append(Function("reset", ("j", "t", q, q_dot, "p", "out"), ("j",), (q, q_dot), _reset_cases(spec, A),
                                  "The state after reset j (RESETS): out[STATE_ALPHA] = the coordinate, "
                                  "out[STATE_ALPHA_DOT] = its rate (camdyn.vocabulary).", "fill"))
    functions += _static_functions(spec)
    return SceneModule(spec, A, tuple(functions), _variational_functions(spec, A))


def _variational_functions(spec: SceneSpec, A: Automaton) -> tuple[Function, ...]:
    """The kernels of the companion module: the field's parameter derivatives (non-linear model)
    and the switching surfaces' gradients (a scene with transitions)."""
    functions = []
    if spec.model == "nonlinear" and spec.contact != "rigid":  # (the rigid law's: not derived yet)
        names = fields.continuation_parameters(spec, A.modes)
        functions.append(Function("field_sensitivity", _state_args(spec, "m", out=True), ("m",),
                                  tuple(f"d{state_names(spec.follower)[0]}_ddot_d{n}" for n in names),
                                  _mode_cases(A, lambda mode: fields.field_sensitivity(spec, mode, names)),
                                  "Derivatives of alpha_ddot in mode m by the continuation parameters of "
                                  "SENSITIVITY (total: the static equilibrium's alpha*, chi*, vartheta follow "
                                  "them), at a fixed state and time: out[SENS_<NAME>].", "fill"))
    if A.transitions:
        q, q_dot = state_names(spec.follower)
        functions.append(Function("surface_gradient", _state_args(spec, "m", "s", out=True), ("m", "s"),
                                  (f"dh_d{q}", f"dh_d{q_dot}", "dh_dt"), _gradient_cases(spec, A),
                                  "Gradient of switching surface s's value h under mode m's laws, for the "
                                  "surfaces m watches: out[GRAD_D_ALPHA] = dh/dalpha, out[GRAD_D_ALPHA_DOT] = "
                                  "dh/dalpha_dot, out[GRAD_D_T] = dh/dt at a fixed state (through Theta(t)); "
                                  "nan elsewhere.", "fill"))
    if len(A.resets) > 1:
        functions.append(Function("reset_jacobian", ("j", "t") + state_names(spec.follower) + ("p", "out"), ("j",),
                                  RESET_JACOBIAN, _reset_jacobian_cases(spec, A),
                                  "Derivatives of the state after reset j (RESETS) by the state before it and by t "
                                  "at a fixed state, out[RJ_<NAME>] in the order of RESET_JACOBIAN (camdyn.vocabulary): "
                                  "the reset's part of the saltation matrix of an impact.", "fill"))
    return tuple(functions)


__all__ = ["SceneSpec", "SceneSpecError", "Case", "Function", "SceneModule", "build", "OPTIONS", "OUTPUTS",
           "Definition", "quantity"]
