"""A grazing curve (:func:`camdyn.orbits.continuation.continue_grazing`) as a self-describing
``xarray.Dataset``: units and long names on every variable, the scene, the rig's parameters,
the settings and camdyn's version in its attributes."""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..._version import __version__
from ...model.rig import PARAMETERS
from ...vocabulary import STATE, STATE_ALPHA, STATE_ALPHA_DOT
from ..shooting import sorted_multipliers
from .grazing_curve import CODIM2, GrazingOutcome
from .problem import N_STATE, SPEED


def unit(parameter: str) -> str:
    """The unit of a continuation parameter: rev/min for the speed, else the rig parameter's (SI)."""
    return "rev/min" if parameter == SPEED else next(p.unit for p in PARAMETERS if p.name == parameter)


def _long_name(parameter: str) -> str:
    return "cam speed" if parameter == SPEED else next(p.description for p in PARAMETERS if p.name == parameter)


def grazing_dataset(system, curve, layout, settings):
    """The curve as an ``xarray.Dataset``.

    Dims ``point`` (every grazing orbit, in the order continued), ``multiplier`` (2, by
    decreasing modulus), ``codim2`` (the codimension-2 points).  Per point: the two parameters
    by their names (attrs ``free``: lambda1, at zero gap; ``parameter``: lambda2), lambda1 of
    the orbit itself, converged at psi_i(t_g) = -margin (``<free>_orbit``), ``alpha``, ``alpha_dot``
    at the section, ``grazing_time`` (t_g - t0, s after the section) and ``grazing_phase``
    (its fraction of T), ``grazing_gap`` (psi_i at t_g, m: within [-3, -1] gap_tol of the
    deflection scale, the contact side; on a rigid contact -F_n, N, within [-3, -1] gap_tol of
    the force's scale: :mod:`.boundary`), ``multiplier_real``/``_imag``/``_modulus`` (the
    grazing orbit's, contact side), ``stable``, ``residual`` (scaled), ``iterations`` and
    ``one_sided`` (a lambda-derivative was one-sided there).  Per codimension-2 point:
    ``codim2_kind`` (code into attrs ``codim2_kinds``), both parameters (``codim2_<name>``),
    ``codim2_point`` (the point just before it), ``codim2_multiplier_real``/``_imag``.  Attrs:
    ``outcome`` (a :class:`GrazingOutcome` name) and ``outcome_message``, ``boundary``
    (``grazing``, or ``lift_off`` on a rigid contact), its scale (``deflection_scale_m``, or
    ``force_scale_n``), ``phase_pinned_at_corner`` (1 or 0), the range, the scene,
    ``rig_<parameter>`` (SI), the settings (``settings_<name>``), the scales, ``camdyn_version``.
    """
    import xarray as xr

    points = curve.points
    data = {**_point_variables(system, points), **codim2_variables(system, curve.found, lambda at: at.grazing)}
    return xr.Dataset(data, attrs=_attributes(system, curve, layout, settings))


def _point_variables(system, points) -> dict:
    P, PM = ("point",), ("point", "multiplier")
    mu = np.array([sorted_multipliers(p.M) for p in points], dtype=complex).reshape(len(points), N_STATE)
    T = np.array([p.evaluation.section_map.model.period for p in points])
    phase = np.array([p.phase for p in points])
    return {
        system.free: (P, np.array([p.grazing for p in points]),
                      {"units": unit(system.free), "long_name": f"{_long_name(system.free)} at grazing (zero gap, "
                                                                "one Newton step from the orbit at -margin)"}),
        f"{system.free}_orbit": (P, np.array([p.free for p in points]),
                                 {"units": unit(system.free), "long_name": f"{_long_name(system.free)} of the "
                                                                           "orbit converged at psi_i(t_g) = -margin"}),
        system.parameter: (P, np.array([p.lam for p in points]), {"units": unit(system.parameter),
                                                                  "long_name": _long_name(system.parameter)}),
        "alpha": (P, np.array([p.x[STATE_ALPHA] for p in points]),
                  {"units": "rad", "long_name": "alpha at the section"}),
        "alpha_dot": (P, np.array([p.x[STATE_ALPHA_DOT] for p in points]),
                      {"units": "rad/s", "long_name": "alpha_dot at the section"}),
        "grazing_time": (P, phase * T, {"units": "s", "long_name": "time of the largest gap after the section"}),
        "grazing_phase": (P, phase, {"units": "1", "long_name": "time of the largest gap after the section, "
                                                                "a fraction of the cam period"}),
        "grazing_gap": (P, np.array([p.evaluation.psi_g for p in points]),
                        {"units": system.boundary.unit, "long_name": f"{system.boundary.meaning} at its largest "
                                                                     "(the contact side)"}),
        "multiplier_real": (PM, mu.real, {"units": "1", "long_name": "Floquet multiplier at grazing (contact side), "
                                                                    "real part"}),
        "multiplier_imag": (PM, mu.imag, {"units": "1", "long_name": "Floquet multiplier at grazing (contact side), "
                                                                    "imaginary part"}),
        "multiplier_modulus": (PM, np.abs(mu), {"units": "1", "long_name": "|Floquet multiplier| at grazing"}),
        "stable": (P, np.all(np.abs(mu) < 1.0, axis=1), {"long_name": "every |multiplier| < 1 (contact side)"}),
        "residual": (P, np.array([float(np.max(np.abs(p.evaluation.residual))) for p in points]),
                     {"units": "1", "long_name": "scaled residual of the extended system"}),
        "iterations": (P, np.array([p.iterations for p in points], dtype=int),
                       {"long_name": "corrector iterations"}),
        "one_sided": (P, np.array([bool(p.derivatives.note) for p in points], dtype=bool),
                      {"long_name": "a parameter derivative was one-sided (the other side lifts off)"}),
    }


def codim2_variables(system, found, free) -> dict:
    """The codimension-2 points ``found`` (:class:`.grazing_curve.Codim2`) along dim ``codim2``:
    ``codim2_kind`` (an index into :data:`.grazing_curve.CODIM2`, the attribute
    ``codim2_kinds``), both parameters (``codim2_<name>``; lambda1 is ``free(orbit)``),
    ``codim2_point`` (the point just before it), ``codim2_multiplier_real``/``_imag``."""
    C, CM = ("codim2",), ("codim2", "multiplier")
    kinds = list(CODIM2)
    mu = np.array([sorted_multipliers(c.at.M) for c in found], dtype=complex).reshape(-1, N_STATE)
    return {
        "codim2_kind": (C, np.array([kinds.index(c.kind) for c in found], dtype=int),
                        {"long_name": "kind (index into the attribute codim2_kinds)"}),
        f"codim2_{system.free}": (C, np.array([free(c.at) for c in found]), {"units": unit(system.free)}),
        f"codim2_{system.parameter}": (C, np.array([c.at.lam for c in found]), {"units": unit(system.parameter)}),
        "codim2_point": (C, np.array([c.point for c in found], dtype=int),
                         {"long_name": "index of the point just before it"}),
        "codim2_multiplier_real": (CM, mu.real, {"units": "1"}),
        "codim2_multiplier_imag": (CM, mu.imag, {"units": "1"}),
    }


def common_attributes(system, curve, scale) -> dict:
    """The attributes every two-parameter curve's Dataset has: the parameters, their units and
    range, the section, the scene, the outcome, the scales, the solver, the rig's parameters,
    camdyn's version."""
    outcome = curve.outcome or GrazingOutcome.STEP_TOO_SMALL
    return {
        "source": f"camdyn {__version__}", "camdyn_version": __version__,
        "free": system.free, "free_units": unit(system.free), "parameter": system.parameter,
        "parameter_units": unit(system.parameter), "start": system.start, "end": system.end,
        "speed_rpm": math.nan if system.speed_rpm is None else float(system.speed_rpm),
        "phase_fraction": system.phase_fraction, "scene": system.scene.slug,
        "outcome": outcome.name, "outcome_message": outcome.message + (f" ({curve.message})" if curve.message else ""),
        "outcomes": " ".join(o.name for o in GrazingOutcome),
        **{f"scale_{name}": float(scale[i]) for i, name in enumerate(STATE)},
        "solver_method": system.options.method, "solver_rtol": system.options.rtol,
        "solver_atol": system.options.atol, "backend": system.backend,
        "rig_name": system.rig.name,
        **{f"rig_{p.name}": float(getattr(system.rig, p.name)) for p in PARAMETERS
           if getattr(system.rig, p.name) is not None},
        "rig_units": "; ".join(f"{p.name} {p.unit}" for p in PARAMETERS),
    }


def _attributes(system, curve, layout, settings) -> dict:
    scale = np.full(N_STATE, math.nan) if layout is None else layout.scale
    plain = {**dataclasses.asdict(settings.continuation), "gap_tol": settings.gap_tol,
             **{f"search_{k}": v for k, v in dataclasses.asdict(settings.search).items()}}
    return {
        "title": f"camdyn grazing curve in ({system.free}, {system.parameter}), rig {system.rig.name}",
        **common_attributes(system, curve, scale),
        "codim2_kinds": " ".join(CODIM2), "boundary": system.boundary.kind,
        system.boundary.scale_attribute: system.deflection, "phase_pinned_at_corner": int(system.pinned),
        **{f"settings_{k}": v for k, v in plain.items()},
    }
