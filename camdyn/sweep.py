"""Parameter sweeps on any ``concurrent.futures.Executor``, as labelled xarray results.

:func:`sweep` runs :func:`camdyn.simulate` (compiled backend by default) at every point
of a grid -- the outer product of named 1-D value lists: ``speed_rpm`` and/or any rig
parameter (``k_s``, ``e``, ``zeta_D``...) -- applies a *measure* to each Result, and
returns an ``xarray.Dataset`` with one dimension per grid name, in the grid's order, plus
whatever dimensions the measure adds.  The same call runs serially (``executor=None``),
on local processes (``ProcessPoolExecutor``) or on a dask cluster
(``distributed.Client(...).get_executor()``); points are grouped into chunks, each chunk is
one task, and results are placed by index, so the order (and every value) is the same
whichever executor ran them and in whatever order the tasks finished.  A progress bar
(tqdm) counts points.  The Dataset is NetCDF3-compatible: ``ds.to_netcdf(path)`` saves it.

A measure is a picklable callable ``measure(result) -> dict``: each value a number or an
``(dims, array)`` pair, as in ``xarray.Dataset`` (see :class:`Summary`, :class:`PoincareSection`).
:func:`bifurcation` (Poincare section of alpha once per revolution against speed) and
:func:`contact_loss_map` (k_s against cam speed, as in the paper's Fig. 9) are sweeps.
"""
from __future__ import annotations

import itertools
import math
from concurrent.futures import Executor, as_completed
from dataclasses import dataclass
from typing import Callable, Mapping, Sequence

import numpy as np

from . import __version__
from .analysis import contact_loss_speed, residual_stats
from .cam import ConstantSpeed
from .errors import ParameterError
from .outcome import Outcome
from .result import Result
from .rig import Rig
from .scene import Scene
from .simulation import simulate

#: grid names that are not rig parameters
CAM_NAMES = ("speed_rpm",)
OUTCOME_CODES = {o.name: i for i, o in enumerate(Outcome)}


@dataclass(frozen=True)
class Summary:
    """Impacts per revolution, residual response (rms, peak-to-peak of alpha_r) and the outcome
    code (position in camdyn.Outcome), after ``transient_revolutions``."""

    transient_revolutions: float = 0.0

    def __call__(self, result: Result) -> dict:
        outcome = OUTCOME_CODES[result.outcome.name]
        if not result.ok or result.t.size < 2:
            return {"impacts_per_rev": math.nan, "alpha_r_rms": math.nan, "alpha_r_ptp": math.nan,
                    "outcome": outcome}
        t0 = result.t[0] + self.transient_revolutions * result.period
        steady = result.after(t0)
        revs = (result.t[-1] - t0) / result.period
        stats = residual_stats(steady)
        return {"impacts_per_rev": steady.impacts().size / revs if revs > 0 else math.nan,
                "alpha_r_rms": stats.rms, "alpha_r_ptp": stats.peak_to_peak, "outcome": outcome}


@dataclass(frozen=True)
class PoincareSection:
    """alpha once per revolution (the samples at t = k T), after ``transient_revolutions``;
    run with ``samples_per_revolution=1``.  Also the impacts per revolution and the outcome."""

    transient_revolutions: int = 0

    def __call__(self, result: Result) -> dict:
        per_rev = max(1, int(round(result.period * _sample_rate(result))))
        section = result.alpha[::per_rev][self.transient_revolutions:]
        summary = Summary(self.transient_revolutions)(result)
        return {"alpha_section": (("revolution",), section), "impacts_per_rev": summary["impacts_per_rev"],
                "outcome": summary["outcome"]}


def _sample_rate(result: Result) -> float:
    return 1.0 / (result.t[1] - result.t[0]) if result.t.size > 1 else math.nan


def _grid(rig: Rig, grid: Mapping[str, Sequence[float]]) -> dict[str, np.ndarray]:
    if not isinstance(grid, Mapping) or not grid:
        raise ParameterError("grid", grid, "a non-empty mapping of names to 1-D value lists")
    out = {}
    known = set(rig.to_dict())
    for name, values in grid.items():
        if name not in CAM_NAMES and name not in known:
            raise ParameterError("grid", name, f"speed_rpm or a rig parameter ({', '.join(sorted(known))})")
        arr = np.asarray(values, dtype=float)
        if arr.ndim != 1 or arr.size == 0 or not np.all(np.isfinite(arr)):
            raise ParameterError(name, values, "a non-empty 1-D list of finite numbers (a grid axis)")
        out[name] = arr
    return out


def _run_chunk(rig: Rig, scene: Scene, names: tuple, points: list, measure: Callable,
               kwargs: dict) -> list[dict]:
    """One task: simulate and measure each point of the chunk (module level: picklable)."""
    results = []
    for point in points:
        values = dict(zip(names, point))
        speed = values.pop("speed_rpm", None)
        point_rig = rig.replace(**values) if values else rig
        kw = dict(kwargs)
        if speed is not None:
            kw["cam"] = ConstantSpeed(speed)
        per_rev = kw.pop("samples_per_revolution", None)
        if per_rev is not None:
            kw["sample_rate_Hz"] = per_rev / kw["cam"].period
        results.append(measure(simulate(point_rig, scene, **kw)))
    return results


def _chunks(n: int, size: int) -> list[range]:
    return [range(i, min(n, i + size)) for i in range(0, n, size)]


def sweep(rig: Rig, scene: Scene, grid: Mapping[str, Sequence[float]], measure: Callable = Summary(), *,
          executor: Executor | None = None, progress: bool = True, chunksize: int | None = None,
          samples_per_revolution: int | None = None, **simulate_kwargs):
    """Simulate every point of ``grid`` and measure it; an ``xarray.Dataset`` (see the module doc).

    ``simulate_kwargs`` go to :func:`camdyn.simulate` (``revolutions``, ``rtol``...;
    ``backend`` defaults to ``"compiled"``).  ``samples_per_revolution`` sets each point's
    sample rate from its own cam period (1: one sample per revolution, a Poincare section).
    ``chunksize``: points per task (default: about four tasks per worker).
    """
    import xarray as xr
    from tqdm.auto import tqdm

    axes = _grid(rig, grid)
    names = tuple(axes)
    if "speed_rpm" not in axes and "cam" not in simulate_kwargs and "speed_rpm" not in simulate_kwargs:
        raise ParameterError("speed_rpm", None, "a grid axis 'speed_rpm', or cam=/speed_rpm= for every point")
    if samples_per_revolution is not None:
        if isinstance(samples_per_revolution, bool) or not isinstance(samples_per_revolution, int) \
                or samples_per_revolution < 1:
            raise ParameterError("samples_per_revolution", samples_per_revolution, "an integer >= 1")
        simulate_kwargs["samples_per_revolution"] = samples_per_revolution
    if "speed_rpm" in simulate_kwargs:
        simulate_kwargs["cam"] = ConstantSpeed(simulate_kwargs.pop("speed_rpm"))
    simulate_kwargs.setdefault("backend", "compiled")
    points = list(itertools.product(*(a.tolist() for a in axes.values())))
    workers = getattr(executor, "_max_workers", None) or 2
    size = chunksize or max(1, math.ceil(len(points) / (4 * workers)))
    chunks = _chunks(len(points), size)
    rows: list = [None] * len(points)
    bar = tqdm(total=len(points), disable=not progress, desc=f"sweep {scene.slug}", unit="pt")
    args = (rig, scene, names)
    if executor is None:
        for chunk in chunks:
            rows[chunk.start:chunk.stop] = _run_chunk(*args, [points[i] for i in chunk], measure, simulate_kwargs)
            bar.update(len(chunk))
    else:
        futures = {executor.submit(_run_chunk, *args, [points[i] for i in chunk], measure, simulate_kwargs): chunk
                   for chunk in chunks}
        for future in as_completed(futures):
            chunk = futures[future]
            rows[chunk.start:chunk.stop] = future.result()
            bar.update(len(chunk))
    bar.close()
    return _dataset(xr, axes, rows, rig, scene, simulate_kwargs)


def _dataset(xr, axes: dict, rows: list, rig: Rig, scene: Scene, kwargs: dict):
    shape = tuple(a.size for a in axes.values())
    dims = tuple(axes)
    data = {}
    for name, first in rows[0].items():
        if isinstance(first, tuple):
            extra_dims, _ = first
            length = max(len(np.atleast_1d(r[name][1])) for r in rows)
            block = np.full((len(rows), length), np.nan)
            for i, r in enumerate(rows):
                v = np.asarray(r[name][1], dtype=float)
                block[i, :v.size] = v
            data[name] = (dims + tuple(extra_dims), block.reshape(shape + (length,)))
        else:
            values = np.array([r[name] for r in rows])
            values = values.astype(np.int32) if np.issubdtype(values.dtype, np.integer) else values.astype(float)
            data[name] = (dims, values.reshape(shape))
    attrs = {"scene": scene.slug, "rig": str(rig.name), "camdyn_version": __version__,
             "simulate": ", ".join(f"{k}={v!r}" for k, v in sorted(kwargs.items())),
             "outcome_codes": ", ".join(f"{i}={name}" for name, i in OUTCOME_CODES.items())}
    coords = {name: (name, a) for name, a in axes.items()}
    return xr.Dataset(data, coords=coords, attrs=attrs)


def bifurcation(rig: Rig, scene: Scene, speeds_rpm: Sequence[float], *, revolutions: int = 200,
                transient_revolutions: int = 50, **kwargs):
    """Poincare section of alpha once per revolution against cam speed: ``alpha_section``
    (speed_rpm, revolution) for the revolutions after the transient."""
    if isinstance(revolutions, bool) or not isinstance(revolutions, int) or revolutions < 1:
        raise ParameterError("revolutions", revolutions, "an integer >= 1")
    if not 0 <= transient_revolutions < revolutions:
        raise ParameterError("transient_revolutions", transient_revolutions, f"0 <= it < revolutions ({revolutions})")
    return sweep(rig, scene, {"speed_rpm": speeds_rpm}, PoincareSection(transient_revolutions),
                 revolutions=revolutions, samples_per_revolution=1, **kwargs)


def contact_loss_map(rig: Rig, scene: Scene, k_s: Sequence[float], speeds_rpm: Sequence[float], *,
                     revolutions: float = 6, transient_revolutions: float = 3, samples_per_revolution: int = 64,
                     **kwargs):
    """Where the follower leaves the cam: ``impacts_per_rev`` over (k_s, speed_rpm) from simulation,
    ``contact_lost`` (impacts after the transient), and ``loss_speed_predicted`` (k_s), the
    inverse-kinematics contact-loss speed (Section 6) -- the curve of the paper's Fig. 9."""
    ds = sweep(rig, scene, {"k_s": k_s, "speed_rpm": speeds_rpm}, Summary(transient_revolutions),
               revolutions=revolutions, samples_per_revolution=samples_per_revolution, **kwargs)
    ds["contact_lost"] = (ds["impacts_per_rev"] > 0).astype(np.int32)
    ds["loss_speed_predicted"] = ("k_s", np.array([contact_loss_speed(rig.replace(k_s=float(k)))
                                                   for k in ds["k_s"].values]))
    return ds


__all__ = ["sweep", "Summary", "PoincareSection", "bifurcation", "contact_loss_map"]
