"""Parameter sweeps on any ``concurrent.futures.Executor``, as labelled xarray results.

:func:`sweep` runs :func:`camdyn.simulate` (compiled backend by default) at every point
of a grid -- the outer product of named 1-D value lists: ``speed_rpm`` and/or any rig
parameter (``k_s``, ``e``, ``zeta_D``...) -- applies a *measure* to each Result, and
returns an ``xarray.Dataset`` with one dimension per grid name, in the grid's order, plus
whatever dimensions the measure adds, and two variables of its own: ``outcome`` (a code per
point: the engine's ``camdyn.Outcome``, or INVALID, ERROR, NOT_RUN; the codes are in the
variable's ``flag_values``/``flag_meanings``) and ``message`` (why a point did not succeed).

Sweeps at scale lose nothing:

* every point is checked before any work (:mod:`camdyn.sweep.check`): by default a grid
  with invalid points is refused with all of them listed (:class:`InvalidGridError`);
  ``invalid="skip"`` records them as INVALID (NaN values, the reason in ``message``) and
  runs the rest;
* a point whose simulation or measure raises is recorded as ERROR with its message; a run
  that stops early is recorded with its engine outcome; neither stops the sweep;
* with ``out="map.nc"`` the finished chunks stream to ``map.nc.parts/`` as they complete
  (:mod:`camdyn.sweep.store`); after Ctrl-C, a crash or a killed process, :func:`resume`
  runs only the missing points, and the result equals an uninterrupted sweep's;
* ``out`` is checked before any work: a folder, a missing or read-only parent folder, and a
  finished file (unless ``overwrite=True``) are refused; the process writing ``map.nc.parts/``
  holds its lock, so a second sweep or resume of it is refused while the first runs (a killed
  process releases it); a file that is not a camdyn sweep is refused by :func:`resume`
  (:class:`NotASweepError`);
* a worker that dies costs a retry of its chunk (:mod:`camdyn.sweep.dispatch`); a chunk that
  cannot run, also because the executor or its dask cluster was lost, is recorded as NOT_RUN
  and the sweep says so (a warning on ``camdyn.sweep.api``); :func:`resume` runs it later;
  the workers of :func:`process_pool` end when the sweep's process dies;
* the Dataset is the same serially (``executor=None``), on local processes
  (``ProcessPoolExecutor``) or on a dask cluster (``distributed.Client(...).get_executor()``),
  for any chunk size and worker count: each point's values depend only on the point;
* memory is O(points): each Result is measured in the worker and dropped.

A measure is a picklable callable ``measure(result) -> dict``: each value a number or a
``(dim, 1-D array)`` pair (see :class:`Summary`, :class:`PoincareSection`); numbers are
stored as floats.  Its optional ``variables`` (name -> (long_name, units)) label the file.  A
measure whose ``wants_inputs`` is True is called ``measure(result, inputs)``, ``inputs`` the
point's rig, scene, cam and request (:class:`camdyn.sweep.spec.PointInputs`), to run more of it.
The grid may hold the initial state (``alpha_start``, ``alpha_dot_start``): maps of initial
conditions, as :func:`camdyn.sweep.attractors.basins` draws basins of attraction with them.
:func:`bifurcation` (Poincare section of alpha once per revolution against speed) and
:func:`contact_loss_map` (k_s against cam speed, as in the paper's Fig. 9) are sweeps.
"""
from __future__ import annotations

import logging
import math
import pickle
from concurrent.futures import Executor, ProcessPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, ClassVar, Mapping, Sequence

import numpy as np

from .._checks import flag, integer
from ..analysis.statics import contact_loss_speed, residual_stats
from ..model.cam import ConstantSpeed
from ..errors import CamdynError, ParameterError
from ..runs.result import Result
from ..model.rig import Rig
from ..model.scene import Scene
from ..runs.request import DEFAULT_BACKEND
from ..runs.stopping import StopWhenPeriodic
from .check import InvalidGridError, check_by_running, check_grid, check_settings
from .dispatch import Dispatch, chunks_of, process_pool, run_serial, worker_count
from .spec import ALL_CODES, ERROR, INVALID, NOT_RUN, OUTCOME_CODES, STATE_NAMES, SweepSpec, chunk_of, grid_axes
from .store import (FolderStore, MemoryStore, NotASweepError, StoreError, assemble, check_out, done_mask, load_sweep,
                    parts_folder, refuse_if_in_use, rig_of, scene_of, stop_summary)

log = logging.getLogger("camdyn.sweep.api")


@dataclass(frozen=True)
class Summary:
    """Impacts per revolution and the residual response (rms, peak-to-peak of alpha_r), after
    ``transient_revolutions``; NaN for a run that did not succeed."""

    transient_revolutions: float = 0.0
    variables: ClassVar[dict] = {
        "impacts_per_rev": ("impacts per cam revolution after the transient", "1"),
        "alpha_r_rms": ("rms of the residual response alpha_r after the transient", "rad"),
        "alpha_r_ptp": ("peak-to-peak of the residual response alpha_r after the transient", "rad")}

    def __call__(self, result: Result) -> dict:
        if not result.ok or result.t.size < 2:
            return {"impacts_per_rev": math.nan, "alpha_r_rms": math.nan, "alpha_r_ptp": math.nan}
        t0 = result.t[0] + self.transient_revolutions * result.period
        steady = result.after(t0)
        revs = (result.t[-1] - t0) / result.period
        stats = residual_stats(steady)
        return {"impacts_per_rev": steady.impacts().size / revs if revs > 0 else math.nan,
                "alpha_r_rms": stats.rms, "alpha_r_ptp": stats.peak_to_peak}


@dataclass(frozen=True)
class PoincareSection:
    """alpha once per revolution (the samples at t = k T), after ``transient_revolutions``;
    run with ``samples_per_revolution=1``.  Also the impacts per revolution."""

    transient_revolutions: int = 0
    variables: ClassVar[dict] = {
        "alpha_section": ("follower angle alpha once per cam revolution (Poincare section)", "rad"),
        "impacts_per_rev": Summary.variables["impacts_per_rev"]}

    def __call__(self, result: Result) -> dict:
        rate = _sample_rate(result)   # NaN for a run that stopped before its second sample
        per_rev = max(1, int(round(result.period * rate))) if math.isfinite(rate) else 1
        section = result.q[::per_rev][self.transient_revolutions:]
        summary = Summary(self.transient_revolutions)(result)
        return {"alpha_section": (("revolution",), section), "impacts_per_rev": summary["impacts_per_rev"]}


def _sample_rate(result: Result) -> float:
    return 1.0 / (result.t[1] - result.t[0]) if result.t.size > 1 else math.nan


@dataclass(frozen=True)
class _RunOptions:
    """How to run the chunks (none of it changes the result)."""

    executor: Executor | None = None
    progress: bool = True
    chunksize: int | None = None
    retries: int = 2

    def __post_init__(self):
        if self.chunksize is not None:
            integer("chunksize", self.chunksize, "an integer >= 1 (points per task), or None", lambda n: n >= 1)
        integer("retries", self.retries, "an integer >= 0", lambda n: n >= 0)


def sweep(rig: Rig, scene: Scene, grid: Mapping[str, Sequence[float]], measure: Callable = Summary(), *,
          executor: Executor | None = None, progress: bool = True, chunksize: int | None = None,
          samples_per_revolution: int | None = None, out=None, overwrite: bool = False, invalid: str = "raise",
          retries: int = 2, stop: StopWhenPeriodic | None = None, **simulate_kwargs):
    """Simulate every point of ``grid`` and measure it (see the module doc).

    Parameters
    ----------
    rig, scene : camdyn.Rig, camdyn.Scene
        The base rig (each point replaces the grid's rig parameters) and the physics.
    grid : mapping of str to 1-D sequence of float
        ``speed_rpm``, rig parameters (SI) and/or the initial state ``alpha_start`` (rad),
        ``alpha_dot_start`` (rad/s) -- each point's ``y0``; a component without an axis comes
        from ``y0=`` -- each with its values; the points are the outer product, and the
        Dataset's dimensions follow this order.
    measure : callable, optional
        ``measure(result) -> dict`` (picklable); default :class:`Summary`.
    executor : concurrent.futures.Executor, optional
        Where the chunks run: None (serially, here), a ``ProcessPoolExecutor``, or dask's
        ``Client.get_executor()``.  The result does not depend on it.
    progress : bool
        Show a progress bar (tqdm) counting points.
    chunksize : int, optional
        Points per task (default: about 16 tasks per worker).  The result does not depend on it.
    samples_per_revolution : int, optional
        Each point's sample rate from its own cam period (1: a Poincare section).
    out : str or os.PathLike, optional
        A netCDF file to write.  The finished chunks stream to the folder ``<out>.parts``
        while the sweep runs; an interrupted sweep is continued by :func:`resume`.  Checked
        before any work (:class:`StoreError`): not a folder, in a writable folder, and not an
        existing file unless ``overwrite``.
    overwrite : bool
        Replace an existing ``out`` (when the sweep has finished; until then it is kept).
    invalid : {"raise", "skip"}
        A grid with points that cannot run: "raise" refuses to start and lists every one
        (:class:`InvalidGridError`); "skip" records them as INVALID and runs the others.
    retries : int
        Times a chunk whose worker died (or whose task failed) is submitted again.
    stop : camdyn.StopWhenPeriodic, optional
        End each point's run once its once-per-revolution section repeats (period <=
        ``stop.max_period``, to ``stop.tol``), its Result completed by repeating the converged
        cycle (:mod:`camdyn.runs.stopping`; needs ``samples_per_revolution``).  The Dataset then
        also has ``revolutions_run`` and ``stop_period`` (0: not converged, run to the end) per
        point, and the attributes ``revolutions_requested_total``, ``revolutions_run_total`` and
        ``points_stopped_converged``; the saving is logged.  A run that has not converged is
        never stopped.  Default off (on in :func:`bifurcation`).
    **simulate_kwargs
        simulate's keywords for every point (``span`` or ``revolutions``/``t_end``...,
        ``options`` or ``rtol``..., ``backend`` -- "compiled" unless given -- ``y0``, and ``cam``
        or ``speed_rpm`` when the speed is not a grid axis): the run's
        :class:`~camdyn.runs.request.RunRequest` is built from them once, as simulate builds it,
        and a bad one raises before any work.  With ``samples_per_revolution`` the span's sample
        rate is each point's own.

    Returns
    -------
    xarray.Dataset
        One dimension per grid name, the measured variables, ``outcome`` and ``message``.
    """
    if stop is not None:
        if samples_per_revolution is None:
            raise ParameterError("samples_per_revolution", None, "an integer >= 1 with stop= (the section is "
                                 "every samples_per_revolution-th sample)")
        simulate_kwargs = {**simulate_kwargs, "stop": stop}
    spec = _spec(rig, scene, grid, measure, samples_per_revolution, simulate_kwargs)
    return _start(spec, _Output(out, overwrite), invalid, _RunOptions(executor, progress, chunksize, retries))


def resume(out, *, executor: Executor | None = None, progress: bool = True, chunksize: int | None = None,
           retries: int = 2):
    """Continue the sweep that was writing ``out``: run only the points missing from
    ``<out>.parts`` and write ``out``; the result equals an uninterrupted sweep's.

    The grid, rig, scene, measure and settings come from the folder; ``executor``,
    ``progress``, ``chunksize`` and ``retries`` are as in :func:`sweep` and may differ from
    the first run's.  A sweep that already finished returns its file's Dataset.  A folder that
    another process is writing (its lock is held) is refused with :class:`StoreError`, a file
    that is not a camdyn sweep with :class:`NotASweepError`.
    """
    options = _RunOptions(executor, progress, chunksize, retries)
    if not parts_folder(out).exists() and Path(out).is_file():
        log.info("%s is complete: nothing to resume", out)
        return load_sweep(out)
    with FolderStore.open(out) as store:
        return _run(store.spec(), store, options)


def load_partial(out):
    """The Dataset of an unfinished sweep writing ``out``, as far as it got: the points not
    run yet are NOT_RUN (NaN values).  Nothing runs (and nothing is locked)."""
    store = FolderStore.open(out, lock=False)
    return assemble(store.spec(), store.chunks())


def settings_of(out) -> tuple[dict, dict[str, np.ndarray]]:
    """(attributes, grid) of the sweep writing ``out`` (its folder's manifest) or written to it
    (the file's attributes and coordinates): how it was run, without running or locking it."""
    if parts_folder(out).exists():
        manifest = FolderStore.open(out, lock=False).manifest()
        return manifest["attributes"], {k: np.asarray(v, dtype=float) for k, v in manifest["grid"].items()}
    if not Path(out).is_file():
        raise StoreError(f"{out}: no sweep to resume (neither the file nor {parts_folder(out)} exists)")
    ds = load_sweep(out)
    return dict(ds.attrs), {name: ds[name].values for name in ds.attrs["grid"].split()}


def _spec(rig, scene, grid, measure, samples_per_revolution, kwargs: dict, finish=None) -> SweepSpec:
    axes = grid_axes(rig, grid)
    kwargs = dict(kwargs)
    state = [name for name in STATE_NAMES if name in axes]
    if state and len(state) < len(STATE_NAMES) and kwargs.get("y0") is None:
        missing = next(name for name in STATE_NAMES if name not in axes)
        raise ParameterError("y0", None, f"(alpha rad, alpha_dot rad/s) for the start's {missing.replace('_start', '')},"
                             f" which has no grid axis {missing!r}")
    if not callable(measure):
        raise ParameterError("measure", measure, "a callable measure(result) -> dict")
    if samples_per_revolution is not None:
        integer("samples_per_revolution", samples_per_revolution, "an integer >= 1", lambda n: n >= 1)
    if "speed_rpm" in kwargs:
        if "speed_rpm" in axes or "cam" in kwargs:
            raise ParameterError("speed_rpm", kwargs["speed_rpm"], "not given with a speed_rpm axis or cam=")
        kwargs["cam"] = ConstantSpeed(kwargs.pop("speed_rpm"))
    if "speed_rpm" in axes and "cam" in kwargs:
        raise ParameterError("cam", kwargs["cam"], "not given with a speed_rpm axis")
    if "speed_rpm" not in axes and "cam" not in kwargs:
        raise ParameterError("speed_rpm", None, "a grid axis 'speed_rpm', or cam=/speed_rpm= for every point")
    if "speed_rpm" in axes and scene.motion != "constant":
        raise ParameterError("grid", "speed_rpm", f"no speed_rpm axis with the scene's {scene.motion!r} motion")
    kwargs.setdefault("backend", DEFAULT_BACKEND)   # recorded in the file, whatever the default
    return SweepSpec(rig, scene, axes, measure, kwargs, samples_per_revolution, finish)


@dataclass(frozen=True)
class _Output:
    """Where a sweep goes: the file ``out`` (None: memory only), and whether it may replace one."""

    out: object = None
    overwrite: bool = False

    def check(self) -> None:
        flag("overwrite", self.overwrite)
        if self.out is not None:
            check_out(self.out, self.overwrite)

    def store(self, spec: SweepSpec):
        return MemoryStore() if self.out is None else FolderStore.create(self.out, spec, self.overwrite)


def _start(spec: SweepSpec, output: _Output, invalid: str, options: _RunOptions):
    """Check the output and every point, then run the sweep into memory or into the output's folder."""
    if invalid not in ("raise", "skip"):
        raise ParameterError("invalid", invalid, "'raise' or 'skip'")
    output.check()
    check_settings(spec)
    bad, lines = check_grid(spec)
    if bad and invalid == "raise":
        raise InvalidGridError(spec.size, bad, lines)
    first = next((i for i in range(spec.size) if i not in bad), None)
    if first is not None:
        check_by_running(spec, first)
    if output.out is not None or isinstance(options.executor, ProcessPoolExecutor):
        try:
            pickle.dumps(spec)
        except Exception as exc:
            raise TypeError(f"the sweep's measure and settings must be picklable to run in other processes "
                            f"or to be resumed ({type(exc).__name__}: {exc})") from None
    with output.store(spec) as store:
        if bad:
            indices = sorted(bad)
            store.put(chunk_of(indices, [(INVALID, bad[i], {}) for i in indices]))
        return _run(spec, store, options)


def _run(spec: SweepSpec, store, options: _RunOptions):
    """Run the points missing from the store; assemble (and, with a folder, write) the Dataset."""
    todo = np.flatnonzero(~done_mask(spec, store.chunks()))
    workers = worker_count(options.executor)
    size = options.chunksize or max(1, math.ceil(todo.size / (16 * workers)))
    chunks = chunks_of(todo, size)
    bar = _Progress(spec, todo.size, options.progress)
    try:
        if options.executor is None:
            not_run = run_serial(spec, chunks, store, bar)
        else:
            not_run = Dispatch(spec, chunks, store, bar, options.executor, options.retries).run()
    finally:
        bar.close()
    ds = assemble(spec, store.chunks(), not_run)
    if isinstance(store, FolderStore):
        store.finish(ds, complete=not not_run)
    _report(ds, store)
    return ds


class _Progress:
    """A tqdm bar counting points, with the number that did not succeed."""

    def __init__(self, spec: SweepSpec, total: int, enabled: bool):
        from tqdm.auto import tqdm

        self.bar = tqdm(total=spec.size, initial=spec.size - total, disable=not enabled,
                        desc=f"sweep {spec.scene.slug}", unit="pt")
        self.failed = 0

    def done(self, chunk) -> None:
        self.bar.update(len(chunk))
        failed = int(np.sum(chunk.outcome != OUTCOME_CODES["SUCCESS"]))
        if failed:
            self.failed += failed
            self.bar.set_postfix_str(f"{self.failed} not SUCCESS", refresh=False)

    def close(self) -> None:
        self.bar.close()


def _report(ds, store) -> None:
    codes = ds["outcome"].values
    errors, not_run, skipped = (int(np.sum(codes == c)) for c in (ERROR, NOT_RUN, INVALID))
    if "revolutions_run_total" in ds.attrs:
        log.info("%s", stop_summary(ds))
    if skipped:
        log.info("%d of %d points skipped as INVALID (invalid='skip'; the message variable says why)", skipped,
                 codes.size)
    if errors:
        log.warning("%d of %d points raised: recorded as ERROR (the message variable says why)", errors, codes.size)
    if not_run:
        where = (f"camdyn.sweep.api.resume({str(store.out)!r}) runs them" if isinstance(store, FolderStore)
                 else "run the sweep with out= to be able to resume it")
        log.warning("%d of %d points could not run: recorded as NOT_RUN; %s", not_run, codes.size, where)


def bifurcation(rig: Rig, scene: Scene, speeds_rpm: Sequence[float], *, revolutions: int = 200,
                transient_revolutions: int = 50, stop: StopWhenPeriodic | None = StopWhenPeriodic(), **kwargs):
    """Poincare section of alpha once per revolution against cam speed: ``alpha_section``
    (speed_rpm, revolution) for the revolutions after the transient.  By default each run stops
    once its section repeats (``stop``, see :func:`sweep`): the section values over the
    remaining revolutions are its converged cycle, repeated (``stop_period`` says which
    points stopped, ``revolutions_run`` how far each ran); ``stop=None`` runs every point to
    the end.  ``kwargs`` go to :func:`sweep` (``executor``, ``out``, ``rtol``...)."""
    revolutions = integer("revolutions", revolutions, "an integer >= 1", lambda n: n >= 1)
    if not 0 <= transient_revolutions < revolutions:
        raise ParameterError("transient_revolutions", transient_revolutions, f"0 <= it < revolutions ({revolutions})")
    return sweep(rig, scene, {"speed_rpm": speeds_rpm}, PoincareSection(transient_revolutions),
                 revolutions=revolutions, samples_per_revolution=1, stop=stop, **kwargs)


def contact_loss_map(rig: Rig, scene: Scene, k_s: Sequence[float], speeds_rpm: Sequence[float], *,
                     revolutions: float = 6, transient_revolutions: float = 3, samples_per_revolution: int = 64,
                     executor: Executor | None = None, progress: bool = True, chunksize: int | None = None,
                     out=None, overwrite: bool = False, invalid: str = "raise", retries: int = 2,
                     **simulate_kwargs):
    """Where the follower leaves the cam: ``impacts_per_rev`` over (k_s, speed_rpm) from simulation,
    ``contact_lost`` (1 with impacts after the transient, 0 without, NaN where the run did not
    succeed), and ``loss_speed_predicted`` (k_s), the inverse-kinematics contact-loss speed
    (Section 6) -- the curve of the paper's Fig. 9.  Other keywords as in :func:`sweep`."""
    spec = _spec(rig, scene, {"k_s": k_s, "speed_rpm": speeds_rpm}, Summary(transient_revolutions),
                 samples_per_revolution, {"revolutions": revolutions, **simulate_kwargs}, finish=add_contact_loss)
    return _start(spec, _Output(out, overwrite), invalid, _RunOptions(executor, progress, chunksize, retries))


def add_contact_loss(ds, spec: SweepSpec):
    """The derived variables of :func:`contact_loss_map` (its ``finish``: run on resume too)."""
    import xarray as xr

    impacts = ds["impacts_per_rev"]
    ds["contact_lost"] = xr.where(impacts.isnull(), np.nan, (impacts > 0).astype(float))
    ds["contact_lost"].attrs = {"units": "1", "long_name": "1: impacts after the transient, 0: none, NaN: no run"}
    ds["loss_speed_predicted"] = ("k_s", np.array([_loss_speed(spec.rig, float(k)) for k in ds["k_s"].values]),
                                  {"units": "rev/min", "long_name": "contact-loss speed by inverse kinematics "
                                                                    "(Section 6)"})
    return ds


def _loss_speed(rig: Rig, k_s: float) -> float:
    try:
        return contact_loss_speed(rig.replace(k_s=k_s))
    except CamdynError:
        return math.nan


__all__ = ["sweep", "resume", "StopWhenPeriodic", "load_partial", "load_sweep", "settings_of", "process_pool",
           "Summary", "PoincareSection", "bifurcation", "contact_loss_map", "InvalidGridError", "StoreError",
           "NotASweepError", "ALL_CODES", "rig_of", "scene_of", "stop_summary", "check_out", "parts_folder",
           "refuse_if_in_use"]
