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
from ..hybrid import STICK
from ..integrate import SolverOptions, Switch, Trajectory
from ..model import ANGLE_LIMIT, Model
from ..outcome import Outcome
from . import engine
from .kernels import scene_kernels
from .regimes import STICK as STICK_FLAG
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


def has_stick(kernels) -> bool:
    """Coulomb friction (a 'forward' flag): slip reversals may stick (Filippov mode)."""
    return "forward" in kernels.FLAGS


def tables(kernels):
    """(flags_of, signs, lookup, partner) of a scene, from FLAGS, FLAG_SURFACES, REGIMES and
    REGIME_NAMES (see camdyn.compiled.regimes).  With Coulomb friction flags_of has a second
    block of rows, the stick modes nr + r of the forward regimes r (forward flag STICK)."""
    names = list(kernels.REGIME_NAMES)
    nr = len(names)
    flags = kernels.FLAGS
    nf = max(1, len(flags))
    stick = has_stick(kernels)
    flags_of = np.full(((2 if stick else 1) * nr, nf), -1, dtype=np.int64)
    lookup = np.full(3 ** nf, -1, dtype=np.int64)
    for key, name in kernels.REGIMES.items():
        r = names.index(name)
        code = 0
        for k, v in enumerate(key):
            flags_of[r, k] = -1 if v is None else int(v)
            code += (flags_of[r, k] + 1) * 3 ** k
        lookup[code] = r
    partner = np.full(nr, -1, dtype=np.int64)
    if stick:
        for key, name in kernels.REGIMES.items():
            if key[-1] is not None:
                partner[names.index(name)] = names.index(kernels.REGIMES[key[:-1] + (not key[-1],)])
                if key[-1]:
                    flags_of[nr + names.index(name)] = flags_of[names.index(name)]
                    flags_of[nr + names.index(name), -1] = STICK_FLAG
    signs = np.array([kernels.FLAG_SURFACES[f][1] for f in flags], dtype=np.int64)
    return flags_of, signs, lookup, partner


def regime_names(kernels) -> tuple[list[str], dict[str, tuple]]:
    """Names of the engine's regime indices (stick modes after the generated regimes, named
    as camdyn.hybrid names them) and each name's discrete-state key."""
    names = list(kernels.REGIME_NAMES)
    keys = {name: key for key, name in kernels.REGIMES.items()}
    if has_stick(kernels):
        for name in list(names):
            key = keys[name]
            stuck = name.replace("_fwd", "_stick") if key[-1] else ""
            names.append(stuck)
            if stuck:
                keys[stuck] = key[:-1] + (STICK,)
    return names, keys


#: names of the switches past the flags' surfaces (camdyn.hybrid's event names)
EXTRA_SWITCHES = ("unstick_fwd", "unstick_bwd")


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
              options: SolverOptions = SolverOptions(), key: tuple | None = None) -> Trajectory:
    """Integrate the hybrid model compiled; same arguments and result as camdyn.integrate.integrate."""
    K = model.kernels
    fns = scene_kernels(K)
    method = method_arrays(options.method)
    tab = tables(K)
    t0, t_end = map(float, t_span)
    y = np.ascontiguousarray(y0, dtype=float)
    t_eval = np.ascontiguousarray(t_eval, dtype=float)
    if key is not None:
        names, keys = regime_names(K)
        r0 = names.index(next(name for name, k in keys.items() if k == key))
    else:
        r0 = _fixed_regime(model, t0, y) if not K.FLAGS else -1
    ev = options.events
    contact_step = 0.1 / model.equilibrium.vartheta  # s: as the SciPy backend (camdyn.integrate)
    fset = np.array([options.rtol, options.atol, options.max_step, ev.xtol, ANGLE_LIMIT, CHATTER_WINDOW,
                     contact_step])
    rate_flag = next((k for k, f in enumerate(K.FLAGS) if K.FLAG_SURFACES[f][0] == "gap_rate"), -1)
    iset = np.array([ev.interior_points, ev.max_events, CHATTER_SWITCHES, hasattr(K, "aux_index"),
                     has_stick(K), rate_flag], dtype=np.int64)
    out_y = np.empty((5 if options.ledger else 2, t_eval.size))
    out_r = np.empty(t_eval.size, dtype=np.int64)
    p = np.ascontiguousarray(model.p, dtype=float)
    code, n, sw, stats = engine.run(fns, method, p, tab, len(K.REGIME_NAMES), r0, t0, t_end, y,
                                    t_eval, fset, iset, out_y, out_r)
    return trajectory(model, t_eval[:n], out_y[:, :n], out_r[:n], sw, code, stats)


def trajectory(model: Model, t, y, r, sw, code: int, stats) -> Trajectory:
    """The engine's arrays as a camdyn.integrate.Trajectory."""
    K = model.kernels
    names, keys = regime_names(K)
    names = np.array(names, dtype=object)
    surfaces = K.FLAGS + EXTRA_SWITCHES
    switches = [Switch(float(s[0]), surfaces[int(s[1])], names[int(s[2])], names[int(s[3])], float(s[4]),
                       float(s[5])) for s in sw]
    info = {name: int(v) for name, v in zip(engine.STATS, stats)}
    info.update(njev=0, switches=len(switches), backend="compiled")
    fields = {"t": t, "y": y, "regime": names[r] if r.size else np.empty(0, dtype=object),
              "switches": switches, "outcome": Outcome[engine.OUTCOMES[code]], "stats": info}
    if "keys" in {f.name for f in dataclasses.fields(Trajectory)}:
        fields["keys"] = keys
    return Trajectory(**fields)


__all__ = ["integrate", "tables", "method_arrays", "trajectory"]
