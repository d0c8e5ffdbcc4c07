"""What a sweep runs, and running it: the grid, one point's inputs, a chunk of points in a worker.

A :class:`SweepSpec` is everything a worker needs (the base rig, the scene, the grid axes, the
measure and the :func:`camdyn.simulate` settings); a point is a flat index into the grid, in
C order over the axes (the last grid name varies fastest).  :func:`run_chunk` simulates and
measures a list of points and returns a :class:`ChunkResult`: one row per point, whatever the
point did.  A point whose simulation or measure raises is recorded with outcome ``ERROR`` and
the exception's message; nothing a point does ends the chunk early.  A point's row depends
only on the spec and its index, never on the chunk or the worker that ran it.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from functools import cached_property
from typing import Callable, Mapping, NamedTuple, Sequence

import numpy as np

from ..errors import ParameterError
from ..model.cam import ConstantSpeed
from ..model.rig import Rig
from ..model.scene import Scene
from ..outcome import Outcome
from ..runs.request import RunRequest, loose_keywords, run_request
from ..runs.simulation import run

#: grid names that are not rig parameters: the cam's speed, and the initial state (alpha rad,
#: alpha_dot rad/s at t_start: each point's ``y0``, for maps of initial conditions such as basins)
CAM_NAMES = ("speed_rpm",)
STATE_NAMES = ("alpha_start", "alpha_dot_start")
#: outcome codes of a point: the engine's outcomes by their position in camdyn.Outcome, and
#: three of the sweep's own, negative so that a new engine outcome never shifts them
OUTCOME_CODES = {o.name: i for i, o in enumerate(Outcome)}
INVALID, ERROR, NOT_RUN = -1, -2, -3
SWEEP_CODES = {"INVALID": INVALID, "ERROR": ERROR, "NOT_RUN": NOT_RUN}
ALL_CODES = {**OUTCOME_CODES, **SWEEP_CODES}
#: variable names a measure may not use: the sweep's own (with stop=: what the convergence check
#: did), and the chunk files' point axis
OWN = ("outcome", "message", "point", "point_index")
RESERVED = OWN + ("revolutions_run", "stop_period")


@dataclass(frozen=True, eq=False)
class SweepSpec:
    """One sweep: ``simulate(rig with the point's parameters, scene, cam, **settings)`` at every
    point of the outer product of ``axes``, measured by ``measure``.

    ``settings`` are simulate's keywords as given (with ``cam`` when the speed is not a grid
    axis): the sweep's record; what runs is :attr:`request`, built from them once.
    ``samples_per_revolution`` sets each point's sample rate from its own cam period;
    ``finish(dataset, spec)``, if given, adds derived variables to the assembled Dataset.
    """

    rig: Rig
    scene: Scene
    axes: dict[str, np.ndarray]
    measure: Callable
    settings: dict = field(default_factory=dict)
    samples_per_revolution: int | None = None
    finish: Callable | None = None

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.axes)

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(a.size for a in self.axes.values())

    @property
    def size(self) -> int:
        return math.prod(self.shape)

    def values(self, index: int) -> dict[str, float]:
        """The grid values of the point with this flat index."""
        where = np.unravel_index(int(index), self.shape)
        return {name: float(a[i]) for (name, a), i in zip(self.axes.items(), where)}

    def label(self, index: int) -> str:
        return ", ".join(f"{k}={v:g}" for k, v in self.values(index).items())

    @cached_property
    def request(self) -> RunRequest:
        """The request every point shares, built from ``settings`` by simulate's own
        :func:`~camdyn.runs.request.run_request` (so checked by it, once)."""
        return run_request(**{k: v for k, v in self.settings.items() if k != "cam"})

    def __getstate__(self) -> dict:
        """Pickled without :attr:`request` (built again from ``settings`` where it is read)."""
        return {k: v for k, v in self.__dict__.items() if k != "request"}

    def record(self) -> dict:
        """simulate's settings as the sweep's file records them: the keywords as given, a span or
        options given whole spelled out in loose keywords (:func:`~camdyn.runs.request.loose_keywords`;
        no sample rate with ``samples_per_revolution``, which sets it per point)."""
        out = loose_keywords(self.settings)
        if self.samples_per_revolution is not None:
            out.pop("sample_rate_Hz", None)
        return out

    def request_at(self, cam) -> RunRequest:
        """The request of a point driven by ``cam``: the shared one, sampled
        ``samples_per_revolution`` times per cam period when that is given."""
        if self.samples_per_revolution is None:
            return self.request
        span = dataclasses.replace(self.request.span, sample_rate_Hz=self.samples_per_revolution / cam.period)
        return dataclasses.replace(self.request, span=span)

    def inputs(self, index: int):
        """(rig, cam, request) of one point; the rig, cam and request validate themselves.  A point
        with an initial-state axis (:data:`STATE_NAMES`) starts there: its request's ``y0`` is the
        point's (alpha_start, alpha_dot_start), a component without an axis taken from ``y0=``."""
        values = self.values(index)
        speed = values.pop("speed_rpm", None)
        state = {name: values.pop(name) for name in STATE_NAMES if name in values}
        rig = self.rig.replace(**values) if values else self.rig
        cam = ConstantSpeed(speed) if speed is not None else self.settings["cam"]
        request = self.request_at(cam)
        if state:
            base = request.y0 or (math.nan, math.nan)
            y0 = tuple(state.get(name, b) for name, b in zip(STATE_NAMES, base))
            request = dataclasses.replace(request, y0=y0)
        return rig, cam, request


def grid_axes(rig: Rig, grid: Mapping[str, Sequence[float]]) -> dict[str, np.ndarray]:
    """The grid as named 1-D float arrays, in the grid's order; bad names or values raise."""
    if not isinstance(grid, Mapping) or not grid:
        raise ParameterError("grid", grid, "a non-empty mapping of names to 1-D value lists")
    out = {}
    known = set(rig.to_dict()) - {"name", "description"}
    for name, values in grid.items():
        if name not in CAM_NAMES and name not in STATE_NAMES and name not in known:
            raise ParameterError("grid", name, f"speed_rpm, {', '.join(STATE_NAMES)} (the initial state) or a rig "
                                 f"parameter ({', '.join(sorted(known))})")
        try:
            arr = np.asarray(values, dtype=float)
        except (TypeError, ValueError):
            arr = np.array([np.nan])
        if arr.ndim != 1 or arr.size == 0 or not np.all(np.isfinite(arr)):
            raise ParameterError(name, values, "a non-empty 1-D list of finite numbers (a grid axis)")
        out[name] = arr
    return out


@dataclass
class ChunkResult:
    """The rows of some points: flat ``index``, ``outcome`` code and ``message`` per point, and
    each measured variable as ``(extra dims, float array)`` with one row per point (NaN where a
    point has no value; an array variable padded with NaN to the chunk's longest, at least 1)."""

    index: np.ndarray
    outcome: np.ndarray
    message: list[str]
    values: dict[str, tuple[tuple[str, ...], np.ndarray]]

    def __len__(self) -> int:
        return int(self.index.size)


def run_chunk(spec: SweepSpec, indices: Sequence[int], attempt: int = 0) -> ChunkResult:
    """One task: simulate and measure each point (module level: picklable for any executor).
    ``attempt`` is not used: it makes a retried chunk a new task for executors that name tasks
    by their arguments (dask), which would otherwise hand back the failed one."""
    rows = [run_point(spec, i) for i in indices]
    return chunk_of(indices, rows)


class PointInputs(NamedTuple):
    """What one point ran: given to a measure whose ``wants_inputs`` is True, as
    ``measure(result, inputs)`` (e.g. to run more of the same point, as the basins' Lyapunov
    verdict does)."""

    rig: Rig
    scene: Scene
    cam: object
    request: RunRequest


def run_point(spec: SweepSpec, index: int) -> tuple[int, str, dict]:
    """(outcome code, message, measured values) of one point; an exception becomes ERROR."""
    try:
        rig, cam, request = spec.inputs(index)
        result = run(rig, spec.scene, cam, request)
        if getattr(spec.measure, "wants_inputs", False):
            raw = spec.measure(result, PointInputs(rig, spec.scene, cam, request))
        else:
            raw = spec.measure(result)
        values = measured(raw, spec.names)
    except Exception as exc:  # a failing point never sinks the sweep: it is recorded
        if _interrupted(exc):
            raise KeyboardInterrupt from exc
        return ERROR, f"{type(exc).__name__}: {exc}", {}
    if request.stop is not None:        # what the convergence check did (camdyn.runs.stopping)
        values["revolutions_run"] = float(result.stats.get("revolutions_run", math.nan))
        values["stop_period"] = float(result.stats.get("stop_period", 0))
    return OUTCOME_CODES[result.outcome.name], "" if result.ok else result.outcome.message, values


def _interrupted(exc: BaseException | None) -> bool:
    """Ctrl-C in compiled code reaches Python as another exception (numba's dispatcher returns with
    the KeyboardInterrupt set: a SystemError caused by it); an interrupt is never a point's error."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            return True
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return False


def measured(values, grid_names: Sequence[str]) -> dict:
    """A measure's dict, checked: each value a number, or (dims, 1-D array) with one dim."""
    if not isinstance(values, Mapping):
        raise TypeError(f"a measure must return a dict, got {type(values).__name__}")
    out = {}
    for name, value in values.items():
        if name in RESERVED or name in grid_names:
            raise ValueError(f"a measure may not return {name!r}: the sweep uses that name")
        if isinstance(value, tuple):
            dims, array = value
            dims = (dims,) if isinstance(dims, str) else tuple(dims)
            array = np.asarray(array, dtype=float)
            if len(dims) != 1 or array.ndim != 1:
                raise ValueError(f"measure value {name!r}: an array must be (one dim name, 1-D array)")
            out[name] = (dims, array)
        else:
            try:
                out[name] = float(value)
            except (TypeError, ValueError):
                raise TypeError(f"measure value {name!r} = {value!r}: must be a number or (dim, 1-D array)") from None
    return out


def chunk_of(indices: Sequence[int], rows: Sequence[tuple[int, str, dict]]) -> ChunkResult:
    """The rows of :func:`run_point` as columns; an array variable's extra dim is as long as the
    longest value of any variable on it (at least 1: netCDF3 has no empty fixed dims)."""
    n = len(rows)
    dims_of: dict[str, tuple] = {}
    width: dict[str, int] = {}
    for _, _, values in rows:
        for name, value in values.items():
            dims = dims_of.setdefault(name, value[0] if isinstance(value, tuple) else ())
            for d in dims:
                width[d] = max(width.get(d, 1), np.size(value[1]))
    columns = {}
    for name, dims in dims_of.items():
        block = np.full((n,) + tuple(width[d] for d in dims), np.nan)
        for i, (_, _, values) in enumerate(rows):
            if name in values:
                value = values[name]
                if dims:
                    block[i, :np.size(value[1])] = value[1]
                else:
                    block[i] = value
        columns[name] = (dims, block)
    return ChunkResult(np.asarray(indices, dtype=np.int64).reshape(n), np.array([r[0] for r in rows], dtype=np.int32),
                       [r[1] for r in rows], columns)
