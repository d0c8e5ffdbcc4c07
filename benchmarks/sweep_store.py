"""What streaming a sweep to disk costs, and how much memory a large sweep holds.

    python benchmarks/sweep_store.py overhead      # the 200 x 200 bifurcation sweep, in memory and streamed
    python benchmarks/sweep_store.py memory --points 100000

``overhead``: the bifurcation sweep of docs/performance.md (benchmarks/perf/timing.py's
``sweep_timing``: example rig with a 16 mm line contact, damping D, Coulomb friction, 200 speeds
from 0.8 to 1.6 x the contact-loss speed, 200 revolutions each, the second half as the Poincare
section, rtol 1e-7, atol 1e-11, ProcessPoolExecutor(2), compiled backend), timed in memory
(``out=None``) and streamed (``out=file``) in turn (the order alternating), ``--repeats`` times
each, within one run; the two Datasets must be identical.  The overhead is the ratio of the
times, minus 1.  On a shared machine that ratio carries the noise of other jobs, so the time
this process spends in the store (creating the folder, writing each chunk, reading the chunks
back, writing the file) is also timed, as a fraction of the streamed sweep's time.

``memory``: a sweep of ``--points`` points (k_s x speed, 0.85-0.95 x the contact-loss speed: in
contact, and cheap to run), each a short run (``--revolutions``) sampled once per revolution,
streamed to a file on a process pool;
prints the peak resident memory of this process and of the largest worker (getrusage), the
Python-heap peak of this process during the sweep (tracemalloc; the workers come from a fork
server, so they do not inherit it) and the size of the result.
"""
from __future__ import annotations

import argparse
import math
import multiprocessing
import os
import resource
import tempfile
import time
import tracemalloc
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

import camdyn
from camdyn.sweep import api as S
from sweep_stop import RTOL as SWEEP_RTOL  # the bifurcation benchmark's tolerance

RIG = camdyn.example_rig()
SCENE = camdyn.Scene(damping="D", friction="coulomb")


class StoreClock:
    """Time spent in FolderStore's methods (this process only)."""

    def __init__(self):
        from camdyn.sweep.store import FolderStore

        self.seconds = 0.0
        for name in ("create", "put", "chunks", "finish"):
            setattr(FolderStore, name, self._timed(getattr(FolderStore, name)))

    def _timed(self, method):
        def timed(*args, **kwargs):
            t0 = time.perf_counter()
            try:
                return method(*args, **kwargs)
            finally:
                self.seconds += time.perf_counter() - t0
        return timed


def overhead(speeds: int, revolutions: int, repeats: int, workers: int) -> None:
    import xarray as xr

    rig = RIG.replace(l_lambda=0.016)
    loss = camdyn.contact_loss_speed(rig)
    grid = np.linspace(0.8 * loss, 1.6 * loss, speeds)
    S.bifurcation(rig, SCENE, grid[:2], revolutions=2, transient_revolutions=1, progress=False)  # load the engine
    times: dict[str, list[float]] = {"in memory": [], "streamed": []}
    results, store, in_store = {}, StoreClock(), []
    with tempfile.TemporaryDirectory() as folder:
        for r in range(repeats):
            for label in (list(times) if r % 2 == 0 else list(times)[::-1]):
                out = Path(folder) / f"bif{r}.nc" if label == "streamed" else None
                store.seconds = 0.0
                t0 = time.perf_counter()
                with ProcessPoolExecutor(workers) as pool:
                    results[label] = S.bifurcation(rig, SCENE, grid, revolutions=revolutions,
                                                   transient_revolutions=revolutions // 2, executor=pool,
                                                   progress=False, rtol=SWEEP_RTOL, atol=SWEEP_RTOL * 1e-4, out=out)
                times[label].append(time.perf_counter() - t0)
                extra = ""
                if out is not None:
                    in_store.append(store.seconds)
                    extra = f" (in the store: {store.seconds:.3f} s, {store.seconds / times[label][-1]:.2%})"
                print(f"  {label:9s} run {r + 1}: {times[label][-1]:.2f} s{extra}", flush=True)
            xr.testing.assert_identical(results["in memory"], results["streamed"])
    mem, disk = sum(times["in memory"]), sum(times["streamed"])
    pairs = ", ".join(f"{d / m - 1:+.1%}" for m, d in zip(times["in memory"], times["streamed"]))
    print(f"{speeds} speeds x {revolutions} revolutions, ProcessPoolExecutor({workers}), {repeats} runs each: "
          f"in memory {mem / repeats:.2f} s, streamed {disk / repeats:.2f} s per sweep; "
          f"streaming overhead {disk / mem - 1:+.1%} (per pair: {pairs}); time in the store "
          f"{sum(in_store) / repeats:.3f} s per sweep, {sum(in_store) / disk:.2%} of the streamed time; "
          "the Datasets are identical")


def _peak_rss_MB(_=None) -> tuple[int, float, float]:
    """(pid, peak resident memory in MB, CPU seconds) of the process running this (a worker)."""
    time.sleep(0.05)  # so that every worker gets one of the probes
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return os.getpid(), usage.ru_maxrss / 1024, usage.ru_utime + usage.ru_stime


def memory(points: int, revolutions: int, workers: int) -> None:
    n_k = max(1, int(round(math.sqrt(points / 10))))
    n_v = points // n_k
    k_s = np.linspace(RIG.k_s, 2 * RIG.k_s, n_k)
    loss = camdyn.contact_loss_speed(RIG)
    speeds = np.linspace(0.85 * loss, 0.95 * loss, n_v)
    S.bifurcation(RIG, SCENE, speeds[:2], revolutions=2, transient_revolutions=0, progress=False)  # load the engine
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    # workers from a fork server: a forked worker would inherit this process's tracemalloc, which
    # slows every allocation (several times the cost of a point)
    pool = ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("forkserver"))
    tracemalloc.start()
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as folder, pool:
        ds = S.sweep(RIG, SCENE, {"k_s": k_s, "speed_rpm": speeds}, S.PoincareSection(0), executor=pool,
                     revolutions=revolutions, samples_per_revolution=1, out=Path(folder) / "big.nc", progress=False)
        seconds = time.perf_counter() - t0
        _, heap = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        peaks = {pid: (rss, cpu) for pid, rss, cpu in pool.map(_peak_rss_MB, range(8 * workers))}
    main = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    ok = int((ds["outcome"] == 0).sum())
    cpu = sum(c for _, c in peaks.values())
    print(f"{ds['outcome'].size} points ({n_k} k_s x {n_v} speeds), {revolutions} revolutions each, one sample per "
          f"revolution, ProcessPoolExecutor({workers}), streamed: {seconds:.1f} s ({cpu / ds['outcome'].size * 1e3:.1f} "
          f"ms of worker CPU per point), {ok} SUCCESS; Dataset {ds.nbytes / 1e6:.1f} MB")
    print(f"  peak RSS: this process {main:.0f} MB (before the sweep {before:.0f} MB), workers "
          f"{', '.join(f'{rss:.0f}' for rss, _ in peaks.values())} MB; "
          f"Python heap peak of this process during the sweep {heap / 1e6:.1f} MB")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("what", choices=["overhead", "memory"])
    parser.add_argument("--speeds", type=int, default=200)
    parser.add_argument("--revolutions", type=int, default=None, help="default: 200 (overhead), 2 (memory)")
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--points", type=int, default=100_000)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    if args.what == "overhead":
        overhead(args.speeds, args.revolutions or 200, args.repeats, args.workers)
    else:
        memory(args.points, args.revolutions or 2, args.workers)


if __name__ == "__main__":
    main()
