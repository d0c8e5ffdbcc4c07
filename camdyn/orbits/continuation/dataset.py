"""The branches and events of a continuation as an ``xarray.Dataset``, and its events as rows."""
from __future__ import annotations

import math

import numpy as np

from ...model.rig import PARAMETERS
from ...vocabulary import COORDINATES, STATE, STATE_ALPHA, STATE_ALPHA_DOT
from ..shooting import sorted_multipliers
from .events import EVENTS
from .problem import N_STATE, SPEED, ContinuationOutcome, Problem


def _unit(parameter: str) -> str:
    return "rev/min" if parameter == SPEED else next(p.unit for p in PARAMETERS if p.name == parameter)


def branch_dataset(problem: Problem, branches: list, events: list, scale=None):
    """The branches and events as an ``xarray.Dataset``.

    Dims: ``point`` (every orbit of every branch, branch by branch, in the order continued),
    ``multiplier`` (2, by decreasing modulus), ``revolution`` (n of the longest period, NaN
    beyond a point's own), ``event``, ``branch`` (a coordinate: 0, 1, ...).  Per point:
    ``lambda`` (the parameter, its unit), ``alpha`` and ``alpha_dot`` at the section (the follower's
    coordinate and rate, named in the attribute ``coordinate``: the translating follower's y, m),
    ``multiplier_real``/``_imag``/``_modulus`` (NaN where unresolved), ``resolved`` (the point's
    derivatives passed the rule of :mod:`camdyn.orbits.derivatives`), ``stable`` (resolved and every
    ``|mu| < 1``), ``jacobian_provider`` (code into attrs ``providers``), ``difference_step``
    (the central-difference steps, dim ``difference``: alpha rad, alpha_dot rad/s, lambda; NaN
    where not by differences), ``max_gap`` (the largest psi_i over the orbit, m: < 0 in
    permanent contact), ``point_branch`` (the branch it is on), ``periods``, ``mode`` (code into
    attrs ``modes``), ``residual``, ``alpha_revolution`` (alpha at the starts of the orbit's
    revolutions: the points of the brute-force diagram), ``impact_angle`` (dim ``impact``, the most
    impacts of any orbit, at least 1: the cam's body angle phi, rad in [0, 2 pi), at which each
    Newton impact of the orbit lands, in time order from the section, NaN beyond its own and on a
    compliant scene: :class:`.corners.Landings`; the profile's junctions, where a ``corner_impact``
    lands, are ``rig.profile.junctions()``).  Per event: ``event_kind`` (code into
    ``event_kinds``), ``event_lambda``, ``event_alpha``, ``event_alpha_dot``, ``event_branch``,
    ``event_point`` (the point just before it), ``event_max_gap``, ``event_multiplier_real``/
    ``_imag``, ``event_alpha_revolution``.  Per branch: ``branch_periods``, ``branch_parent``
    (-1: none), ``branch_origin`` (the event it was switched to at, -1: none: a period-doubled
    branch is drawn from there), ``branch_outcome`` (code into ``outcomes``), and the messages as
    attrs ``branch_<i>_message``; attrs ``scale_alpha`` (rad) and ``scale_alpha_dot`` (rad/s): the
    size of the motion at the start, the residual's scale.
    """
    import xarray as xr

    unit, outcomes = _unit(problem.parameter), list(ContinuationOutcome)
    n_rev = max([b.periods for b in branches] + [1])
    providers = sorted({p.derivation.provider for b in branches for p in b.points})
    data = {**_point_variables(problem, branches, unit, n_rev, providers),
            **_event_variables(problem, branches, events, unit, n_rev), **_branch_variables(branches, outcomes)}
    s = np.full(N_STATE, np.nan) if scale is None else np.asarray(scale, dtype=float)
    attrs = {"parameter": problem.parameter, "parameter_units": unit, "start": problem.start, "end": problem.end,
             "speed_rpm": problem.speed_rpm if problem.speed_rpm is not None else math.nan,
             "phase_fraction": problem.phase_fraction, "rig": problem.rig.name, "scene": problem.scene.slug,
             "modes": " ".join(problem.model(problem.start).kernels.MODES), "event_kinds": " ".join(EVENTS),
             "outcomes": " ".join(o.name for o in outcomes), "providers": " ".join(providers),
             "coordinate": _coordinate(problem)[0],
             **{f"scale_{name}": float(s[i]) for i, name in enumerate(STATE)}}
    for i, b in enumerate(branches):
        attrs[f"branch_{i}_message"] = f"{b.outcome.message}" + (f" ({b.message.strip('; ')})" if b.message else "")
    return xr.Dataset(data, coords={"branch": np.arange(len(branches))}, attrs=attrs)


def _branch_variables(branches: list, outcomes: list) -> dict:
    B = ("branch",)
    return {
        "branch_periods": (B, np.array([b.periods for b in branches], dtype=int),
                           {"long_name": "period n of the branch's orbits, in cam periods"}),
        "branch_parent": (B, np.array([b.parent for b in branches], dtype=int),
                          {"long_name": "the branch it was switched from (-1: none)"}),
        "branch_origin": (B, np.array([b.origin for b in branches], dtype=int),
                          {"long_name": "the event it was switched to at (index into event; -1: none)"}),
        "branch_outcome": (B, np.array([outcomes.index(b.outcome) for b in branches], dtype=int),
                           {"long_name": "how the branch ended (index into the attribute outcomes)"}),
    }


def _coordinate(problem: Problem) -> tuple[str, str]:
    """The follower's coordinate, its name and unit (the variables alpha... hold it whatever the follower:
    the translating follower's y, m)."""
    name, unit, _ = COORDINATES[problem.scene.follower]
    return name, unit


def _point_variables(problem: Problem, branches: list, unit: str, n_rev: int, providers: list) -> dict:
    q, q_unit = _coordinate(problem)
    points = [p for b in branches for p in b.points]
    resolved = np.array([p.resolved for p in points], dtype=bool)
    mu = np.array([sorted_multipliers(p.jacobian) for p in points]).reshape(len(points), N_STATE)
    mu[~resolved] = np.nan
    counts = [len(b.points) for b in branches]
    P, PM = ("point",), ("point", "multiplier")
    return {
        "lambda": (P, np.array([p.lam for p in points]), {"units": unit, "long_name": problem.parameter}),
        "alpha": (P, np.array([p.x[STATE_ALPHA] for p in points]), {"units": q_unit,
                                                                    "long_name": f"{q} at the section"}),
        "alpha_dot": (P, np.array([p.x[STATE_ALPHA_DOT] for p in points]),
                      {"units": f"{q_unit}/s", "long_name": f"{q}_dot at the section"}),
        "multiplier_real": (PM, mu.real, {"units": "1", "long_name": "Floquet multiplier, real part"}),
        "multiplier_imag": (PM, mu.imag, {"units": "1", "long_name": "Floquet multiplier, imaginary part"}),
        "multiplier_modulus": (PM, np.abs(mu), {"units": "1", "long_name": "|Floquet multiplier|"}),
        "resolved": (P, resolved, {"long_name": "the derivatives are resolved (camdyn.orbits.derivatives): "
                                                "multipliers given"}),
        "stable": (P, resolved & np.all(np.abs(mu) < 1.0, axis=1),
                   {"long_name": "resolved and every |multiplier| < 1"}),
        "jacobian_provider": (P, np.array([providers.index(p.derivation.provider) for p in points], dtype=int),
                              {"long_name": "the provider of dP/dx (index into the attribute providers)"}),
        "difference_step": (("point", "difference"),
                            np.array([p.derivation.steps for p in points]).reshape(-1, N_STATE + 1),
                            {"long_name": f"central-difference steps in {q} ({q_unit}), {q}_dot ({q_unit}/s) and "
                                          "the parameter (its unit); NaN: not by differences"}),
        "max_gap": (P, np.array([p.max_gap for p in points]),
                    {"units": "m", "long_name": "largest gap psi_i over the orbit (Eq. 6); < 0: deflection, "
                                                "the follower never leaves the cam"}),
        "point_branch": (P, np.repeat(np.arange(len(branches)), counts), {"long_name": "the branch of the point"}),
        "periods": (P, np.repeat([b.periods for b in branches], counts),
                    {"long_name": "period n of the orbit, in cam periods"}),
        "mode": (P, np.array([p.mode for p in points], dtype=int),
                 {"long_name": "mode at the section (index into the attribute modes)"}),
        "residual": (P, np.array([p.residual for p in points]), {"units": "1", "long_name": "scaled residual"}),
        "alpha_revolution": (("point", "revolution"), _padded([p.alpha_revolutions for p in points], n_rev),
                             {"units": q_unit, "long_name": f"{q} at the starts of the orbit's revolutions "
                                                            "(the brute-force diagram's sections)"}),
        "impact_angle": (("point", "impact"), _padded([p.landings.angles for p in points],
                                                      max([p.landings.angles.size for p in points] + [1])),
                         {"units": "rad", "long_name": "cam body angle phi at which each impact lands, in time "
                                                       "order from the section (NaN: none)"}),
    }


def _event_variables(problem: Problem, branches: list, events: list, unit: str, n_rev: int) -> dict:
    q, q_unit = _coordinate(problem)
    offsets = np.cumsum([0] + [len(b.points) for b in branches])
    E, EM = ("event",), ("event", "multiplier")
    mu = np.array([e.multipliers for e in events], dtype=complex).reshape(-1, N_STATE)
    return {
        "event_kind": (E, np.array([EVENTS.index(e.kind) for e in events], dtype=int),
                       {"long_name": "event kind (index into the attribute event_kinds)"}),
        "event_lambda": (E, np.array([e.lam for e in events]), {"units": unit, "long_name": problem.parameter}),
        "event_alpha": (E, np.array([e.x[STATE_ALPHA] for e in events]), {"units": q_unit, "long_name": q}),
        "event_alpha_dot": (E, np.array([e.x[STATE_ALPHA_DOT] for e in events]), {"units": f"{q_unit}/s",
                                                                                  "long_name": f"{q}_dot"}),
        "event_branch": (E, np.array([e.branch for e in events], dtype=int), {"long_name": "the branch of the event"}),
        "event_point": (E, np.array([offsets[e.branch] + e.point for e in events], dtype=int),
                        {"long_name": "index of the point just before the event"}),
        "event_alpha_revolution": (("event", "revolution"), _padded([e.alpha_revolutions for e in events], n_rev),
                                   {"units": q_unit, "long_name": f"{q} at the starts of the revolutions at the event"}),
        "event_max_gap": (E, np.array([e.max_gap for e in events]),
                          {"units": "m", "long_name": "largest gap psi_i over the orbit at the event (0 at grazing)"}),
        "event_multiplier_real": (EM, mu.real, {"units": "1"}),
        "event_multiplier_imag": (EM, mu.imag, {"units": "1"}),
    }


def _padded(rows, width: int) -> np.ndarray:
    out = np.full((len(rows), width), np.nan)
    for i, row in enumerate(rows):
        out[i, :row.size] = row
    return out


def events_table(ds) -> list[tuple[str, float, int, int]]:
    """The events of a :func:`continue_orbit` Dataset as (kind, lambda, branch, point) rows."""
    kinds = ds.attrs["event_kinds"].split()
    return [(kinds[int(k)], float(lam), int(b), int(p)) for k, lam, b, p in
            zip(ds["event_kind"].values, ds["event_lambda"].values, ds["event_branch"].values,
                ds["event_point"].values)]
