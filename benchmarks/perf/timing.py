"""Start-up (cold and warm, in fresh processes) and the sweeps, timed."""
from __future__ import annotations

import os
import statistics
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np

import camdyn
import sweep_stop

from .cases import ATOL_PER_RTOL, RIG, Config

START_CODE = ("import time; t0 = time.perf_counter(); import camdyn; "
              "camdyn.simulate(camdyn.example_rig(), camdyn.Scene(), speed_rpm=300, t_end=0.01); "
              "print(time.perf_counter() - t0)")
START_COMMAND = f'CAMDYN_CACHE_DIR=<dir> python -c "{START_CODE}"'


def _fresh_process(cache: str) -> tuple[float, float]:
    """(in-process s from before `import camdyn` to the end of the run, whole process wall s)."""
    env = {**os.environ, "CAMDYN_CACHE_DIR": cache}
    t0 = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", START_CODE], env=env, capture_output=True, text=True, check=True)
    return float(out.stdout.split()[-1]), time.perf_counter() - t0


def start_times(cfg: Config) -> dict:
    """Cold start: a fresh process on a new, empty CAMDYN_CACHE_DIR (numba compiles the engine
    and the scene's kernels); warm start: a fresh process on a filled one.  Alternated, so a busy
    spell falls on both."""
    cold, warm = [], []
    with tempfile.TemporaryDirectory() as filled:
        _fresh_process(filled)                      # fill it
        for _ in range(cfg.start_runs):
            with tempfile.TemporaryDirectory() as empty:
                cold.append(_fresh_process(empty))
            warm.append(_fresh_process(filled))
    med = lambda xs, i: statistics.median(x[i] for x in xs)  # noqa: E731
    return {"cold": med(cold, 0), "cold_process": med(cold, 1), "warm": med(warm, 0), "warm_process": med(warm, 1),
            "runs": cfg.start_runs, "cold_all": [c[0] for c in cold], "warm_all": [w[0] for w in warm]}


# --- sweeps -----------------------------------------------------------------------------------------
#: the bifurcation sweep's tolerance, benchmarks/sweep_stop.py's (permanent_contact_tolerance shows rtol
#: against cost and error)
SWEEP_RTOL = sweep_stop.RTOL


def permanent_contact_tolerance(revolutions: int) -> dict:
    """One permanent-contact point of the sweep (0.85 x the contact-loss speed) at several
    tolerances: wall time, steps, switches and the largest error of its Poincare section
    (the second half of the revolutions) against rtol 1e-10."""
    rig = RIG.replace(l_lambda=0.016)
    scene = camdyn.Scene(damping="D", friction="coulomb")
    speed = 0.85 * camdyn.contact_loss_speed(rig)
    rows = []
    for rtol in (1e-10, 1e-6, 1e-7, 1e-8):
        t0 = time.perf_counter()
        res = camdyn.simulate(rig, scene, camdyn.ConstantSpeed(speed), revolutions=revolutions,
                              sample_rate_Hz=speed / 60.0, rtol=rtol, atol=rtol * ATOL_PER_RTOL)
        rows.append((rtol, time.perf_counter() - t0, res.stats["steps"], len(res.switches), res.alpha))
    ref = rows[0][4]
    half = ref.size // 2
    return {"speed": speed, "rows": [(rtol, secs, steps, sw, float(np.max(np.abs(a[half:] - ref[half:]))))
                                     for rtol, secs, steps, sw, a in rows[1:]]}


def _bifurcation_parts(rig, scene, grid, loss, revolutions) -> tuple[list, dict]:
    from camdyn.sweep import api as S
    parts, seconds = [], {}
    for name, part in (("permanent contact", grid[grid <= loss]), ("impacting", grid[grid > loss])):
        t0 = time.perf_counter()
        with ProcessPoolExecutor(2) as pool:
            parts.append(S.bifurcation(rig, scene, part, revolutions=revolutions,
                                       transient_revolutions=revolutions // 2, executor=pool, progress=False,
                                       rtol=SWEEP_RTOL, atol=SWEEP_RTOL * ATOL_PER_RTOL, stop=None))
        seconds[name] = (part.size, time.perf_counter() - t0, float(np.sum(revolutions * 60.0 / part)))
    return parts, seconds


def sweep_timing(cfg: Config) -> dict:
    """The bifurcation sweep timed in two parts, below the contact-loss speed (permanent contact)
    and above it (impacting), every point to the end (stop=None); the contact-loss map; the
    tolerance study of one point; the same diagram stopping once periodic (benchmarks/sweep_stop.py)."""
    import xarray as xr
    from camdyn.analysis import statics as analysis
    from camdyn.sweep import api as S
    rig, scene = RIG.replace(l_lambda=0.016), camdyn.Scene(damping="D", friction="coulomb")
    loss = camdyn.contact_loss_speed(rig)
    grid = np.linspace(0.8 * loss, 1.6 * loss, cfg.speeds)
    S.bifurcation(rig, scene, grid[:2], revolutions=2, transient_revolutions=1, progress=False)  # load
    parts, seconds = _bifurcation_parts(rig, scene, grid, loss, cfg.revolutions)
    t0 = time.perf_counter()
    with ProcessPoolExecutor(2) as pool:
        cmap = S.contact_loss_map(RIG, scene, np.linspace(1000, 5000, 9), np.linspace(400, 2000, 17), executor=pool,
                                  progress=False, rtol=SWEEP_RTOL, atol=SWEEP_RTOL * ATOL_PER_RTOL)
    return {"bif": xr.concat(parts, dim="speed_rpm"), "seconds": sum(v[1] for v in seconds.values()),
            "parts": seconds, "cmap": cmap, "map_seconds": time.perf_counter() - t0, "loss": loss,
            "frequency_Hz": analysis.natural_frequency(rig, scene, camdyn.ConstantSpeed(loss)).Hz,
            "tolerance": permanent_contact_tolerance(cfg.revolutions), "stopping": sweep_stop.measure(cfg.quick)}
