"""Basins of attraction and coexisting attractors (issue 29): the attractor each initial
condition reaches, as a sweep.

:func:`basins` is a :func:`camdyn.sweep.api.sweep` over the initial state -- the grid axes
``alpha_start`` (rad) and ``alpha_dot_start`` (rad/s), each point's ``y0`` at t = 0 -- and, when
``speed_rpm`` is a list, over the cam speed too: so it runs on any ``concurrent.futures``
Executor, streams to ``out`` and is resumed by :func:`camdyn.sweep.api.resume` like any sweep.
Every point is sampled once per cam revolution, at the stroboscopic section t = k T (the cam
at Theta0 + 2 pi k; the section of :class:`camdyn.sweep.api.PoincareSection` and of
``periodic_orbit(phase=0)``), and runs with ``stop=StopWhenPeriodic(...)``
(:mod:`camdyn.runs.stopping`), which ends it once its section repeats.

What a point reached (:class:`AttractorSection`, in the worker):

* **periodic**: its run stopped with ``stop_period`` p >= 1, the *minimal* period of the section
  within the stop threshold ``tol (rtol max abs(alpha) + atol)``
  (:meth:`camdyn.StopWhenPeriodic.period_of`); its p section points (alpha, alpha_dot) are kept,
  rotated to start at the smallest alpha;
* **chaotic**: it did not settle within ``revolutions``, and its largest Lyapunov exponent
  (:func:`camdyn.orbits.lyapunov.spectrum`, from its last section point at an even revolution,
  over ``lyapunov_revolutions``) is positive by more than ``chaos_se`` standard errors; only
  with ``lyapunov_revolutions`` > 0; where the tangent dynamics cannot pass first contact
  (damping C and E: :mod:`camdyn.orbits.tangent`) the exponent is estimated by two neighbouring
  runs at two distances, and both estimates must say so (:func:`camdyn.orbits.lyapunov.verdict`);
* **not settled**: neither (a long transient, a period above ``stop.max_period``, or chaos
  with no exponent);
* **no run**: the run did not succeed (its ``outcome`` says why).

Labelling (:class:`LabelAttractors`, the sweep's ``finish``: it runs again on resume, so a
resumed map is labelled as an uninterrupted one): a point's cycle is first reduced to its
minimal period within ``tol`` (below); periodic points at the same values of the
non-state axes (the speed, rig parameters) are one attractor when their periods are equal and
their section cycles match as sets: every point of each within ``tol`` (rad) in alpha and
``tol Omega_c`` (rad/s, Omega_c the cam's angular speed) in alpha_dot of a point of the other.
Two period-1 attractors at different section points are therefore different.  Ids are given
in the order of first appearance over the grid (C order), so the map is labelled the same
whatever ran it.  Why ``tol`` = 1e-6 rad by default: a stopped run's section differs from its
orbit by about the stop threshold / (1 - abs(mu)) (:class:`camdyn.StopWhenPeriodic`), 4e-8 rad
on the 16 mm experiment rig at the default rtol, so two runs on one stable orbit agree to well
within 1e-6 unless its largest multiplier is above ~0.96; attractors closer than 1e-6 rad are
not told apart.

The Dataset has, besides the sweep's own variables, ``attractor`` (per point: an id >= 0, or
CHAOTIC, NOT_SETTLED, NO_RUN) and the attractor table along the dimension ``attractor_id``:
``attractor_period``, ``attractor_alpha`` and ``attractor_alpha_dot`` (its section points,
along ``cycle``), ``attractor_points`` (the map's points that reach it), the values of the
non-state axes (``attractor_speed_rpm``...), and with ``confirm`` the shooting check
(``attractor_confirmed``...): :func:`camdyn.periodic_orbit` from its first section point,
``periods=p``, converged, stable, and within ``tol`` of a point of the cycle.
"""
from __future__ import annotations

import math
from concurrent.futures import Executor
from dataclasses import dataclass
from typing import ClassVar, Sequence

import numpy as np

from .._checks import integer, real
from ..errors import ParameterError
from ..model.model import Model
from ..model.rig import Rig
from ..model.scene import Scene
from ..runs.stopping import StopWhenPeriodic
from .spec import OUTCOME_CODES, STATE_NAMES, SweepSpec, _interrupted

#: ``attractor`` of a start that did not settle and whose lambda_1 is positive by ``chaos_se`` standard errors
CHAOTIC = -1
#: ``attractor`` of a start that did not settle within the revolutions, with no chaos verdict
NOT_SETTLED = -2
#: ``attractor`` of a start whose run did not succeed (its ``outcome`` and ``message`` say why)
NO_RUN = -3
#: the codes of ``attractor`` that are not an attractor's id, by name (its ``flag_meanings``)
VERDICTS = {"chaotic": CHAOTIC, "not_settled": NOT_SETTLED, "no_run": NO_RUN}


@dataclass(frozen=True)
class AttractorSection:
    """The measure of a basin map's point (see the module doc): the section cycle it converged to
    (``cycle_alpha``, ``cycle_alpha_dot``: p points; where it did not settle the last
    ``max_period`` section points) and, where it did not settle and ``lyapunov_revolutions`` > 0,
    the largest Lyapunov exponent with its standard error over ``lyapunov_batches`` batches."""

    max_period: int = 8
    lyapunov_revolutions: int = 0
    lyapunov_batches: int = 10
    wants_inputs: ClassVar[bool] = True
    variables: ClassVar[dict] = {
        "cycle_alpha": ("alpha at the section t = k T over the converged cycle (its p points from the smallest "
                        "alpha; not settled: the last max_period section points)", "rad"),
        "cycle_alpha_dot": ("alpha_dot at the section t = k T over the converged cycle (as cycle_alpha)", "rad/s"),
        "lyapunov": ("largest Lyapunov exponent of a run that did not settle (NaN: not computed, or no tangent "
                     "dynamics)", "1/s"),
        "lyapunov_se": ("standard error of lyapunov (batch means)", "1/s"),
        "lyapunov_check": ("a second estimate of lyapunov: by two neighbouring runs (damping C, E), the one at "
                           "10 times the neighbour's distance; else lyapunov itself", "1/s")}

    def __post_init__(self):
        integer("max_period", self.max_period, "an integer >= 1", lambda n: n >= 1)
        integer("lyapunov_revolutions", self.lyapunov_revolutions, "an integer >= 0 (0: no Lyapunov verdict)",
                lambda n: n >= 0)
        integer("lyapunov_batches", self.lyapunov_batches, "an integer >= 2", lambda n: n >= 2)
        if self.lyapunov_revolutions % self.lyapunov_batches:
            raise ParameterError("lyapunov_revolutions", self.lyapunov_revolutions,
                                 f"a multiple of lyapunov_batches = {self.lyapunov_batches}")

    def __call__(self, result, inputs) -> dict:
        out = {"lyapunov": math.nan, "lyapunov_se": math.nan, "lyapunov_check": math.nan}
        if not result.ok or result.t.size == 0:
            return {**out, "cycle_alpha": ("cycle", []), "cycle_alpha_dot": ("cycle", [])}
        p = int(result.stats.get("stop_period", 0))
        alpha, alpha_dot = result.q[-(p or self.max_period):], result.q_dot[-(p or self.max_period):]
        if p:
            first = int(np.argmin(alpha))
            alpha, alpha_dot = np.roll(alpha, -first), np.roll(alpha_dot, -first)
        elif self.lyapunov_revolutions:
            out.update(self._lyapunov(result, inputs))
        return {**out, "cycle_alpha": ("cycle", alpha), "cycle_alpha_dot": ("cycle", alpha_dot)}

    def _lyapunov(self, result, inputs) -> dict:
        """lambda_1 from the last section point at an even revolution (the kernels' period is 2 T,
        so that state is a start at t = 0): by the tangent dynamics, or where they cannot pass
        first contact (damping C, E) by two neighbouring runs at two distances
        (:func:`camdyn.orbits.lyapunov.largest_exponent`); NaN where neither runs."""
        from ..orbits.lyapunov import LyapunovSettings, largest_exponent

        k = (result.t.size - 1) // 2 * 2
        settings = LyapunovSettings(self.lyapunov_revolutions, 0, self.lyapunov_batches)
        try:
            e = largest_exponent(Model(inputs.rig, inputs.scene, inputs.cam), settings, (result.q[k], result.q_dot[k]),
                                 inputs.request.options, inputs.request.backend)
            return {"lyapunov": e.largest, "lyapunov_se": e.standard_error, "lyapunov_check": e.check}
        except Exception as exc:  # a run that fails from here: no verdict
            if _interrupted(exc):
                raise KeyboardInterrupt from exc
            return {}


@dataclass(frozen=True)
class LabelAttractors:
    """The ``finish`` of a basin map: the attractor of every point and the attractor table (see the
    module doc).  ``tol`` (rad; alpha_dot to ``tol Omega_c``) tells attractors apart; ``chaos_se``:
    lambda_1 above this many standard errors is chaotic; ``confirm``: shoot for each attractor."""

    tol: float = 1e-6
    chaos_se: float = 3.0
    confirm: bool = True

    def __post_init__(self):
        real("tol", self.tol, "0 < tol < 1 (rad)", lambda v: 0 < v < 1)
        real("chaos_se", self.chaos_se, "chaos_se > 0 (standard errors)", lambda v: v > 0)

    def __call__(self, ds, spec: SweepSpec):
        codes, table = self.label(ds, spec)
        ds["attractor"] = (spec.names, codes.reshape(spec.shape), {
            "long_name": "the attractor each start reaches: an id of the attractor table (>= 0), or a verdict",
            "units": "1", "flag_values": np.array(list(VERDICTS.values()), dtype=np.int32),
            "flag_meanings": " ".join(VERDICTS)})
        ds.attrs.update({"attractor_tol": self.tol, "attractor_tol_units": "rad (alpha_dot: rad/s, times Omega_c)",
                         "attractor_chaos_se": self.chaos_se, "attractors": len(table),
                         "section": "t = t_start + k T (cam angle Theta0 + 2 pi k)"})
        if table:
            ds = ds.assign_coords(attractor_id=("attractor_id", np.arange(len(table), dtype=np.int32),
                                                {"units": "1", "long_name": "id of an attractor (the values of "
                                                                            "attractor)"}))
            ds = ds.assign(self._table_variables(table, spec, ds.sizes["cycle"]))
            if self.confirm:
                ds = ds.assign(_confirmations(table, spec, self.tol))
        return ds

    def label(self, ds, spec: SweepSpec) -> tuple[np.ndarray, list[dict]]:
        """(the code of every point in flat order, the attractors found: dicts in id order)."""
        from ..orbits.lyapunov import verdict as chaos_verdict
        n = spec.size
        outcome = ds["outcome"].values.reshape(n)
        period = np.nan_to_num(ds["stop_period"].values.reshape(n)).astype(int)
        alpha = ds["cycle_alpha"].values.reshape(n, -1)
        alpha_dot = ds["cycle_alpha_dot"].values.reshape(n, -1)
        lam, se = ds["lyapunov"].values.reshape(n), ds["lyapunov_se"].values.reshape(n)
        # (a map streamed before lyapunov_check was recorded: its one estimate)
        check = ds["lyapunov_check"].values.reshape(n) if "lyapunov_check" in ds else lam
        others = [k for k, name in enumerate(spec.names) if name not in STATE_NAMES]
        codes = np.full(n, NO_RUN, dtype=np.int32)
        table: list[dict] = []
        found: dict[tuple, list[int]] = {}           # group -> ids of its attractors
        for index, where in enumerate(np.ndindex(spec.shape)):
            if outcome[index] != OUTCOME_CODES["SUCCESS"]:
                continue
            p = period[index]
            if p <= 0:
                chaotic = chaos_verdict((lam[index], check[index]), se[index], self.chaos_se) == "chaotic"
                codes[index] = CHAOTIC if chaotic else NOT_SETTLED
                continue
            group = tuple(where[k] for k in others)
            omega = _omega(spec, index)
            cycle = _minimal_cycle(alpha[index, :p], alpha_dot[index, :p], self.tol, self.tol * omega)
            p = cycle[0].size
            ids = found.setdefault(group, [])
            match = next((i for i in ids if table[i]["period"] == p
                          and _same_cycle(table[i]["cycle"], cycle, self.tol, self.tol * omega)), None)
            if match is None:
                match = len(table)
                table.append({"period": p, "cycle": cycle, "points": 0, "first": index, "group": group})
                ids.append(match)
            table[match]["points"] += 1
            codes[index] = match
        return codes, table

    def _table_variables(self, table: list[dict], spec: SweepSpec, width: int) -> dict:
        """The table along ``attractor_id``; the cycles along the map's ``cycle`` (``width`` long)."""
        cycles = np.full((2, len(table), width), np.nan)
        for i, a in enumerate(table):
            cycles[:, i, :a["period"]] = a["cycle"]
        out = {"attractor_period": ("attractor_id", np.array([a["period"] for a in table], dtype=np.int32),
                                    {"units": "1", "long_name": "minimal period of the attractor (cam revolutions)"}),
               "attractor_alpha": (("attractor_id", "cycle"), cycles[0],
                                   {"units": "rad", "long_name": "alpha at the attractor's section points (t = k T), "
                                                                 "from the smallest"}),
               "attractor_alpha_dot": (("attractor_id", "cycle"), cycles[1],
                                       {"units": "rad/s", "long_name": "alpha_dot at the attractor's section points"}),
               "attractor_points": ("attractor_id", np.array([a["points"] for a in table], dtype=np.int32),
                                    {"units": "1", "long_name": "points of the map that reach the attractor"})}
        for name in spec.names:
            if name not in STATE_NAMES:
                values = [spec.values(a["first"])[name] for a in table]
                unit = "rev/min" if name == "speed_rpm" else ""
                out[f"attractor_{name}"] = ("attractor_id", np.array(values),
                                            {"units": unit, "long_name": f"{name} of the attractor's map points"})
        return out


def _omega(spec: SweepSpec, index: int) -> float:
    """The cam's angular speed (rad/s) at a point: the scale of alpha_dot's tolerance."""
    speed = spec.values(index).get("speed_rpm")
    period = 60.0 / speed if speed is not None else spec.settings["cam"].period
    return 2 * math.pi / period


def _minimal_cycle(alpha: np.ndarray, alpha_dot: np.ndarray, tol_alpha: float, tol_rate: float):
    """The cycle of a run's p section points at its minimal period within the map's tolerances:
    its first q points for the least divisor q of p with every point within them of the point q
    later, rotated to start at the smallest alpha.  (The stop's period is minimal within its own,
    tighter threshold: a run still converging to a P1 orbit along a complex pair of multipliers can
    pass for a P2 cycle there; at the map's tol it is the P1 orbit.)"""
    p = alpha.size
    for q in range(1, p):
        if p % q == 0 and np.all(np.abs(alpha - np.roll(alpha, -q)) <= tol_alpha) \
                and np.all(np.abs(alpha_dot - np.roll(alpha_dot, -q)) <= tol_rate):
            alpha, alpha_dot = alpha[:q], alpha_dot[:q]
            break
    first = int(np.argmin(alpha))
    return np.roll(alpha, -first), np.roll(alpha_dot, -first)


def _same_cycle(a, b, tol_alpha: float, tol_rate: float) -> bool:
    """Whether two section cycles (alpha, alpha_dot arrays) match as sets, each point of either
    within the tolerances of a point of the other."""
    close = ((np.abs(a[0][:, None] - b[0][None, :]) <= tol_alpha)
             & (np.abs(a[1][:, None] - b[1][None, :]) <= tol_rate))
    return bool(close.any(axis=1).all() and close.any(axis=0).all())


def _confirmations(table: list[dict], spec: SweepSpec, tol: float) -> dict:
    """Each attractor checked by shooting: ``periodic_orbit`` from its first section point with
    ``periods`` = its period, at the point's rig and speed; confirmed where it converges to a stable
    orbit within ``tol`` of a point of the cycle."""
    from ..orbits.shooting import periodic_orbit

    outcome, distance, largest, confirmed = [], [], [], []
    for a in table:
        rig, cam, request = spec.inputs(a["first"])
        x0 = (float(a["cycle"][0][0]), float(a["cycle"][1][0]))
        orbit = periodic_orbit(rig, spec.scene, cam, periods=a["period"], y0=x0, warmup_revolutions=a["period"],
                               backend=request.backend)
        scale = np.array([tol, tol * _omega(spec, a["first"])])
        d = math.nan
        if np.all(np.isfinite(orbit.state)):
            d = float(np.min(np.max(np.abs(np.array(a["cycle"]) - orbit.state[:, None]) / scale[:, None], axis=0)))
        mu = float(np.max(np.abs(orbit.multipliers))) if orbit.ok and orbit.multipliers.size else math.nan
        outcome.append(orbit.outcome.name)
        distance.append(d)
        largest.append(mu)
        confirmed.append(int(orbit.ok and bool(orbit.stable) and d <= 1.0))
    return {"attractor_orbit": ("attractor_id", np.array(outcome, dtype=object),
                                {"long_name": "how camdyn.periodic_orbit from the attractor's first section point "
                                              "ended"}),
            "attractor_orbit_distance": ("attractor_id", np.array(distance),
                                         {"units": "1", "long_name": "distance of the shooting orbit's state from the "
                                                                     "nearest section point of the attractor, in tol"}),
            "attractor_orbit_multiplier": ("attractor_id", np.array(largest),
                                           {"units": "1", "long_name": "largest Floquet multiplier modulus of the "
                                                                       "shooting orbit"}),
            "attractor_confirmed": ("attractor_id", np.array(confirmed, dtype=np.int32),
                                    {"units": "1", "long_name": "1: a stable periodic orbit by shooting within tol "
                                                                "of the attractor, 0: not confirmed"})}


def basins(rig: Rig, scene: Scene, *, alpha: Sequence[float] | float, alpha_dot: Sequence[float] | float,
           speed_rpm: Sequence[float] | float, revolutions: int = 200, stop: StopWhenPeriodic = StopWhenPeriodic(),
           tol: float = 1e-6, confirm: bool = True, lyapunov_revolutions: int = 0, chaos_se: float = 3.0,
           executor: Executor | None = None, progress: bool = True, chunksize: int | None = None, out=None,
           overwrite: bool = False, invalid: str = "raise", retries: int = 2, **simulate_kwargs):
    """The basin map: the attractor reached from every start (alpha, alpha_dot) at t = 0 (the
    section t = k T), at one speed or, with a list of speeds, at each (see the module doc).

    Parameters
    ----------
    rig, scene : camdyn.Rig, camdyn.Scene
    alpha, alpha_dot : 1-D sequence of float, or a float
        The starts' alpha (rad) and alpha_dot (rad/s): grid axes ``alpha_start`` and
        ``alpha_dot_start`` (a single value: an axis of one).
    speed_rpm : float or 1-D sequence of float
        The cam speed; a sequence makes it the first grid axis ((speed, initial condition) maps).
    revolutions : int
        The longest run (cam revolutions); a run stops earlier once periodic (``stop``).
    stop : camdyn.StopWhenPeriodic
        When a run counts as periodic, and its minimal period (at most ``stop.max_period``).
    tol : float
        Attractors closer than ``tol`` rad (alpha_dot: ``tol Omega_c`` rad/s) are one.
    confirm : bool
        Confirm each attractor by shooting (:func:`camdyn.periodic_orbit`).
    lyapunov_revolutions, chaos_se : int, float
        A run that does not settle is *chaotic* where its lambda_1 over ``lyapunov_revolutions``
        (0: not computed) is above ``chaos_se`` standard errors.
    executor, progress, chunksize, out, overwrite, invalid, retries
        As in :func:`camdyn.sweep.api.sweep` (any Executor, streamed to ``out``, resumable).
    **simulate_kwargs
        Other keywords of :func:`camdyn.simulate` (``rtol``, ``atol``, ``backend``...); not
        ``y0``, ``span``, ``t_start`` or a sample rate (the map sets them).

    Returns
    -------
    xarray.Dataset
        The sweep's Dataset (dims: ``speed_rpm`` if a list, ``alpha_start``, ``alpha_dot_start``)
        with ``attractor`` and the attractor table.
    """
    from .api import _Output, _RunOptions, _spec, _start

    for name in ("y0", "span", "t_start", "sample_rate_Hz", "samples_per_revolution", "t_end"):
        if name in simulate_kwargs:
            raise ParameterError(name, simulate_kwargs[name], "not given to basins (the map sets each point's start, "
                                 "length and its samples at the section t = k T)")
    if not isinstance(stop, StopWhenPeriodic):
        raise ParameterError("stop", stop, "a camdyn.StopWhenPeriodic (the map needs each run's period)")
    revolutions = integer("revolutions", revolutions, f"an integer >= stop.revolutions + stop.check_every "
                          f"({stop.revolutions + stop.check_every})", lambda n: n >= stop.revolutions + stop.check_every)
    grid = {}
    if np.ndim(speed_rpm) == 0:
        simulate_kwargs["speed_rpm"] = speed_rpm
    else:
        grid["speed_rpm"] = speed_rpm
    grid.update(alpha_start=np.atleast_1d(alpha), alpha_dot_start=np.atleast_1d(alpha_dot))
    measure = AttractorSection(stop.max_period, lyapunov_revolutions)
    finish = LabelAttractors(tol, chaos_se, bool(confirm))
    spec = _spec(rig, scene, grid, measure, 1, {"revolutions": revolutions, "stop": stop, **simulate_kwargs},
                 finish=finish)
    return _start(spec, _Output(out, overwrite), invalid, _RunOptions(executor, progress, chunksize, retries))


def attractor_table(ds) -> list[dict]:
    """The attractor table of a basin map as rows: id, period, the first section point (alpha,
    alpha_dot), the points reaching it, the values of the non-state axes, and the shooting
    check where there is one; then one row per verdict that occurs (chaotic, not settled, no run)."""
    rows = []
    codes = ds["attractor"].values
    for i in range(int(ds.attrs.get("attractors", 0))):
        row = {"id": i, "period": int(ds["attractor_period"].values[i]),
               "alpha": float(ds["attractor_alpha"].values[i, 0]),
               "alpha_dot": float(ds["attractor_alpha_dot"].values[i, 0]),
               "points": int(ds["attractor_points"].values[i])}
        row.update({name[len("attractor_"):]: float(ds[name].values[i]) for name in ds.data_vars
                    if name.startswith("attractor_") and ds[name].dims == ("attractor_id",)
                    and name[len("attractor_"):] in ds.dims})
        if "attractor_confirmed" in ds:
            row.update(confirmed=bool(ds["attractor_confirmed"].values[i]), orbit=str(ds["attractor_orbit"].values[i]),
                       multiplier=float(ds["attractor_orbit_multiplier"].values[i]))
        rows.append(row)
    for name, code in VERDICTS.items():
        count = int(np.sum(codes == code))
        if count:
            rows.append({"id": name, "points": count})
    return rows


__all__ = ["basins", "attractor_table", "AttractorSection", "LabelAttractors", "CHAOTIC", "NOT_SETTLED", "NO_RUN",
           "VERDICTS"]
