"""Where a cold start's compile time goes: each numba-compiled function's own share.

Run from the repository root, in a fresh process (it needs an empty numba cache, so it makes a
new CAMDYN_CACHE_DIR and removes it at the end):

    python benchmarks/compile_times.py [--top N]

It runs the start-up command of docs/performance.md (``camdyn.simulate`` of the default scene,
0.01 s at 300 rev/min) with numba's compile events recorded (``numba.core.event``, kind
``numba:compile``) and prints, per compiled function, its *self* time: the time of its
compile minus the compiles it triggered (a function's typing compiles the functions it
calls), with how much of it numba's lowering pass took.  The scene's cfuncs are not
dispatchers and send no such event: they are in the total, not in the table.  Times are wall
seconds on a shared machine: compare two versions alternated, as ratios.
"""
from __future__ import annotations

import argparse
import os
import shutil
import sys
import tempfile
import time
from collections import Counter


def _name(dispatcher) -> str:
    fn = getattr(dispatcher, "py_func", None)
    return f"{fn.__module__.split('.')[-1]}.{fn.__qualname__}" if fn is not None else repr(dispatcher)[:50]


def self_times(buffer) -> tuple[Counter, dict]:
    """Per dispatcher (by id): its compile time minus its nested compiles; and id -> dispatcher."""
    stack, own, dispatchers = [], Counter(), {}
    for ts, event in buffer:
        d = event.data.get("dispatcher")
        if event.is_start:
            dispatchers[id(d)] = d
            stack.append([id(d), ts, 0.0])
            continue
        key, start, nested = stack.pop()
        own[key] += (ts - start) - nested
        if stack:
            stack[-1][2] += ts - start
    return own, dispatchers


def lowering_time(dispatcher) -> float:
    """numba's native-lowering pass time over the dispatcher's compiled signatures (s)."""
    return sum(t.run for cres in getattr(dispatcher, "overloads", {}).values()
               for times in (cres.metadata or {}).get("pipeline_times", {}).values()
               for name, t in times.items() if "native_lowering" in name)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--top", type=int, default=30, help="rows to print")
    args = parser.parse_args(argv)
    if "camdyn" in sys.modules:
        raise SystemExit("run it in a fresh process")
    cache = tempfile.mkdtemp(prefix="camdyn-cold-")
    os.environ["CAMDYN_CACHE_DIR"] = cache
    import warnings

    import numba.core.event as ev
    warnings.simplefilter("ignore")
    t0, c0 = time.perf_counter(), time.process_time()
    with ev.install_recorder("numba:compile") as rec:
        import camdyn
        camdyn.simulate(camdyn.example_rig(), camdyn.Scene(), speed_rpm=300, t_end=0.01)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    shutil.rmtree(cache, ignore_errors=True)
    own, dispatchers = self_times(rec.buffer)
    rows = sorted(((own[k], lowering_time(d), _name(d)) for k, d in dispatchers.items()), reverse=True)
    print(f"cold start: {wall:.2f} s wall, {cpu:.2f} s CPU in process; {len(rows)} compiled functions, "
          f"{sum(r[0] for r in rows):.2f} s of their compiles (load average {os.getloadavg()[0]:.2f})")
    print(" self s  lowering s  function")
    for s, low, name in rows[:args.top]:
        print(f"{s:7.2f} {low:11.2f}  {name}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
