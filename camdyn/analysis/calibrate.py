"""Calibration: fit unknown rig parameters to quantities camdyn computes.

The paper identified its damping constants by matching model output to measurements
(Section 4); the same is needed for any rig whose geometry or inertia is not known.
:func:`calibrate` fits chosen *unknowns* of a :class:`~camdyn.Rig` (with bounds, on a
log or linear scale) to *targets*: measured or reported values of quantities that camdyn
computes from a rig, by weighted non-linear least squares
(:func:`scipy.optimize.least_squares`, trust-region reflective, bounded).

Targets are built with the helpers below or from any callable of the rig::

    import camdyn
    from camdyn.analysis import calibrate as cal

    rig = camdyn.load_rig("example")
    result = cal.calibrate(
        rig,
        unknowns=[cal.Unknown("I_Pb", 1e-4, 1.0), cal.Unknown("w_b", 1e-3, 0.05)],
        targets=[
            cal.natural_frequency(2182.0, camdyn.Scene(), camdyn.ConstantSpeed(300), digits=4, name="f_de"),
            cal.natural_frequency(2125.0, camdyn.Scene(), camdyn.ConstantSpeed(-300), digits=4, name="f_se"),
        ],
        fixed={"chi0": "measured on the drawing"},
    )
    print(result.report())          # fitted values, residual per target, degrees of freedom
    fitted = result.rig

Each target has an uncertainty ``sigma`` (absolute, in the target's unit; by default the
value itself, i.e. a relative residual; ``digits=n`` makes it half a unit of the n-th
significant digit, the rounding of a printed number). The least-squares residual of a
target is ``(computed - value) / sigma``.

A target can be measured on a *variant* of the rig (another spring, another contact
length): ``settings={"k_s": 26.0, "l_lambda": 0.016}`` replaces those parameters before
computing it. A setting given as a string names an *extra unknown*, a parameter of the
variant only (e.g. the experiment's spring ``"k_s_exp"``), fitted with the others:
``Unknown("k_s_exp", 1, 2000)`` with ``settings={"k_s": "k_s_exp"}``.

``tied={"e": lambda p: 0.1 * p["r_c"]}`` keeps a parameter a fixed function of the
others (``p`` maps every rig parameter and extra unknown to its current value).

The result states the degrees of freedom: how many targets, how many unknowns, the
numerical rank of the weighted Jacobian at the solution (how many independent
combinations the targets actually pin down), and which parameters were fixed by
assumption and why (``fixed``). More unknowns than targets is an error unless
``allow_underdetermined=True``: fix the rest by assumption and say why.

Every public name is imported from here; the unknowns, the targets and the checks of a problem
are defined in ``calibration_problem``, the result in ``calibration_result``.
"""
from __future__ import annotations

import math
from typing import Any, Callable, Mapping, Sequence

import numpy as np
from scipy.optimize import least_squares

from . import statics as analysis
from ..errors import CamdynError
from ..model.cam import CamMotion
from ..model.rig import Rig
from ..model.scene import Scene
from .calibration_problem import BY_NAME, CalibrationError, Problem, Target, Unknown, rounding_sigma, validate
from .calibration_result import Calibration, DegreesOfFreedom, TargetResidual

__all__ = [
    "CalibrationError",
    "Unknown",
    "Target",
    "TargetResidual",
    "DegreesOfFreedom",
    "Calibration",
    "calibrate",
    "evaluate",
    "rounding_sigma",
    "contact_stiffness",
    "natural_frequency",
    "contact_loss_speed",
    "equilibrium_angle",
    "energy_balance_saturation",
    "energy_balance_peak",
]


# ----------------------------------------------------------------------------- targets of camdyn's analyses


def _kw(name, default, kw):
    kw.setdefault("name", name or default)
    return kw


def contact_stiffness(value: float, contact: str = "line", *, name: str | None = None, **kw) -> Target:
    """Contact stiffness k_lambda(psi_i*) at the static equilibrium, N/m (Eq. 13 or 34; the
    secant stiffness, as the paper quotes it: misprint 5)."""
    kw = _kw(name, f"k_{contact}", kw)
    kw.setdefault("unit", "N/m")
    return Target(value=value, compute=lambda rig: analysis.static_equilibrium(rig, contact).contact_stiffness, **kw)


def natural_frequency(value_Hz: float, scene: Scene | None = None, cam: CamMotion | None = None, *,
                      name: str | None = None, **kw) -> Target:
    """Linearized natural frequency in Hz at the static equilibrium (Eqs. 21-23) for a scene;
    the cam's rotation sense sets the friction direction (Section 7.1)."""
    scene = scene or Scene(damping="none", friction="none")
    kw = _kw(name, f"f_{scene.slug}", kw)
    kw.setdefault("unit", "Hz")
    return Target(value=value_Hz, compute=lambda rig: analysis.natural_frequency(rig, scene, cam).Hz, **kw)


def contact_loss_speed(value_rpm: float, *, name: str | None = None, **kw) -> Target:
    """Cam speed (rev/min) above which the follower leaves the cam, by inverse kinematics
    (Section 4; :func:`camdyn.analysis.statics.contact_loss_speed`)."""
    kw = _kw(name, "contact_loss", kw)
    kw.setdefault("unit", "rev/min")
    return Target(value=value_rpm, compute=lambda rig: analysis.contact_loss_speed(rig), **kw)


def equilibrium_angle(value_rad: float, contact: str = "line", *, name: str | None = None, **kw) -> Target:
    """The static equilibrium angle alpha* in rad (Eqs. 16-18)."""
    kw = _kw(name, "alpha_star", kw)
    kw.setdefault("unit", "rad")
    return Target(value=value_rad, compute=lambda rig: analysis.static_equilibrium(rig, contact).alpha, **kw)


def energy_balance_saturation(value_rad: float, contact: str = "line", *, name: str | None = None, **kw) -> Target:
    """The value at which the energy-balance alpha_rp saturates as the speed grows
    (Section 5, Fig. 8): pi/2 - alpha*, the follower swung to 90 degrees."""
    kw = _kw(name, "alpha_rp_saturation", kw)
    kw.setdefault("unit", "rad")
    return Target(value=value_rad,
                  compute=lambda rig: math.pi / 2 - analysis.static_equilibrium(rig, contact).alpha, **kw)


def energy_balance_peak(value_rad: float, speed_rpm: float, xi: float, *, potential: str = "printed",
                        name: str | None = None, **kw) -> Target:
    """alpha_rp from the approximate energy balance at one speed and restitution xi (Eqs. 30-33)."""
    kw = _kw(name, f"alpha_rp_energy_{speed_rpm:g}rpm_xi{xi:g}", kw)
    kw.setdefault("unit", "rad")
    return Target(value=value_rad,
                  compute=lambda rig: analysis.energy_balance_peak(rig, speed_rpm, xi, potential=potential), **kw)


# ----------------------------------------------------------------------------- the fit


def _apply(rig: Rig, unknowns, values: Mapping[str, float], tied) -> tuple[Rig, dict]:
    rig_changes = {u.name: values[u.name] for u in unknowns if u.name in BY_NAME}
    extras = {u.name: values[u.name] for u in unknowns if u.name not in BY_NAME}
    if tied:
        current = {**{k: v for k, v in rig.to_dict().items() if k in BY_NAME}, **rig_changes, **extras}
        for k, fn in tied.items():
            rig_changes[k] = float(fn(current))
            current[k] = rig_changes[k]
    return rig.replace(**rig_changes), extras


def evaluate(rig: Rig, targets: Sequence[Target], extras: Mapping[str, float] | None = None
             ) -> tuple[TargetResidual, ...]:
    """Compute every target on ``rig`` (with its settings), without fitting."""
    out = []
    for t in targets:
        try:
            computed = float(t.compute(t.variant(rig, extras)))
        except CalibrationError:
            raise
        except (CamdynError, ValueError, ArithmeticError) as exc:
            raise CalibrationError(f"target {t.name!r} cannot be computed on this rig: {exc}") from exc
        out.append(TargetResidual(t.name, float(t.value), computed, t.uncertainty, t.unit, t.source))
    return tuple(out)


def calibrate(rig: Rig, unknowns: Sequence[Unknown], targets: Sequence[Target], *,
              fixed: Mapping[str, str] | None = None,
              tied: Mapping[str, Callable[[Mapping[str, float]], float]] | None = None,
              allow_underdetermined: bool = False, rank_rtol: float = 1e-6,
              name: str | None = None, description: str | None = None,
              **least_squares_options) -> Calibration:
    """Fit ``unknowns`` of ``rig`` so that the ``targets`` computed from it match their values.

    Parameters
    ----------
    rig : Rig
        The starting rig: every parameter not fitted keeps its value here.
    unknowns : sequence of Unknown
        The parameters to fit, with bounds and scale.
    targets : sequence of Target
        The quantities to match (see :func:`contact_stiffness`, :func:`natural_frequency`,
        :func:`contact_loss_speed`, :func:`energy_balance_saturation`, or ``Target`` with
        any callable of the rig).
    fixed : mapping, optional
        Parameters fixed by assumption, each with the reason its value is plausible; they
        are recorded in the degrees-of-freedom statement.
    tied : mapping, optional
        Parameters computed from the others, e.g. ``{"e": lambda p: 0.1 * p["r_c"]}``.
    allow_underdetermined : bool
        Allow more unknowns than targets (the result then depends on the initial values).
    rank_rtol : float
        Singular values of the weighted Jacobian below ``rank_rtol`` times the largest
        count as zero in the rank.
    name, description : str, optional
        Name and description of the fitted rig.
    **least_squares_options
        Passed to :func:`scipy.optimize.least_squares` (``xtol``, ``ftol``, ``max_nfev``...).

    Raises
    ------
    CalibrationError
        On an ill-posed problem (naming the parameter or target), or if a target cannot be
        computed on the starting rig.
    """
    problem = validate(rig, unknowns, targets, fixed, tied, allow_underdetermined)
    _check_start(rig, problem)
    sol, failures = _least_squares(rig, problem, least_squares_options)
    fitted = _unpack(problem.unknowns, sol.x)
    final_rig, extras = _apply(rig, problem.unknowns, fitted, problem.tied)
    changes = {k: v for k, v in (("name", name), ("description", description)) if v is not None}
    if changes:
        final_rig = final_rig.replace(**changes)
    results = evaluate(final_rig, problem.targets, extras)
    J = np.asarray(sol.jac, dtype=float)
    message = sol.message if sol.success else f"did not converge: {sol.message}"
    if failures:
        message += f" ({len(failures)} trial point(s) could not be evaluated, e.g.: {failures[0]})"
    return Calibration(final_rig, fitted, extras, results, _degrees_of_freedom(J, sol.active_mask, problem, rank_rtol),
                       problem.unknowns, problem.targets, problem.initial, _sensitivity(J, problem, fitted, results),
                       bool(sol.success), message, float(sol.cost), int(sol.nfev))


def _unpack(unknowns: tuple[Unknown, ...], z) -> dict[str, float]:
    """The unknowns' values from the internal variables, clipped to their bounds."""
    return {u.name: min(max(u.from_internal(zi), u.lower), u.upper) for u, zi in zip(unknowns, z)}


def _check_start(rig: Rig, problem: Problem) -> None:
    """The starting values give a valid rig on which every target can be computed (else an
    error naming the target)."""
    try:
        start_rig, start_extras = _apply(rig, problem.unknowns, problem.initial, problem.tied)
    except CamdynError as exc:
        raise CalibrationError(f"the starting values give an invalid rig: {exc}") from exc
    evaluate(start_rig, problem.targets, start_extras)


#: the residual of every target at a trial point where some target cannot be computed
PENALTY = 1e6


def _least_squares(rig: Rig, problem: Problem, overrides: Mapping[str, Any]):
    """scipy's least_squares on the weighted residuals (computed - value) / sigma in the internal
    variables; (its solution, the messages of the trial points that could not be evaluated)."""
    unknowns, targets = problem.unknowns, problem.targets
    sigmas = np.array([t.uncertainty for t in targets])
    values = np.array([float(t.value) for t in targets])
    failures: list[str] = []

    def residuals(z):
        try:
            current, extras = _apply(rig, unknowns, _unpack(unknowns, z), problem.tied)
            computed = np.array([float(t.compute(t.variant(current, extras))) for t in targets])
        except (CamdynError, ValueError, ArithmeticError) as exc:
            failures.append(str(exc))
            return np.full(len(targets), PENALTY)
        r = (computed - values) / sigmas
        return np.where(np.isfinite(r), r, PENALTY)

    z0 = np.array([u.to_internal(problem.initial[u.name]) for u in unknowns])
    lower, upper = zip(*(u.internal_bounds() for u in unknowns))
    options = {"method": "trf", "x_scale": 1.0, "xtol": 1e-12, "ftol": 1e-12, "gtol": 1e-12,
               "diff_step": 1e-7, "max_nfev": 400 * (len(unknowns) + 1)}
    options.update(overrides)
    if len(targets) < len(unknowns) and options["method"] == "lm":
        raise CalibrationError("method='lm' needs at least as many targets as unknowns")
    sol = least_squares(residuals, z0, bounds=(np.array(lower), np.array(upper)), **options)
    return sol, failures


def _degrees_of_freedom(J: np.ndarray, active_mask, problem: Problem, rank_rtol: float) -> DegreesOfFreedom:
    """What the targets determine, from the weighted Jacobian at the solution (internal variables)."""
    s = np.linalg.svd(J, compute_uv=False) if J.size else np.zeros(0)
    rank = int(np.sum(s > rank_rtol * s.max())) if s.size and s.max() > 0 else 0
    at_bounds = tuple(u.name for u, active in zip(problem.unknowns, active_mask) if active != 0)
    return DegreesOfFreedom(len(problem.targets), len(problem.unknowns), rank, tuple(float(v) for v in s),
                            dict(problem.fixed), tuple(problem.tied), at_bounds)


def _sensitivity(J: np.ndarray, problem: Problem, fitted: Mapping[str, float], results) -> np.ndarray:
    """d log(computed) / d log(unknown), targets x unknowns, from J = d((c - v)/sigma)/dz."""
    sigmas = np.array([t.uncertainty for t in problem.targets])
    computed = np.array([r.computed for r in results])
    sens = np.full((len(problem.targets), len(problem.unknowns)), np.nan)
    for j, u in enumerate(problem.unknowns):
        dz_dlogx = 1.0 if u.log else fitted[u.name] / (u.upper - u.lower if math.isfinite(u.upper - u.lower) else 1.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            sens[:, j] = J[:, j] * sigmas * dz_dlogx / computed
    return sens
