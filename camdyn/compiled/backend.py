"""The compiled backend's entry point: a Model in, a Trajectory out (as camdyn.integrate).

:func:`integrate` builds the regime tables and settings arrays, calls the compiled loop
(:func:`camdyn.compiled.engine.run`) and turns its arrays back into the SciPy backend's
``Trajectory`` (sample times and states, regime names, ``Switch`` records, ``Outcome``),
so :func:`camdyn.simulation._result` builds the Result the same way for both backends.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from ..errors import ParameterError
from ..integrate import SolverOptions, Switch, Trajectory
from ..model import ANGLE_LIMIT, Model
from ..outcome import Outcome
from . import engine
from .kernels import scene_functions
from .tableau import TABLEAUS, arrays

#: same chatter rule as the SciPy backend: this many switches within 1e-9 (relative) of time
CHATTER_SWITCHES = 20
CHATTER_WINDOW = 1e-9


def method_arrays(name: str):
    if name not in TABLEAUS:
        raise ParameterError("method", name, f"one of {sorted(TABLEAUS)} with backend='compiled' "
                             "(explicit Runge-Kutta with dense output); Radau, BDF and LSODA run "
                             "with backend='scipy'")
    return arrays(TABLEAUS[name])


def tables(kernels):
    """(flags_of, signs, lookup) of a scene, from FLAGS, FLAG_SURFACES, REGIMES, REGIME_NAMES."""
    names = list(kernels.REGIME_NAMES)
    flags = kernels.FLAGS
    nf = max(1, len(flags))
    flags_of = np.full((len(names), nf), -1, dtype=np.int64)
    lookup = np.full(3 ** nf, -1, dtype=np.int64)
    for key, name in kernels.REGIMES.items():
        r = names.index(name)
        code = 0
        for k, v in enumerate(key):
            flags_of[r, k] = -1 if v is None else int(v)
            code += (flags_of[r, k] + 1) * 3 ** k
        lookup[code] = r
    signs = np.array([kernels.FLAG_SURFACES[f][1] for f in flags], dtype=np.int64)
    return flags_of, signs, lookup


def _fixed_regime(model: Model, t: float, y) -> int:
    """Linear models: sliding contact throughout, the Coulomb sign fixed by v_r at the start
    (the SciPy backend's rule)."""
    K = model.kernels
    names = list(K.REGIME_NAMES)
    if len(names) == 1:
        return 0
    v_r = model.bind(K.out_contact_fwd)(t, y[0], y[1])[6]
    return names.index(K.REGIMES[(bool(v_r >= 0),)])


def integrate(model: Model, t_span: tuple[float, float], y0, t_eval: np.ndarray,
              options: SolverOptions = SolverOptions()) -> Trajectory:
    """Integrate the hybrid model compiled; same arguments and result as camdyn.integrate.integrate."""
    K = model.kernels
    rhs, surface = scene_functions(K)
    method = method_arrays(options.method)
    flags_of, signs, lookup = tables(K)
    t0, t_end = map(float, t_span)
    y = np.ascontiguousarray(y0, dtype=float)
    t_eval = np.ascontiguousarray(t_eval, dtype=float)
    r0 = _fixed_regime(model, t0, y) if not K.FLAGS else -1
    ev = options.events
    fset = np.array([options.rtol, options.atol, options.max_step, ev.xtol, ANGLE_LIMIT, CHATTER_WINDOW])
    iset = np.array([ev.interior_points, ev.max_events, CHATTER_SWITCHES], dtype=np.int64)
    out_y = np.empty((2, t_eval.size))
    out_r = np.empty(t_eval.size, dtype=np.int64)
    p = np.ascontiguousarray(model.p, dtype=float)
    code, n, sw, stats = engine.run(rhs, surface, method, p, flags_of, signs, lookup, r0, t0, t_end, y,
                                    t_eval, fset, iset, out_y, out_r)
    return trajectory(model, t_eval[:n], out_y[:, :n], out_r[:n], sw, code, stats)


def trajectory(model: Model, t, y, r, sw, code: int, stats) -> Trajectory:
    """The engine's arrays as a camdyn.integrate.Trajectory."""
    K = model.kernels
    names = np.array(K.REGIME_NAMES, dtype=object)
    flags = K.FLAGS
    switches = [Switch(float(s[0]), flags[int(s[1])], names[int(s[2])], names[int(s[3])], float(s[4]),
                       float(s[5])) for s in sw]
    info = {name: int(v) for name, v in zip(engine.STATS, stats)}
    info.update(njev=0, switches=len(switches), backend="compiled")
    fields = {"t": t, "y": y, "regime": names[r] if r.size else np.empty(0, dtype=object),
              "switches": switches, "outcome": Outcome[engine.OUTCOMES[code]], "stats": info}
    if "keys" in {f.name for f in dataclasses.fields(Trajectory)}:
        fields["keys"] = {name: key for key, name in K.REGIMES.items()}
    return Trajectory(**fields)


__all__ = ["integrate", "tables", "method_arrays", "trajectory"]
