"""Running a sweep's chunks: serially, or on any ``concurrent.futures.Executor``.

Each finished chunk goes to the store at once.  On an executor at most a window of tasks is
in flight (about two per worker), so a large sweep never holds every task's arguments or
results at once.  A task that fails is a task whose worker died or whose executor broke (the
chunk itself never raises: :func:`camdyn.sweep.spec.run_chunk` records a failing point):

* on dask, a worker that dies has its tasks moved by the scheduler; a task that still fails
  (``KilledWorker``) is submitted again, up to ``retries`` times;
* a ``ProcessPoolExecutor`` whose worker dies is broken for good, with every task in flight
  failed: a new pool of the same size takes over, and the chunks that were in flight run
  again one at a time, so that the one that kills its worker is found (the others are not
  blamed) and retried up to ``retries`` times.

A chunk that still cannot run is reported back; its points are recorded as NOT_RUN.  So are
the chunks not yet run when the executor can take no more tasks (a dask cluster that was closed
or lost, a pool that was shut down): the sweep ends, says so, and ``resume`` runs them later.

Workers that outlive their parent: a ``ProcessPoolExecutor``'s workers wait for tasks on pipes
from the parent, and a parent killed with SIGKILL leaves them waiting for ever (with the memory
of a loaded engine each).  :func:`process_pool` starts its workers with :func:`exit_with_parent`,
which ends each worker when the process that started the pool dies.
"""
from __future__ import annotations

import ctypes
import logging
import os
import signal
import sys
import threading
import time
from collections import Counter, deque
from concurrent.futures import FIRST_COMPLETED, BrokenExecutor, Executor, ProcessPoolExecutor, wait

import numpy as np

from .spec import SweepSpec, run_chunk

log = logging.getLogger("camdyn.sweep.api")
#: prctl(2) option: the signal a process gets when its parent (the thread that forked it) ends
PR_SET_PDEATHSIG = 1
#: seconds between two looks at the parent, where prctl is not available
WATCH_INTERVAL = 1.0


def process_pool(workers: int, **kwargs) -> ProcessPoolExecutor:
    """A ``ProcessPoolExecutor`` of ``workers`` processes that end when this process dies (also by
    SIGKILL); other keywords go to ``ProcessPoolExecutor`` (not ``initializer``)."""
    return ProcessPoolExecutor(workers, initializer=exit_with_parent, initargs=(os.getpid(),), **kwargs)


def exit_with_parent(parent: int) -> None:
    """Worker initializer: end this worker when the process ``parent`` ends.

    On Linux, ``prctl(PR_SET_PDEATHSIG, SIGKILL)``: the kernel kills the worker the moment its
    parent ends, whatever the worker is doing (a compiled run holds the GIL for its whole length,
    so a Python thread could only look between runs); then a look at ``parent`` closes the race
    of a parent that died before the call.  (The "parent" is the thread that forked the worker;
    a sweep's pool is forked from the thread that submits, which lives as long as the sweep.
    With the forkserver start method the parent is the fork server, which ends with ``parent``.)
    Elsewhere on POSIX, a daemon thread looks at ``parent`` every ``WATCH_INTERVAL`` seconds;
    on Windows nothing is done (``os.kill`` there would end the parent).
    """
    if sys.platform.startswith("linux") and _parent_death_signal(signal.SIGKILL):
        if not _alive(parent):
            os._exit(1)
    elif os.name == "posix":
        threading.Thread(target=_watch, args=(parent,), daemon=True, name="camdyn-exit-with-parent").start()


def _parent_death_signal(sig: int) -> bool:
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        return libc.prctl(PR_SET_PDEATHSIG, int(sig), 0, 0, 0) == 0
    except (OSError, AttributeError):  # no libc prctl (an unusual Linux): fall back to the watcher
        return False


def _alive(pid: int) -> bool:
    """Whether process ``pid`` exists (POSIX: signal 0 only checks)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # it exists, owned by someone else
        return True
    return True


def _watch(parent: int) -> None:
    while _alive(parent):
        time.sleep(WATCH_INTERVAL)
    os._exit(1)


def worker_count(executor: Executor | None) -> int:
    """Workers of a process or thread pool, threads of a dask cluster, else this machine's CPUs
    (used only for the default chunk size and the window of tasks in flight)."""
    if executor is None:
        return 1
    workers = getattr(executor, "_max_workers", None)
    client = getattr(executor, "_client", None)
    if workers is None and client is not None:
        try:
            workers = sum(client.nthreads().values())
        except Exception:  # an executor we do not know: fall back to the CPU count
            workers = None
    return max(1, workers or os.cpu_count() or 1)


def chunks_of(indices: np.ndarray, size: int) -> list[np.ndarray]:
    return [indices[i:i + size] for i in range(0, indices.size, size)]


def run_serial(spec: SweepSpec, chunks: list[np.ndarray], store, bar) -> dict[int, str]:
    for chunk in chunks:
        result = run_chunk(spec, chunk)
        store.put(result)
        bar.done(result)
    return {}


class Dispatch:
    """Chunks on an executor, a bounded window of them in flight (see the module doc)."""

    def __init__(self, spec: SweepSpec, chunks: list[np.ndarray], store, bar, executor: Executor, retries: int):
        self.spec, self.chunks, self.store, self.bar, self.retries = spec, chunks, store, bar, retries
        self.pool, self.own = executor, None        # own: a replacement pool this sweep started
        self.generation = 0                         # of the pool: a new pool after a break
        self.queue = deque(range(len(chunks)))
        self.suspects: deque[int] = deque()         # in flight when a pool broke: rerun one at a time
        self.running: dict = {}                     # future -> (chunk id, pool generation, ran alone)
        self.attempts: Counter = Counter()
        self.lost: dict[int, str] = {}              # chunk id -> why it could not run
        self.gone = ""                              # why the executor takes no more tasks, once it does not
        self.window = 2 * worker_count(executor)

    def run(self) -> dict[int, str]:
        """Run every chunk; {point index: message} of the points that could not run."""
        try:
            while self.queue or self.suspects or self.running:
                self._fill()
                if self.running:
                    done, _ = wait(self.running, return_when=FIRST_COMPLETED)
                    for future in done:
                        self._collect(future)
        finally:
            for future in self.running:
                future.cancel()
            if self.own is not None:
                self.own.shutdown(wait=False, cancel_futures=True)
        return {int(i): text for cid, text in self.lost.items() for i in self.chunks[cid]}

    def _fill(self) -> None:
        if self.pool is None:  # the executor broke and cannot be replaced
            for cid in list(self.suspects) + list(self.queue):
                self.lost[cid] = f"not run: {self.gone}; resume the sweep to run it"
            self.suspects.clear()
            self.queue.clear()
        elif self.suspects:
            if not self.running:
                self._submit(self.suspects.popleft(), alone=True)
        else:
            while self.queue and self.pool is not None and len(self.running) < self.window:
                self._submit(self.queue.popleft(), alone=False)

    def _submit(self, cid: int, alone: bool) -> None:
        try:
            future = self.pool.submit(run_chunk, self.spec, self.chunks[cid], self.attempts[cid])
        except BrokenExecutor as exc:
            self._failed(cid, self.generation, alone, exc)
            return
        except Exception as exc:  # it takes no tasks: shut down, or its dask client or cluster is gone
            (self.suspects if alone else self.queue).appendleft(cid)
            self._lose_executor(exc)
            return
        self.running[future] = (cid, self.generation, alone)

    def _collect(self, future) -> None:
        cid, generation, alone = self.running.pop(future)
        try:
            result = future.result()
        except Exception as exc:  # the task failed, not a point: its worker died or the executor broke
            self._failed(cid, generation, alone, exc)
            return
        self.store.put(result)
        self.bar.done(result)

    def _failed(self, cid: int, generation: int, alone: bool, exc: Exception) -> None:
        broken = isinstance(exc, BrokenExecutor)
        if broken and generation == self.generation:
            self._replace_pool(exc)
        if broken and not alone:  # one of the tasks in flight broke the pool: find out which
            self.suspects.append(cid)
            return
        if self.pool is None:     # lost with the executor, not by its own doing: no retry to count
            self.queue.appendleft(cid)
            return
        self.attempts[cid] += 1
        points = f"{self.chunks[cid].size} point(s) from {self.spec.label(self.chunks[cid][0])}"
        if self.attempts[cid] > self.retries:
            self.lost[cid] = (f"not run: its task failed {self.attempts[cid]} times, the last with "
                              f"{type(exc).__name__}: {exc}".rstrip(": "))
            log.warning("chunk of %s failed %d times (%s): recorded as NOT_RUN", points, self.attempts[cid],
                        type(exc).__name__)
            return
        log.warning("chunk of %s failed (%s: %s); retry %d of %d", points, type(exc).__name__, exc,
                    self.attempts[cid], self.retries)
        (self.suspects if broken else self.queue).appendleft(cid)

    def _replace_pool(self, exc: Exception) -> None:
        """A broken process pool: start a new one of the same size (owned by this sweep)."""
        self.generation += 1
        old = self.pool
        if not isinstance(old, ProcessPoolExecutor):
            self._lose_executor(exc)
            return
        log.warning("a worker process died (%s); starting a new process pool", type(exc).__name__)
        self.pool = ProcessPoolExecutor(old._max_workers, mp_context=getattr(old, "_mp_context", None),
                                        initializer=getattr(old, "_initializer", None),
                                        initargs=getattr(old, "_initargs", ()))
        if self.own is not None:
            self.own.shutdown(wait=False, cancel_futures=True)
        self.own = self.pool

    def _lose_executor(self, exc: Exception) -> None:
        """The executor takes no more tasks: the chunks not run are recorded as NOT_RUN."""
        self.gone = f"the executor took no more tasks ({type(exc).__name__}: {exc})".replace(": )", ")")
        log.warning("%s; the points not run yet are recorded as NOT_RUN", self.gone)
        self.pool = None
